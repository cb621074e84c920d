//! Discrete Gaussian curvature after Meyer, Desbrun, Schroeder and Barr (2003):
//! `K_G(i) = (2 pi - sum of the angles at i) / A_mixed(i)`.
//!
//! Two passes: one over the triangles works out each triangle's angles and its corners' parts of
//! the mixed areas (and the volume), in blocks the processor takes several triangles at a time;
//! one over the vertices adds up the parts of each vertex's fan.

use crate::mesh::{by_blocks, cross32, dot32, sub32, Topology};
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

    /// The curvature of a vertex from its fan: the corners it has in its triangles, by their
    /// places in the list of all corners ([`CornerCode`]).
    #[inline]
    pub(crate) fn of_fan(corners: &[CornerShape], fan: impl Iterator<Item = usize>) -> Self {
        let (mut angle_sum, mut mixed_area) = (0i64, 0.0);
        for code in fan {
            let c = corners[code];
            angle_sum += i64::from(c.angle);
            mixed_area += f64::from(c.mixed);
        }
        Self {
            angle_defect: (2 * HALF_TURN - angle_sum) as f64 * ANGLE_UNIT,
            mixed_area,
        }
    }
}

/// Curvature of every vertex, in parallel (unreferenced vertices get zeros).
pub fn vertex_curvatures(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
) -> Vec<VertexCurvature> {
    let (corners, _) = triangle_shapes(positions, triangles);
    (0..positions.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let fan = topology.triangles_of(i).iter().map(|&t| {
                let (corner, _, _) = other_corners(triangles[t as usize], i as u32);
                CornerCode::new(t, corner).index()
            });
            VertexCurvature::of_fan(&corners, fan)
        })
        .collect()
}

/// An angle of pi in the fixed-point unit of [`CornerShape::angle`].
const HALF_TURN: i64 = 1 << 30;

/// The fixed-point angle unit in radians: pi / 2^30, about 2.9e-9.
const ANGLE_UNIT: f64 = PI / HALF_TURN as f64;

/// What the vertex pass needs of one corner of a triangle: its angle and its part of the mixed
/// area. The corners lie three per triangle in triangle order, so a vertex reads its own by
/// their place ([`CornerCode`]).
///
/// Angles are integers in units of pi / 2^30, and a triangle's third angle is 2^30 minus the
/// other two: every triangle's angles add up to pi exactly, so Gauss-Bonnet holds to the
/// rounding of the vertex sums, whatever the rounding of each angle. A triangle without area
/// has no such sum: two corners in one place leave the third an angle of 0.
///
/// The angles come from a polynomial arctangent within 3e-7 radians in single precision (f32
/// rounding near pi), far below what the f32 positions themselves carry (one unit in the last
/// place of a 100 mm coordinate moves a 1 mm edge's direction by about 1e-5 radians); the
/// fixed point adds at most 1.5e-9.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CornerShape {
    /// The angle at the corner, in units of pi / 2^30.
    angle: i32,
    /// The corner's part of the mixed area: the Voronoi area `(1/8) sum(cot * |e|^2)` if the
    /// triangle is not obtuse, half the area at an obtuse corner, else a quarter.
    mixed: f32,
}

/// Triangles per parallel work item of [`triangle_shapes`]; partial volumes are added in this
/// order, so the volume is the same bit for bit whatever the thread count.
const TRIANGLE_CHUNK: usize = 8192;

const PI32: f32 = std::f32::consts::PI;

/// Triangles gathered and worked out together, one per lane of the processor's vector unit.
const BLOCK: usize = 64;

