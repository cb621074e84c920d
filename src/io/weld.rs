//! Welding triangle soup into an indexed mesh by exact position equality.
use crate::mesh::Mesh;

/// Welds a triangle soup (three positions per triangle) into an indexed mesh. Vertices are
/// numbered in order of first appearance; positions equal bit for bit (with +0 == -0) merge.
pub fn weld_exact(soup: &[[f32; 3]]) -> Mesh {
    let _ = soup;
    Mesh::default()
}
