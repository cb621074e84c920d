//! Simplification of a smoothed surface for the student's download: fewer triangles, within a
//! distance the author chooses (or a triangle count), the surface still closed and manifold.
//!
//! Half-edge collapses by quadric error (`collapse`): a collapse keeps one of the edge's
//! vertices where it is, so the simplified surface uses a subset of the smoothed surface's
//! vertices, and each kept vertex keeps its original as its morph target. Written here because
//! the simplifier of `meshopt-rs` (our glTF codec) is a port of an early meshoptimizer without
//! the link condition or fold checks: on every smoothed CT structure tried, its results had
//! non-manifold edges and folded triangles even at the smallest errors, and the `meshopt`
//! crate binds the C++ library, which the page's wasm32 build cannot compile. Each result is
//! checked again (the same components and genus, no open or non-manifold edge, no triangle
//! facing against the surface it replaces) and its distance from the smoothed surface measured
//! ([`deviation`]); the collapse cost is searched so that the measured distance keeps within
//! the goal.

mod collapse;
mod deviation;

pub use deviation::deviation;

use collapse::collapse;

use crate::mesh::{vertex_normals, Mesh, MeshReport, Topology};

/// How far a surface may be simplified.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// As few triangles as keep the measured deviation within this many millimetres.
    Within(f64),
    /// About this many triangles, whatever the deviation (then measured and stated).
    Triangles(usize),
}

/// A simplified surface: triangles over the given surface's own vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    pub triangles: Vec<[u32; 3]>,
    /// The measured deviation from the given surface (mm), as [`deviation`] defines it.
    pub deviation_mm: f64,
}

/// Tries of the collapse cost before a surface is kept as it was: a collapse costing the
/// squared distance is usually within it; where the measure says otherwise, a smaller cost.
const TRIES: usize = 3;

/// `surface` simplified towards `goal`; `None` when no try gave a sound surface with fewer
/// triangles (within the distance, for [`Goal::Within`]).
pub fn simplify(surface: &Mesh, goal: Goal) -> Option<Simplified> {
    if surface.triangles.is_empty() {
        return None;
    }
    // Only a closed manifold is simplified: the checks below hold a result to its shape.
    let before = shape(surface, &surface.triangles)?;
    let normals = vertex_normals(&surface.positions, &surface.triangles);
    // A smoothed surface can hold a few such triangles itself (at its sharpest folds).
    let folded = folds(surface, &surface.triangles, &normals);
    let (mut cost, keep) = match goal {
        Goal::Within(mm) if mm > 0.0 && mm.is_finite() => (mm * mm, 0),
        Goal::Triangles(n) if n < surface.triangle_count() => (f64::INFINITY, n),
        _ => return None,
    };
    for _ in 0..TRIES {
        let triangles = collapse(surface, cost, keep);
        if triangles.len() >= surface.triangle_count() {
            return None;
        }
        // The collapses keep the shape; this guards against what they might miss.
        if shape(surface, &triangles) != Some(before)
            || folds(surface, &triangles, &normals) > folded
        {
            cost *= 0.25;
            continue;
        }
        let deviation_mm = deviation(surface, &triangles);
        match goal {
            Goal::Within(mm) if deviation_mm > mm => {
                cost *= 0.8 * (mm / deviation_mm).powi(2);
            }
            _ => {
                return Some(Simplified {
                    triangles,
                    deviation_mm,
                })
            }
        }
    }
    None
}

/// What simplification must keep, or `None` where the triangles are not a closed manifold
/// without degenerate or repeated faces: their components and genus.
fn shape(surface: &Mesh, triangles: &[[u32; 3]]) -> Option<(usize, Option<i64>)> {
    let mesh = Mesh::new(surface.positions.clone(), triangles.to_vec());
    let r = MeshReport::new(&mesh, &Topology::build(&mesh));
    let sound = r.closed
        && r.boundary_edges == 0
        && r.nonmanifold_edges == 0
        && r.nonmanifold_vertices == 0
        && r.degenerate_faces == 0
        && r.duplicate_faces == 0;
    sound.then_some((r.components, r.genus))
}

/// How many triangles face against the surface at their corners (a fold: their corners'
/// normals on the smoothed surface, summed, point away from their own normal).
fn folds(surface: &Mesh, triangles: &[[u32; 3]], normals: &[[f32; 3]]) -> usize {
    let p = |v: u32| surface.positions[v as usize].map(f64::from);
    triangles
        .iter()
        .filter(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let (u, v) = (sub(b, a), sub(c, a));
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let m: [f64; 3] =
                std::array::from_fn(|k| t.iter().map(|&i| f64::from(normals[i as usize][k])).sum());
            // A sliver (corners nearly on a line) has no direction to speak of and covers nothing.
            let longest = [u, v, sub(c, b)]
                .iter()
                .map(|e| e.iter().map(|x| x * x).sum::<f64>())
                .fold(0.0, f64::max);
            let area2 = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            area2 > SLIVER * longest && (0..3).map(|k| n[k] * m[k]).sum::<f64>() <= 0.0
        })
        .count()
}

/// Twice a triangle's area over its longest edge squared below which it is a sliver: its
/// height is below a hundredth of its longest edge.
const SLIVER: f64 = 0.01;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
