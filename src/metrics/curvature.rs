//! Discrete Gaussian curvature after Meyer, Desbrun, Schroeder and Barr (2003):
//! `K_G(i) = (2 pi - sum of the angles at i) / A_mixed(i)`.

use crate::mesh::{by_blocks, cross, dot, sub, to_f64, Topology};
use rayon::prelude::*;
use std::f64::consts::PI;

/// What the curvature of one vertex is made of. `K_G * A_mixed` gives back the angle defect, so
/// Gauss-Bonnet (`sum K_G A_mixed = 2 pi chi` on a closed mesh) holds whatever the areas are.
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
    let sums = fan_sums(
        positions,
        topology.triangles_of(i),
        i as u32,
        |_, t| other_corners(triangles[t as usize], i as u32),
        |_, t| TriangleArea::new(positions, triangles[t as usize]).0,
    );
    VertexCurvature {
        angle_defect: 2.0 * PI - sums.angle_sum,
        mixed_area: sums.mixed_area,
    }
}

/// Curvature of every vertex, in parallel (unreferenced vertices get zeros).
pub fn vertex_curvatures(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
) -> Vec<VertexCurvature> {
    let (areas, _) = triangle_areas(positions, triangles);
    (0..positions.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let fan = topology.triangles_of(i);
            if fan.is_empty() {
                return VertexCurvature::default();
            }
            let sums = fan_sums(
                positions,
                fan,
                i as u32,
                |_, t| other_corners(triangles[t as usize], i as u32),
                |_, t| areas[t as usize],
            );
            VertexCurvature {
                angle_defect: 2.0 * PI - sums.angle_sum,
                mixed_area: sums.mixed_area,
            }
        })
        .collect()
}

/// What the vertex pass needs of each triangle, computed once per triangle rather than at each of
/// its three corners (the square root and the division are the costly parts).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TriangleArea {
    /// `|(b - a) x (c - a)|`.
    twice: f64,
    /// `1 / (8 |(b - a) x (c - a)|)` for the Voronoi areas; 0 for a triangle without area.
    inv_eight_twice: f64,
}

impl TriangleArea {
    /// The triangle's area data and its part of six times the enclosed volume,
    /// `a . m = a . (b x c)` with `m = (b - a) x (c - a)`.
    #[inline]
    fn new(positions: &[[f32; 3]], t: [u32; 3]) -> (Self, f64) {
        let a = to_f64(positions[t[0] as usize]);
        let b = to_f64(positions[t[1] as usize]);
        let c = to_f64(positions[t[2] as usize]);
        let m = cross(sub(b, a), sub(c, a));
        let twice = dot(m, m).sqrt();
        let inv_eight_twice = if twice > 0.0 {
            1.0 / (8.0 * twice)
        } else {
            0.0
        };
        let area = Self {
            twice,
            inv_eight_twice: if inv_eight_twice.is_finite() {
                inv_eight_twice
            } else {
                0.0
            },
        };
        (area, dot(a, m))
    }
}

/// Triangles per parallel work item of [`triangle_areas`]; partial volumes are added in this
/// order, so the volume is the same bit for bit whatever the thread count.
const TRIANGLE_CHUNK: usize = 8192;

/// Area data of every triangle and six times the enclosed volume.
pub(crate) fn triangle_areas(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> (Vec<TriangleArea>, f64) {
    let mut areas = vec![TriangleArea::default(); triangles.len()];
    let partial: Vec<f64> = areas
        .par_chunks_mut(TRIANGLE_CHUNK)
        .zip(triangles.par_chunks(TRIANGLE_CHUNK))
        .map(|(out, tris)| {
            let mut volume6 = 0.0;
            for (o, &t) in out.iter_mut().zip(tris) {
                let (area, v6) = TriangleArea::new(positions, t);
                *o = area;
                volume6 += v6;
            }
            volume6
        })
        .collect();
    (areas, partial.iter().sum())
}

/// For every entry of the vertex->triangle incidence, the triangle's other two corners in winding
/// order: the passes then read them in sequence instead of looking up every triangle.
pub(crate) fn fan_corners(triangles: &[[u32; 3]], topology: &Topology) -> Vec<[u32; 2]> {
    let offsets = &topology.triangle_offsets;
    let n = topology.vertex_count();
    let mut corners = vec![[0u32; 2]; topology.vertex_triangles.len()];
    // Filled in place, a block of vertices per task: no growing or joining of vectors.
    by_blocks(&mut corners, offsets, 0..n, 1)
        .into_par_iter()
        .for_each(|(vertices, out)| {
            let base = offsets[vertices.start] as usize;
            for i in vertices {
                let range = offsets[i] as usize..offsets[i + 1] as usize;
                let fan = &topology.vertex_triangles[range.clone()];
                let out = &mut out[range.start - base..range.end - base];
                for (o, &t) in out.iter_mut().zip(fan) {
                    let (j, k) = other_corners(triangles[t as usize], i as u32);
                    *o = [j, k];
                }
            }
        });
    corners
}

/// The corners of `tri` other than `i`, in winding order: `(i, j, k)` is a rotation of `tri`.
/// Selected by index rather than by branches, which the processor cannot predict here.
#[inline]
pub(crate) fn other_corners(tri: [u32; 3], i: u32) -> (u32, u32) {
    let c = if tri[0] == i {
        0
    } else if tri[1] == i {
        1
    } else {
        2
    };
    let ring = [tri[0], tri[1], tri[2], tri[0], tri[1]];
    (ring[c + 1], ring[c + 2])
}

/// Sums over the triangle fan of one vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FanSums {
    pub angle_sum: f64,
    pub mixed_area: f64,
}

