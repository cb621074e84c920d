//! The deviation a simplified surface's record states, measured again between two surfaces
//! that share no vertex numbering (as read back from a file).
#![allow(dead_code)]

use meshsmooth::mesh::Mesh;
use meshsmooth::metrics::TriangleBvh;

/// The farthest vertex of `full` from `simplified`, and the farthest centroid or edge midpoint
/// of a triangle of `simplified` from `full` (mm): the larger.
pub fn measured(full: &Mesh, simplified: &Mesh) -> f64 {
    let to_simplified = TriangleBvh::new(&simplified.positions, &simplified.triangles);
    let away = (to_simplified.distances(&full.positions).into_iter()).fold(0.0, f64::max);
    let to_full = TriangleBvh::new(&full.positions, &full.triangles);
    let p = |v: u32| simplified.positions[v as usize];
    let samples: Vec<[f32; 3]> = (simplified.triangles.iter())
        .flat_map(|t| {
            let [a, b, c] = t.map(p);
            let mix = |w: [f32; 3]| -> [f32; 3] {
                std::array::from_fn(|k| w[0] * a[k] + w[1] * b[k] + w[2] * c[k])
            };
            [
                mix([1.0 / 3.0; 3]),
                mix([0.5, 0.5, 0.0]),
                mix([0.0, 0.5, 0.5]),
                mix([0.5, 0.0, 0.5]),
            ]
        })
        .collect();
    let back = (to_full.distances(&samples).into_iter()).fold(0.0, f64::max);
    away.max(back)
}

/// How many triangles of `simplified` face against the triangle of `full` nearest their
/// centroid.
pub fn facing_against(full: &Mesh, simplified: &Mesh) -> usize {
    let tree = TriangleBvh::new(&full.positions, &full.triangles);
    let normal = |m: &Mesh, t: [u32; 3]| {
        let [a, b, c] = t.map(|v| m.positions[v as usize].map(f64::from));
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    (simplified.triangles.iter())
        .filter(|&&t| {
            let [a, b, c] = t.map(|v| simplified.positions[v as usize].map(f64::from));
            let centre = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
            let near = tree.closest(centre).expect("a triangle").triangle as usize;
            let (n, m) = (normal(simplified, t), normal(full, full.triangles[near]));
            n[0] * m[0] + n[1] * m[1] + n[2] * m[2] <= 0.0
        })
        .count()
}
