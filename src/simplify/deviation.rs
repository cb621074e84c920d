//! How far a simplified surface lies from the surface it simplifies, measured with exact
//! point-to-triangle distances both ways.

use crate::mesh::Mesh;
use crate::metrics::TriangleBvh;

/// The deviation (mm) of `triangles` (over `surface`'s vertices) from `surface`: the largest of
/// the distances from each vertex of `surface` to the simplified triangles, and from each
/// simplified triangle's centroid and edge midpoints to `surface`. The first is where removed
/// detail shows; the second bounds how far a large flat triangle strays between its corners,
/// which lie on `surface`.
pub fn deviation(surface: &Mesh, triangles: &[[u32; 3]]) -> f64 {
    let simplified = TriangleBvh::new(&surface.positions, triangles);
    let mut used = vec![false; surface.positions.len()];
    for &v in triangles.iter().flatten() {
        used[v as usize] = true;
    }
    // A kept vertex lies on the simplified surface: distance 0.
    let removed: Vec<[f32; 3]> = (surface.positions.iter().zip(&used))
        .filter(|(_, &u)| !u)
        .map(|(p, _)| *p)
        .collect();
    let away = simplified
        .distances(&removed)
        .into_iter()
        .fold(0.0, f64::max);
    let whole = TriangleBvh::new(&surface.positions, &surface.triangles);
    let p = |v: u32| surface.positions[v as usize];
    let samples: Vec<[f32; 3]> = triangles
        .iter()
        .flat_map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let mid = |x: [f32; 3], y: [f32; 3]| -> [f32; 3] {
                std::array::from_fn(|k| 0.5 * (x[k] + y[k]))
            };
            let centre: [f32; 3] = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
            [centre, mid(a, b), mid(b, c), mid(c, a)]
        })
        .collect();
    let back = whole.distances(&samples).into_iter().fold(0.0, f64::max);
    away.max(back)
}