/// Angles within this (radians, about) of 0 or pi are taken as exactly 0 or pi, so every other
/// step of [`AngleSum`] turns the product forwards by more than rounding can move it, and by less
/// than pi.
const NEGLIGIBLE_ANGLE: f64 = 1e-12;

/// Sums angles in `[0, pi]` given as `(x, y)` with `angle = atan2(y, x)`, `y >= 0`, without an
/// `atan2` per angle: it multiplies the complex numbers `x + iy` and takes one `atan2` of the
/// product at the end, counting the whole turns on the way. A step that turns the product
/// forwards by less than pi passes the positive real axis exactly when it takes the product from
/// the lower half-plane into the upper one; angles too close to 0 or pi for that are applied as
/// exact quarter turns or not at all. The common path has no unpredictable branch.
#[derive(Clone, Copy, Debug)]
struct AngleSum {
    re: f64,
    im: f64,
    /// The product lies in the lower half-plane (argument in `[pi, 2 pi)`).
    lower: bool,
    turns: u32,
}

impl AngleSum {
    fn new() -> Self {
        Self {
            re: 1.0,
            im: 0.0,
            lower: false,
            turns: 0,
        }
    }

    /// Adds `atan2(y, x)` (`y >= 0`).
    #[inline]
    fn add(&mut self, x: f64, y: f64) {
        if y > NEGLIGIBLE_ANGLE * x.abs() {
            self.step(self.re * x - self.im * y, self.re * y + self.im * x);
            // Factors are unnormalised (|u| |v|): rescale before the product over- or underflows.
            let size = self.re.abs() + self.im.abs();
            if !(1e-150..=1e150).contains(&size) {
                self.re /= size;
                self.im /= size;
            }
        } else if x < 0.0 {
            // A straight angle: two exact quarter turns.
            self.step(-self.im, self.re);
            self.step(-self.im, self.re);
        }
    }

    /// Moves the product to `re + i im`, counting a pass over the positive real axis.
    #[inline]
    fn step(&mut self, re: f64, im: f64) {
        let lower = (im < 0.0) | ((im == 0.0) & (re < 0.0));
        self.turns += (self.lower & !lower) as u32;
        self.lower = lower;
        self.re = re;
        self.im = im;
    }

    fn total(&self) -> f64 {
        let mut wrapped = self.im.atan2(self.re);
        if wrapped < 0.0 {
            wrapped += 2.0 * PI;
        }
        wrapped + 2.0 * PI * self.turns as f64
    }
}

