//! Binary STL: a fixed header of our own (never the input's: STL headers often carry patient
//! names), facet normals computed from each triangle, then the triangle soup.

use super::ExportError;
use crate::mesh::{cross, sub, to_f64, Mesh};

const HEADER_TEXT: &[u8] = b"meshsmooth binary STL";

pub(super) fn write(mesh: &Mesh) -> Result<Vec<u8>, ExportError> {
    let count = u32::try_from(mesh.triangle_count()).map_err(|_| ExportError::TooLarge {
        format: "STL",
        detail: format!("{} triangles exceed a u32 count", mesh.triangle_count()),
    })?;
    let mut out = Vec::with_capacity(84 + 50 * mesh.triangle_count());
    out.extend_from_slice(HEADER_TEXT);
    out.resize(80, b' ');
    out.extend(count.to_le_bytes());
    for t in &mesh.triangles {
        // Indices were checked against the vertex count by the caller.
        let [a, b, c] = t.map(|v| mesh.positions.get(v as usize).copied().unwrap_or_default());
        for v in facet_normal(a, b, c).iter().chain(&a).chain(&b).chain(&c) {
            out.extend(v.to_le_bytes());
        }
        out.extend([0, 0]);
    }
    Ok(out)
}

/// Unit normal of a counter-clockwise triangle; zero for a degenerate one.
fn facet_normal(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f32; 3] {
    let (a, b, c) = (to_f64(a), to_f64(b), to_f64(c));
    let n = cross(sub(b, a), sub(c, a));
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|v| (v / len) as f32)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_count_and_normals() {
        let mesh = Mesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [4.0, 0.0, 0.0],
            ],
            vec![[0, 1, 2], [0, 1, 3]],
        );
        let bytes = write(&mesh).expect("writes");
        assert_eq!(bytes.len(), 84 + 2 * 50);
        assert!(bytes[..80].starts_with(b"meshsmooth binary STL   "));
        assert!(bytes[21..80].iter().all(|&b| b == b' '));
        assert_eq!(&bytes[80..84], &2u32.to_le_bytes());
        let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        assert_eq!([f32_at(84), f32_at(88), f32_at(92)], [0.0, 0.0, 1.0]);
        assert_eq!(f32_at(84 + 12 + 12), 2.0);
        // The second triangle is collinear: zero normal.
        assert_eq!([f32_at(134), f32_at(138), f32_at(142)], [0.0; 3]);
    }
}