/// The corners of every triangle ([`CornerShape`], three per triangle) and six times the
/// enclosed volume.
pub(crate) fn triangle_shapes(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> (Vec<CornerShape>, f64) {
    let mut corners = Vec::new();
    let volume6 = triangle_shapes_into(positions, triangles, &mut corners);
    (corners, volume6)
}

/// [`triangle_shapes`] into `corners` (resized to three per triangle), so a caller measuring
/// again and again can keep the memory: returns six times the enclosed volume.
pub(crate) fn triangle_shapes_into(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    corners: &mut Vec<CornerShape>,
) -> f64 {
    corners.resize(3 * triangles.len(), CornerShape::default());
    // The volume's terms are taken about a point of the mesh, which keeps them small: on a
    // closed mesh, where the volume means something, the point does not change the sum.
    let origin = triangles
        .first()
        .map_or([0.0; 3], |t| positions[t[0] as usize]);
    let partial: Vec<f64> = corners
        .par_chunks_mut(3 * TRIANGLE_CHUNK)
        .zip(triangles.par_chunks(TRIANGLE_CHUNK))
        .map(|(out, tris)| {
            out.chunks_mut(3 * BLOCK)
                .zip(tris.chunks(BLOCK))
                .map(|(out, tris)| shape_block(positions, tris, origin, out))
                .sum::<f64>()
        })
        .collect();
    partial.iter().sum()
}

/// The shapes of up to [`BLOCK`] triangles and their part of six times the volume, on the
/// processor's widest vectors ([`super::wide`]). Chosen per block, where the check (a cached
/// flag) costs nothing next to 64 triangles: a wide copy of the loop over blocks would run it
/// through the iterator adapters' generic code, which is built without the wide features, and
/// lose most of the gain.
fn shape_block(
    positions: &[[f32; 3]],
    tris: &[[u32; 3]],
    origin: [f32; 3],
    out: &mut [CornerShape],
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if super::wide::available() {
        // SAFETY: the processor has the features `shape_block_wide` is built with.
        return unsafe { shape_block_wide(positions, tris, origin, out) };
    }
    shape_block_kernel(positions, tris, origin, out)
}

/// [`shape_block_kernel`] on AVX-512 (see [`super::wide`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma")]
fn shape_block_wide(
    positions: &[[f32; 3]],
    tris: &[[u32; 3]],
    origin: [f32; 3],
    out: &mut [CornerShape],
) -> f64 {
    shape_block_kernel(positions, tris, origin, out)
}

/// The shapes of up to [`BLOCK`] triangles and their part of six times the volume. The corners
/// are gathered into one array per coordinate, so the arithmetic runs on whole vectors of
/// triangles; lanes past the last triangle compute on zeros and are dropped.
#[inline(always)]
fn shape_block_kernel(
    positions: &[[f32; 3]],
    tris: &[[u32; 3]],
    origin: [f32; 3],
    out: &mut [CornerShape],
) -> f64 {
    let mut p = [[[0.0f32; BLOCK]; 3]; 3];
    for (lane, t) in tris.iter().enumerate() {
        for (corner, &v) in t.iter().enumerate() {
            let q = positions[v as usize];
            for k in 0..3 {
                p[corner][k][lane] = q[k];
            }
        }
    }
    let mut angles = [[0i32; BLOCK]; 3];
    let mut mixed = [[0.0f32; BLOCK]; 3];
    let mut volume6 = [0.0f32; BLOCK];
    for l in 0..BLOCK {
        let corner = |c: usize| [p[c][0][l], p[c][1][l], p[c][2][l]];
        let (a, b, c) = (corner(0), corner(1), corner(2));
        let (ab, ac, bc) = (sub32(b, a), sub32(c, a), sub32(c, b));
        let m = cross32(ab, ac);
        let twice = dot32(m, m).sqrt();
        // The dot product of the two edges leaving each corner: negative where it is obtuse.
        let dots = [dot32(ab, ac), -dot32(ab, bc), dot32(ac, bc)];
        let lengths2 = [dot32(bc, bc), dot32(ac, ac), dot32(ab, ab)];
        angles[0][l] = fixed_angle(angle(dots[0], twice));
        angles[1][l] = fixed_angle(angle(dots[1], twice));
        // Without area, each angle is 0 or pi by the sign of its dot product.
        let flat = if dots[2] < 0.0 { HALF_TURN as i32 } else { 0 };
        angles[2][l] = if twice > 0.0 {
            HALF_TURN as i32 - angles[0][l] - angles[1][l]
        } else {
            flat
        };
        let inv_eight_twice = if twice > 0.0 {
            1.0 / (8.0 * twice)
        } else {
            0.0
        };
        let obtuse = (dots[0] < 0.0) | (dots[1] < 0.0) | (dots[2] < 0.0);
        for corner in 0..3 {
            let (next, prev) = ((corner + 1) % 3, (corner + 2) % 3);
            // (1/8) (|e|^2 cot) over the two edges at this corner; each edge's cot is that of
            // the corner opposite it, cot = dot / |cross|.
            let voronoi =
                (lengths2[prev] * dots[prev] + lengths2[next] * dots[next]) * inv_eight_twice;
            // Selects rather than branches: obtuse or not is a coin toss on a staircase mesh.
            mixed[corner][l] = if !obtuse {
                voronoi
            } else if dots[corner] < 0.0 {
                0.25 * twice
            } else {
                0.125 * twice
            };
        }
        // Edges are differences of nearby coordinates, exact in f32; the volume's terms, taken
        // about the origin point, are only as good as f32's rounding of the shifted corner.
        volume6[l] = dot32(sub32(a, origin), m);
    }
    for (lane, o) in out.chunks_exact_mut(3).enumerate() {
        let o: &mut [CornerShape; 3] = o.try_into().unwrap();
        *o = [0, 1, 2].map(|c| CornerShape {
            angle: angles[c][lane],
            mixed: mixed[c][lane],
        });
    }
    // Lanes past the last triangle hold 0 (no area). Eight running sums, a vector of them,
    // instead of one chain of dependent additions; added in a fixed order, so the volume is
    // the same bit for bit on every run and thread count.
    const SUMS: usize = 8;
    let mut sums = [0.0f64; SUMS];
    for run in volume6.chunks_exact(SUMS) {
        for (s, &v) in sums.iter_mut().zip(run) {
            *s += f64::from(v);
        }
    }
    ((sums[0] + sums[4]) + (sums[1] + sums[5])) + ((sums[2] + sums[6]) + (sums[3] + sums[7]))
}

/// An angle in `[0, pi]` (radians, within f32's rounding) in units of pi / 2^30, to the nearest.
/// Rounded by adding 1.5 * 2^52, which leaves the integer in the low bits of the sum: plain
/// arithmetic the processor runs on whole vectors, where a float-to-integer cast checks its
/// range one lane at a time.
#[inline]
fn fixed_angle(radians: f32) -> i32 {
    const PER_RADIAN: f64 = HALF_TURN as f64 / PI;
    const ROUND: f64 = 6_755_399_441_055_744.0;
    (f64::from(radians) * PER_RADIAN + ROUND).to_bits() as i32
}

/// `atan2(y, x)` for `y >= 0`, in `[0, pi]`, within 3e-7 (f32 steps are 2.4e-7 near pi): the arctangent of the smaller of
/// `|x|` and `y` over the larger, by a polynomial, turned into the right octant by selects (so
/// a block of angles runs as vectors).
#[inline]
fn angle(x: f32, y: f32) -> f32 {
    use std::f32::consts::FRAC_PI_2;
    let ax = x.abs();
    // `ax.min(y)` and `ax.max(y)` as selects, NaNs included: wasm has no instruction for
    // Rust's `f32::min` and calls a function, which keeps this loop from running as vectors.
    let lo = if y < ax || ax.is_nan() { y } else { ax };
    let hi = if y > ax || ax.is_nan() { y } else { ax };
    let t = if hi > 0.0 { lo / hi } else { 0.0 };
    let a = t * atan_polynomial(t * t);
    let a = if y > ax { FRAC_PI_2 - a } else { a };
    if x < 0.0 {
        PI32 - a
    } else {
        a
    }
}

/// `atan(sqrt(s)) / sqrt(s)` on `[0, 1]`: its Chebyshev interpolant of degree 8 in `s`, within
/// 1e-8 (the f32 evaluation rounds to about 1e-7).
#[inline]
fn atan_polynomial(s: f32) -> f32 {
    const C: [f32; 9] = [
        0.999_999_98,
        -0.333_330_37,
        0.199_918_72,
        -0.141_977_98,
        0.106_183_71,
        -0.074_568_55,
        0.042_137_62,
        -0.015_731_25,
        0.002_766_28,
    ];
    C.iter().rev().fold(0.0, |p, &c| p * s + c)
}

/// For every entry of the vertex->triangle incidence, the triangle's other two corners in winding
/// order, and the triangle with the vertex's corner in it as a [`CornerCode`]: the passes then
/// read them in sequence instead of looking up every triangle.
pub(crate) fn fan_corners(
    triangles: &[[u32; 3]],
    topology: &Topology,
) -> (Vec<[u32; 2]>, Vec<CornerCode>) {
    let offsets = &topology.triangle_offsets;
    let n = topology.vertex_count();
    let incidences = topology.vertex_triangles.len();
    let mut corners = vec![[0u32; 2]; incidences];
    let mut codes = vec![CornerCode(0); incidences];
    // Filled in place, a block of vertices per task: no growing or joining of vectors.
    by_blocks(&mut corners, offsets, 0..n, 1)
        .into_par_iter()
        .zip(by_blocks(&mut codes, offsets, 0..n, 1))
        .for_each(|((vertices, out), (_, codes))| {
            let base = offsets[vertices.start] as usize;
            for i in vertices {
                let range = offsets[i] as usize - base..offsets[i + 1] as usize - base;
                let fan = topology.triangles_of(i);
                for ((o, code), &t) in out[range.clone()]
                    .iter_mut()
                    .zip(&mut codes[range])
                    .zip(fan)
                {
                    let (corner, j, k) = other_corners(triangles[t as usize], i as u32);
                    *o = [j, k];
                    *code = CornerCode::new(t, corner);
                }
            }
        });
    (corners, codes)
}

/// A triangle's corner by its place in the list of all corners, three per triangle: the
/// incidence count fits in 32 bits (the topology's offsets), so these do too.
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(transparent)]
pub(crate) struct CornerCode(u32);

