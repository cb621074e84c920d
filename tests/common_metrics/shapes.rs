//! Small meshes with known answers.
#![allow(dead_code)]

use meshsmooth::mesh::Mesh;
use std::collections::HashMap;

/// Unit cube [0,1]^3, 12 outward triangles.
pub fn cube() -> Mesh {
    let p = (0..8)
        .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    // Faces as quads (counter-clockwise from outside), split into two triangles each.
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Mesh::new(p, t)
}

/// Unit right tetrahedron, outward winding (volume 1/6).
pub fn tetrahedron() -> Mesh {
    Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

/// Icosahedron subdivided `levels` times (each triangle into four), projected onto the sphere
/// of radius `r` around `centre`.
pub fn icosphere(levels: u32, r: f64, centre: [f64; 3]) -> Mesh {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    for v in p.iter_mut() {
        *v = unit(*v);
    }
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(t.len() * 4);
        for tri in &t {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *mid.entry(key).or_insert_with(|| {
                    let (pa, pb) = (p[a as usize], p[b as usize]);
                    p.push(unit([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                    (p.len() - 1) as u32
                });
            }
            next.push([tri[0], m[0], m[2]]);
            next.push([tri[1], m[1], m[0]]);
            next.push([tri[2], m[2], m[1]]);
            next.push([m[0], m[1], m[2]]);
        }
        t = next;
    }
    let positions = p
        .iter()
        .map(|v| {
            [
                (centre[0] + r * v[0]) as f32,
                (centre[1] + r * v[1]) as f32,
                (centre[2] + r * v[2]) as f32,
            ]
        })
        .collect();
    Mesh::new(positions, t)
}

/// Flat `n` x `n` grid of unit-spaced vertices in the plane z = `z`, split along alternating
/// diagonals; open (its border is a boundary).
pub fn grid(n: u32, z: f32) -> Mesh {
    let mut p = Vec::new();
    for y in 0..n {
        for x in 0..n {
            p.push([x as f32, y as f32, z]);
        }
    }
    let mut t = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let (a, b, c, d) = (
                y * n + x,
                y * n + x + 1,
                (y + 1) * n + x,
                (y + 1) * n + x + 1,
            );
            if (x + y) % 2 == 0 {
                t.push([a, b, d]);
                t.push([a, d, c]);
            } else {
                t.push([a, b, c]);
                t.push([b, d, c]);
            }
        }
    }
    Mesh::new(p, t)
}