/// Angle sum and mixed area of vertex `i` over the triangles `fan` (all containing `i`);
/// `corners(k, t)` gives the other two corners of triangle `t`, the `k`-th of the fan, in
/// winding order, and `area(k, t)` its area data.
#[inline]
pub(crate) fn fan_sums(
    positions: &[[f32; 3]],
    fan: &[u32],
    i: u32,
    corners: impl Fn(usize, u32) -> (u32, u32),
    area: impl Fn(usize, u32) -> TriangleArea,
) -> FanSums {
    let pi = to_f64(positions[i as usize]);
    let mut sums = FanSums::default();
    let mut angles = AngleSum::new();
    for (n, &t) in fan.iter().enumerate() {
        let (j, k) = corners(n, t);
        let pj = to_f64(positions[j as usize]);
        let pk = to_f64(positions[k as usize]);
        let u = sub(pj, pi);
        let v = sub(pk, pi);
        let TriangleArea {
            twice,
            inv_eight_twice,
        } = area(n, t);
        // Dot products of the two edges leaving each corner (negative: obtuse there); at j and k
        // from |u|^2, |v|^2 and u.v, since pk - pj = v - u.
        let (uu, vv) = (dot(u, u), dot(v, v));
        let dot_i = dot(u, v);
        let dot_j = uu - dot_i;
        let dot_k = vv - dot_i;
        angles.add(dot_i, twice);
        let half = 0.5 * twice;
        // Voronoi area (1/8) (|ij|^2 cot k + |ik|^2 cot j), cot = dot / |cross|; area/2 if
        // obtuse at i, area/4 if obtuse elsewhere. Picked by index: obtuse or not is a coin toss
        // on a staircase mesh, and a mispredicted branch costs more than all three candidates.
        let voronoi = (uu * dot_k + vv * dot_j) * inv_eight_twice;
        let obtuse_i = dot_i < 0.0;
        let obtuse = obtuse_i | (dot_j < 0.0) | (dot_k < 0.0);
        sums.mixed_area += [voronoi, 0.25 * half, 0.5 * half][obtuse as usize + obtuse_i as usize];
    }
    sums.angle_sum = angles.total();
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

    /// Reference: one atan2 per triangle.
    fn angle_sum_by_atan2(positions: &[[f32; 3]], triangles: &[[u32; 3]], i: usize) -> f64 {
        triangles
            .iter()
            .filter(|t| t.contains(&(i as u32)))
            .map(|t| {
                let k = t.iter().position(|&v| v as usize == i).unwrap_or(0);
                let p = to_f64(positions[i]);
                let u = sub(to_f64(positions[t[(k + 1) % 3] as usize]), p);
                let v = sub(to_f64(positions[t[(k + 2) % 3] as usize]), p);
                let m = cross(u, v);
                dot(m, m).sqrt().atan2(dot(u, v))
            })
            .sum()
    }

    #[test]
    fn angle_sums_by_product_match_atan2_for_any_fan_size() {
        // A cone apex over a regular polygon of n rim vertices: angle sums from tiny to 2 pi,
        // with right, acute and obtuse angles.
        for n in [3usize, 4, 6, 7, 12, 40, 41, 64] {
            for height in [0.0f32, 0.01, 0.3, 1.0, 5.0, 200.0] {
                let mut positions = vec![[0.0, 0.0, height]];
                for k in 0..n {
                    let a = 2.0 * std::f32::consts::PI * k as f32 / n as f32;
                    positions.push([a.cos(), a.sin(), 0.0]);
                }
                let triangles: Vec<[u32; 3]> = (0..n as u32)
                    .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
                    .collect();
                let m = Mesh::new(positions, triangles);
                let t = Topology::build(&m);
                let got =
                    2.0 * PI - vertex_curvature(&m.positions, &m.triangles, &t, 0).angle_defect;
                let want = angle_sum_by_atan2(&m.positions, &m.triangles, 0);
                assert!(
                    (got - want).abs() < 1e-12,
                    "n {n} h {height}: {got} vs {want}"
                );
            }
        }
        // A fan folded over itself: triangles with angles near pi at the apex, many whole turns.
        let mut positions = vec![[0.0f32, 0.0, 0.0]];
        for k in 0..30 {
            let s = if k % 2 == 0 { 1.0 } else { -1.0 };
            positions.push([s, 0.001 * k as f32, 0.0]);
        }
        let triangles: Vec<[u32; 3]> = (1..30u32).map(|k| [0, k, k + 1]).collect();
        let m = Mesh::new(positions, triangles);
        let t = Topology::build(&m);
        let got = 2.0 * PI - vertex_curvature(&m.positions, &m.triangles, &t, 0).angle_defect;
        let want = angle_sum_by_atan2(&m.positions, &m.triangles, 0);
        assert!(want > 8.0 * PI);
        assert!((got - want).abs() < 1e-10, "{got} vs {want}");
    }

    #[test]
    fn angle_sum_counts_whole_turns() {
        // Exact axis values, tiny and near-pi angles, and scaled factors, in a fixed mix.
        let special: [(f64, f64, f64); 7] = [
            (1.0, 0.0, 0.0),
            (0.0, 3.0, PI / 2.0),
            (-2.0, 0.0, PI),
            (1.0, 1e-14, 1e-14),
            (-1.0, 1e-13, PI - 1e-13),
            (-1e-13, 1.0, PI / 2.0 + 1e-13),
            (1e-20, 1e-20, PI / 4.0),
        ];
        for n in 1..60usize {
            let mut sum = AngleSum::new();
            let mut want = 0.0;
            for k in 0..n {
                let (x, y, angle) = if k % 3 == 0 {
                    special[(k * 5 + n) % special.len()]
                } else {
                    let a = ((k * 7 + n * 3) % 97) as f64 / 97.0 * PI;
                    let r = 1e3f64.powf(((k + n) % 5) as f64 - 2.0);
                    (r * a.cos(), r * a.sin(), a)
                };
                sum.add(x, y);
                want += angle;
            }
            let got = sum.total();
            assert!((got - want).abs() < 1e-11, "n {n}: {got} vs {want}");
        }
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