impl CornerCode {
    fn new(triangle: u32, corner: usize) -> Self {
        Self(3 * triangle + corner as u32)
    }

    /// The corner's place in the list of all corners, three per triangle.
    #[inline]
    pub(crate) fn index(self) -> usize {
        self.0 as usize
    }
}

/// Which corner of `tri` is `i` (the first if `i` is not one), and the other two in winding
/// order: `(i, j, k)` is a rotation of `tri`. Selected by index rather than by branches, which
/// the processor cannot predict here.
#[inline]
pub(crate) fn other_corners(tri: [u32; 3], i: u32) -> (usize, u32, u32) {
    let c = if tri[0] == i {
        0
    } else if tri[1] == i {
        1
    } else {
        2
    };
    let ring = [tri[0], tri[1], tri[2], tri[0], tri[1]];
    (c, ring[c + 1], ring[c + 2])
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

    /// Reference: one f64 atan2 per triangle.
    fn angle_sum_by_atan2(positions: &[[f32; 3]], triangles: &[[u32; 3]], i: usize) -> f64 {
        use crate::mesh::{cross, dot, sub, to_f64};
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

    fn angle_sum(m: &Mesh, i: usize) -> f64 {
        let t = Topology::build(m);
        2.0 * PI - vertex_curvatures(&m.positions, &m.triangles, &t)[i].angle_defect
    }

    #[test]
    fn polynomial_angle_is_atan2_within_its_bound() {
        // Every direction of the upper half-plane, at scales from tiny to huge, plus the axes.
        let mut worst = 0.0f64;
        for scale in [1e-20f32, 1e-3, 1.0, 7.5, 1e4, 1e20] {
            for k in 0..=20_000 {
                let a = PI * k as f64 / 20_000.0;
                let (x, y) = (
                    (scale as f64 * a.cos()) as f32,
                    (scale as f64 * a.sin()) as f32,
                );
                let want = (y.max(0.0) as f64).atan2(x as f64);
                worst = worst.max((angle(x, y.max(0.0)) as f64 - want).abs());
            }
        }
        assert!(worst < 3e-7, "worst {worst}");
        assert_eq!([angle(1.0, 0.0), angle(0.0, 0.0)], [0.0, 0.0]);
        assert_eq!(angle(-3.0, 0.0), std::f32::consts::PI);
    }

    #[test]
    fn fan_angle_sums_match_atan2() {
        // A cone apex over a regular polygon of n rim vertices: angle sums from tiny to 2 pi,
        // with right, acute and obtuse angles; each angle within the polynomial's bound.
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
                let (got, want) = (
                    angle_sum(&m, 0),
                    angle_sum_by_atan2(&m.positions, &m.triangles, 0),
                );
                assert!(
                    (got - want).abs() < 2e-7 * n as f64,
                    "n {n} h {height}: {got} vs {want}"
                );
            }
        }
        // A fan folded over itself: angles near pi at the apex, many whole turns, and the
        // third corners' angles (pi minus the other two) near 0.
        let mut positions = vec![[0.0f32, 0.0, 0.0]];
        for k in 0..30 {
            let s = if k % 2 == 0 { 1.0 } else { -1.0 };
            positions.push([s, 0.001 * k as f32, 0.0]);
        }
        let triangles: Vec<[u32; 3]> = (1..30u32).map(|k| [k, k + 1, 0]).collect();
        let m = Mesh::new(positions, triangles);
        let (got, want) = (
            angle_sum(&m, 0),
            angle_sum_by_atan2(&m.positions, &m.triangles, 0),
        );
        assert!(want > 8.0 * PI);
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
    }

    #[test]
    fn collinear_triangle_has_angles_zero_zero_pi() {
        let m = Mesh::new(
            vec![[0.0; 3], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            vec![[0, 1, 2]],
        );
        let t = Topology::build(&m);
        let c = vertex_curvatures(&m.positions, &m.triangles, &t);
        let angles: Vec<f64> = c.iter().map(|c| 2.0 * PI - c.angle_defect).collect();
        assert_eq!(angles, [0.0, 0.0, PI]);
    }

    #[test]
    fn triangle_with_two_corners_in_one_place_has_no_angle_at_the_third() {
        // Where smoothing pulls two boundary vertices together: the edges from the third
        // corner coincide, an angle of 0 there (not pi minus two undefined angles).
        for c in 0..3 {
            let mut positions = vec![[1.0, 1.0, 0.0]; 3];
            positions[c] = [4.0, -2.0, 0.5];
            let m = Mesh::new(positions, vec![[0, 1, 2]]);
            let t = Topology::build(&m);
            let v = vertex_curvatures(&m.positions, &m.triangles, &t);
            let at_c = 2.0 * PI - v[c].angle_defect;
            assert!(at_c.abs() < 1e-6, "corner {c}: {at_c}");
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
