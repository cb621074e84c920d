//! Discrete Gaussian curvature after Meyer, Desbrun, Schroeder and Barr (2003):
//! `K_G(i) = (2 pi - sum of the angles at i) / A_mixed(i)`.

use crate::mesh::{cross, dot, sub, to_f64, Topology};
use rayon::prelude::*;
use std::f64::consts::PI;

/// What the curvature of one vertex is made of. `angle_defect * 1 = K_G * A_mixed`, so
/// Gauss-Bonnet (`sum = 2 pi chi` on a closed mesh) holds whatever the areas are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexCurvature {
    /// `2 pi` minus the sum of the triangle angles at the vertex.
    pub angle_defect: f64,
    /// Meyer's mixed area: Voronoi area inside non-obtuse triangles, else a fixed share.
    pub mixed_area: f64,
}

impl VertexCurvature {
    /// `K_G = angle_defect / mixed_area`; `None` where the fan has no area (curvature undefined).
    pub fn gaussian(&self) -> Option<f64> {
        let k = self.angle_defect / self.mixed_area;
        (self.mixed_area > 0.0 && k.is_finite()).then_some(k)
    }
}

/// Curvature of vertex `i` over its triangle fan at `positions`.
pub fn vertex_curvature(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
    i: usize,
) -> VertexCurvature {
    let fan = fan_sums(positions, triangles, topology.triangles_of(i), i as u32);
    VertexCurvature {
        angle_defect: 2.0 * PI - fan.angle_sum,
        mixed_area: fan.mixed_area,
    }
}

/// Curvature of every vertex, in parallel (unreferenced vertices get zeros).
pub fn vertex_curvatures(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
) -> Vec<VertexCurvature> {
    (0..positions.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            if topology.triangles_of(i).is_empty() {
                VertexCurvature::default()
            } else {
                vertex_curvature(positions, triangles, topology, i)
            }
        })
        .collect()
}

/// Sums over the triangle fan of one vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FanSums {
    pub angle_sum: f64,
    pub mixed_area: f64,
    /// `p_a . (p_b x p_c)` summed over the fan's triangles whose first corner is this vertex:
    /// every triangle is counted at exactly one vertex, so the per-vertex parts add up to
    /// six times the enclosed volume. The corners are loaded here anyway.
    pub volume6: f64,
}

/// Angle sum, mixed area and volume part of vertex `i` over the triangles `fan` (all containing `i`).
#[inline]
pub(crate) fn fan_sums(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    fan: &[u32],
    i: u32,
) -> FanSums {
    let pi = to_f64(positions[i as usize]);
    let mut sums = FanSums::default();
    for &t in fan {
        let tri = triangles[t as usize];
        // The other two corners in winding order: (i, j, k) is a rotation of the triangle.
        let (j, k) = if tri[0] == i {
            (tri[1], tri[2])
        } else if tri[1] == i {
            (tri[2], tri[0])
        } else {
            (tri[0], tri[1])
        };
        let pj = to_f64(positions[j as usize]);
        let pk = to_f64(positions[k as usize]);
        let u = sub(pj, pi);
        let v = sub(pk, pi);
        let w = sub(pk, pj);
        let m = cross(u, v);
        let twice_area = dot(m, m).sqrt();
        // Dot products of the two edges leaving each corner: negative means obtuse there.
        let dot_i = dot(u, v);
        let dot_j = -dot(u, w);
        let dot_k = dot(v, w);
        // atan2 stays accurate near 0 and pi, and gives 0 rather than NaN for collapsed edges.
        sums.angle_sum += twice_area.atan2(dot_i);
        let area = 0.5 * twice_area;
        sums.mixed_area += if dot_i < 0.0 {
            0.5 * area
        } else if dot_j < 0.0 || dot_k < 0.0 {
            0.25 * area
        } else if twice_area > 0.0 {
            // Voronoi area (1/8) (|ij|^2 cot k + |ik|^2 cot j), cot = dot / |cross| = dot / (2 area).
            (dot(u, u) * dot_k + dot(v, v) * dot_j) / (8.0 * twice_area)
        } else {
            0.0
        };
        if tri[0] == i {
            sums.volume6 += dot(pi, cross(pj, pk));
        }
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    fn one_triangle(c: [f32; 3]) -> (Mesh, Topology) {
        let m = Mesh::new(vec![[0.0; 3], [2.0, 0.0, 0.0], c], vec![[0, 1, 2]]);
        let t = Topology::build(&m);
        (m, t)
    }

    fn areas(c: [f32; 3]) -> [f64; 3] {
        let (m, t) = one_triangle(c);
        let v = vertex_curvatures(&m.positions, &m.triangles, &t);
        [v[0].mixed_area, v[1].mixed_area, v[2].mixed_area]
    }

    #[test]
    fn obtuse_triangle_splits_half_and_quarters() {
        // Obtuse at vertex 2 (apex close to the base), area = 0.5.
        let a = areas([1.0, 0.5, 0.0]);
        assert_eq!(a, [0.125, 0.125, 0.25]);
    }

    #[test]
    fn right_and_equilateral_triangles_use_voronoi_areas() {
        // Right angle at vertex 0 (area 2): the circumcentre is the hypotenuse midpoint, so the
        // right-angle corner gets half the area and the other two a quarter each.
        let a = areas([0.0, 2.0, 0.0]);
        for (got, want) in a.iter().zip([1.0, 0.5, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{a:?}");
        }
        let h = 3f32.sqrt();
        let a = areas([1.0, h, 0.0]);
        let third = (h as f64) / 3.0;
        for got in a {
            assert!((got - third).abs() < 1e-6, "{a:?}");
        }
    }

    #[test]
    fn single_triangle_angles_sum_to_pi() {
        let (m, t) = one_triangle([0.3, 1.7, 0.2]);
        let defect: f64 = vertex_curvatures(&m.positions, &m.triangles, &t)
            .iter()
            .map(|c| c.angle_defect)
            .sum();
        assert!((defect - 5.0 * PI).abs() < 1e-12);
    }

    #[test]
    fn collapsed_triangle_has_no_area_and_no_nan() {
        let (m, t) = one_triangle([0.0; 3]);
        for c in vertex_curvatures(&m.positions, &m.triangles, &t) {
            assert!(c.angle_defect.is_finite());
            assert_eq!(c.mixed_area, 0.0);
            assert_eq!(c.gaussian(), None);
        }
    }
}
