//! Roughness: how much of a mesh's shape is high-frequency, the quantity a smoothing filter
//! exists to reduce. `R = sum_i n_i |L(q)_i|^2`: the umbrella vector of each vertex, weighted by
//! its neighbour count. The neighbours are read from the vertex's triangles: `n_i` triangles,
//! each naming the corner after `i` in its winding. On a closed, consistently oriented mesh
//! that is the 1-ring `N(i)`, each neighbour once; at a boundary it leaves out one boundary
//! neighbour. (The GPU engine reads the same corners in its measure pass.) Isolated vertices add
//! nothing.
//!
//! Why this one: the filters are Jacobi steps of the umbrella operator `L`, which is
//! self-adjoint in the inner product weighted by `n_i`. A filter that is a polynomial `f(L)`
//! (Laplace, Taubin, windowed sinc; HC is close to one) multiplies each eigenvector by `f` of its
//! eigenvalue, and `R` is the `n`-weighted norm of `L q`, so on a closed mesh it can only grow
//! when `|f| > 1` somewhere in the spectrum: the filter amplifies some frequency instead of
//! damping it, and iterating it blows the mesh up. Taubin with a small lambda and a large |mu|
//! and HC with beta below about 0.5 do that on staircase meshes, whose spectrum reaches the
//! highest frequencies. The score S cannot tell: a blown-up mesh is large, its curvature K is
//! small, and the error term E/(E+1) saturates. So the searches rank a parameter set that leaves
//! the mesh rougher than the original after every set that does not ([`crate::suggest`]).

use super::Original;
use rayon::prelude::*;

/// Vertices per parallel task.
const CHUNK: usize = 4096;

/// `R` of `positions` on `original`'s triangles. Each vertex's term is computed in f32, as the
/// GPU engine's measure pass does; the terms are summed in f64, in chunk order (the same for
/// any thread count).
pub fn roughness(original: &Original, positions: &[[f32; 3]]) -> f64 {
    assert_eq!(
        positions.len(),
        original.mesh().vertex_count(),
        "positions must belong to the original mesh"
    );
    let partial: Vec<f64> = (0..positions.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let end = ((c + 1) * CHUNK).min(positions.len());
            (c * CHUNK..end)
                .map(|i| f64::from(vertex_roughness(positions, original.fan_corners(i), i)))
                .sum::<f64>()
        })
        .collect();
    partial.iter().sum()
}

/// `n_i |L(q)_i|^2` in f32: the next corners' sum, scaled by `1/n`, less the vertex.
#[inline]
fn vertex_roughness(positions: &[[f32; 3]], fan: &[[u32; 2]], i: usize) -> f32 {
    if fan.is_empty() {
        return 0.0;
    }
    let mut sum = [0.0f32; 3];
    for &[j, _] in fan {
        let q = positions[j as usize];
        for k in 0..3 {
            sum[k] += q[k];
        }
    }
    let n = fan.len() as f32;
    let inv = 1.0 / n;
    let p = positions[i];
    let d = [
        sum[0] * inv - p[0],
        sum[1] * inv - p[1],
        sum[2] * inv - p[2],
    ];
    n * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
}

/// `R / R0`: 1 for the unchanged mesh. An original without roughness (every vertex at its ring's
/// mean) gives 1 while the result stays so, and infinity once it does not.
pub fn roughness_ratio(roughness: f64, roughness0: f64) -> f64 {
    if roughness0 > 0.0 {
        roughness / roughness0
    } else if roughness > 0.0 {
        f64::INFINITY
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::{double_cone, grid, tetrahedron};
    use crate::mesh::{Mesh, Topology};

    /// The definition in f64 with dense loops: for each vertex, the corner after it in each of
    /// its triangles, then `n |mean - p|^2`.
    fn naive(mesh: &Mesh) -> f64 {
        let n = mesh.vertex_count();
        let mut total = 0.0;
        for i in 0..n {
            let mut ring: Vec<usize> = Vec::new();
            for t in &mesh.triangles {
                for c in 0..3 {
                    if t[c] as usize == i {
                        ring.push(t[(c + 1) % 3] as usize);
                    }
                }
            }
            if ring.is_empty() {
                continue;
            }
            let p = mesh.positions[i];
            let mut d2 = 0.0;
            for (k, &pk) in p.iter().enumerate() {
                let mean = ring
                    .iter()
                    .map(|&j| f64::from(mesh.positions[j][k]))
                    .sum::<f64>()
                    / ring.len() as f64;
                d2 += (mean - f64::from(pk)).powi(2);
            }
            total += ring.len() as f64 * d2;
        }
        total
    }

    #[test]
    fn roughness_follows_its_definition() {
        let mut bumpy = grid(9, 7);
        for (i, p) in bumpy.positions.iter_mut().enumerate() {
            p[2] = ((i * 7919) % 13) as f32 * 0.1;
        }
        for mesh in [tetrahedron(), double_cone(7), bumpy] {
            let original = Original::new(&mesh, &Topology::build(&mesh));
            let got = roughness(&original, &mesh.positions);
            let want = naive(&mesh);
            assert!(want > 0.0);
            assert!((got - want).abs() <= 1e-5 * want, "{got} against {want}");
        }
    }

    #[test]
    fn roughness_grows_with_the_square_of_the_size() {
        let mesh = double_cone(9);
        let original = Original::new(&mesh, &Topology::build(&mesh));
        let r = roughness(&original, &mesh.positions);
        let scaled: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.map(|x| 3.0 * x)).collect();
        let r3 = roughness(&original, &scaled);
        assert_eq!(original.roughness(), r);
        assert!(r > 0.0);
        assert!((r3 / r - 9.0).abs() < 1e-5, "{r3} against 9 x {r}");
    }

    #[test]
    fn the_ratio_is_one_for_the_unchanged_mesh() {
        assert_eq!(roughness_ratio(2.5, 2.5), 1.0);
        assert_eq!(roughness_ratio(1.0, 4.0), 0.25);
        assert_eq!(roughness_ratio(0.0, 0.0), 1.0);
        assert_eq!(roughness_ratio(1e-9, 0.0), f64::INFINITY);
    }
}
