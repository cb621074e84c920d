//! The quality measures written as ALGORITHMS.md states them ("Quality measures"): plain loops
//! over the triangles, f64 throughout, brute force where the tuned pass is clever. This is the
//! definition the tuned measures ([`super::measure`], [`super::Original`], the drifting
//! reference, the GPU engine's measure pass) are tested against; it is slow by design, meant
//! for small meshes and tests.
//!
//! Positions come in as f64 ([`Point`]); the original mesh's connectivity and positions are
//! read from its [`Mesh`].

use std::f64::consts::PI;

use super::{Metrics, VertexCurvature};
use crate::mesh::Mesh;
use crate::smooth::reference::{edge_uses, smooth_steps, to_points, Point, Rings};
use crate::smooth::Params;

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Point, b: Point) -> Point {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn length(a: Point) -> f64 {
    dot(a, a).sqrt()
}

// ---------------------------------------------------------------- volume

/// No edge is used by exactly one triangle, and there is a triangle: only then does an
/// enclosed volume mean something.
pub fn is_closed(mesh: &Mesh) -> bool {
    !mesh.triangles.is_empty() && edge_uses(mesh).iter().all(|&(_, uses)| uses != 1)
}

/// `V = (1/6) sum_t p_a . (p_b x p_c)` (divergence theorem) of `positions` on `mesh`'s
/// triangles; `None` where the mesh is open.
pub fn volume(mesh: &Mesh, positions: &[Point]) -> Option<f64> {
    if !is_closed(mesh) {
        return None;
    }
    let sum: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            dot(a, cross(b, c))
        })
        .sum();
    Some(sum / 6.0)
}

// ---------------------------------------------------------------- curvature

/// Per vertex, `2 pi` minus the angles of its triangles at it, and Meyer's mixed area
/// (Meyer, Desbrun, Schroeder and Barr 2003). A vertex no triangle uses gets `2 pi` and 0.
pub fn vertex_curvatures(mesh: &Mesh, positions: &[Point]) -> Vec<VertexCurvature> {
    let mut angle_sums = vec![0.0; positions.len()];
    let mut areas = vec![0.0; positions.len()];
    for t in &mesh.triangles {
        let corners = t.map(|v| positions[v as usize]);
        for c in 0..3 {
            let i = t[c] as usize;
            let (next, prev) = (corners[(c + 1) % 3], corners[(c + 2) % 3]);
            angle_sums[i] += angle(corners[c], next, prev);
            areas[i] += mixed_area_share(corners, c);
        }
    }
    angle_sums
        .into_iter()
        .zip(areas)
        .map(|(sum, mixed_area)| VertexCurvature {
            angle_defect: 2.0 * PI - sum,
            mixed_area,
        })
        .collect()
}

/// The angle at `at` between the edges to `a` and `b`, in [0, pi].
fn angle(at: Point, a: Point, b: Point) -> f64 {
    let (u, v) = (sub(a, at), sub(b, at));
    length(cross(u, v)).atan2(dot(u, v))
}

/// Corner `c`'s part of the mixed area: in a triangle that is not obtuse, the Voronoi area
/// `(1/8) sum(cot * |e|^2)` over the two edges at the corner (each edge's cot is that of the
/// angle opposite it); in an obtuse one, half the area at the obtuse corner, else a quarter.
/// A triangle without area gives nothing (its cotangents are undefined).
fn mixed_area_share(p: [Point; 3], c: usize) -> f64 {
    let twice_area = length(cross(sub(p[1], p[0]), sub(p[2], p[0])));
    if twice_area == 0.0 {
        return 0.0;
    }
    // The dot product of the two edges leaving corner k: negative where it is obtuse.
    let edge_dot = |k: usize| dot(sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
    let cot = |k: usize| edge_dot(k) / twice_area;
    if edge_dot(c) < 0.0 {
        return twice_area / 4.0;
    }
    if (0..3).any(|k| edge_dot(k) < 0.0) {
        return twice_area / 8.0;
    }
    let (next, prev) = ((c + 1) % 3, (c + 2) % 3);
    let squared = |a: Point, b: Point| dot(sub(a, b), sub(a, b));
    (squared(p[c], p[next]) * cot(prev) + squared(p[c], p[prev]) * cot(next)) / 8.0
}

/// `K_G(i) = angle defect / A_mixed` of every vertex that counts in the curvature measure:
/// interior (on no boundary edge), used by some triangle, with a mixed area. `None` for the
/// others.
pub fn gaussian_curvatures(mesh: &Mesh, positions: &[Point]) -> Vec<Option<f64>> {
    let mut counted = vec![false; positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            counted[v as usize] = true;
        }
    }
    for ([a, b], uses) in edge_uses(mesh) {
        if uses == 1 {
            counted[a as usize] = false;
            counted[b as usize] = false;
        }
    }
    vertex_curvatures(mesh, positions)
        .into_iter()
        .zip(counted)
        .map(|(c, counted)| {
            let k = c.angle_defect / c.mixed_area;
            (counted && c.mixed_area > 0.0 && k.is_finite()).then_some(k)
        })
        .collect()
}

/// K: the mean of `|K_G|` over the vertices that count (0 if none does).
pub fn curvature(mesh: &Mesh, positions: &[Point]) -> f64 {
    let k: Vec<f64> = gaussian_curvatures(mesh, positions)
        .into_iter()
        .flatten()
        .map(f64::abs)
        .collect();
    mean(&k)
}

fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

// ---------------------------------------------------------------- local error

/// One step of the drifting reference: each vertex's reference `r` moves to whichever of `r`
/// and its 1-ring on the original is closest to the vertex's position. Ties keep `r`, then
/// the first (lowest) neighbour, so a vertex that does not move keeps its reference.
pub fn drift_step(
    one_ring: &Rings,
    original: &[Point],
    positions: &[Point],
    reference: &mut [u32],
) {
    for (r, &q) in reference.iter_mut().zip(positions) {
        let distance = |j: u32| length(sub(q, original[j as usize]));
        let mut best = *r;
        for &j in one_ring.ring(*r as usize) {
            if distance(j) < distance(best) {
                best = j;
            }
        }
        *r = best;
    }
}

/// Smooths `mesh` with the reference filters ([`smooth_steps`]) while each vertex's reference
/// drifts after every step: the positions and the references, ready for [`measure`].
pub fn smooth_drifting(
    mesh: &Mesh,
    params: &Params,
    weights: Option<&[f32]>,
) -> (Vec<Point>, Vec<u32>) {
    let one_ring = Rings::one_ring(mesh);
    let original = to_points(&mesh.positions);
    let mut reference: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
    let q = smooth_steps(mesh, params, weights, |q| {
        drift_step(&one_ring, &original, q, &mut reference)
    });
    (q, reference)
}

/// The triangles around every vertex as the other two corners, in winding order.
pub fn fans(mesh: &Mesh) -> Vec<Vec<[u32; 2]>> {
    let mut fans = vec![Vec::new(); mesh.vertex_count()];
    for t in &mesh.triangles {
        for c in 0..3 {
            fans[t[c] as usize].push([t[(c + 1) % 3], t[(c + 2) % 3]]);
        }
    }
    fans
}

/// The local error of a vertex at `q` whose reference is `r` with fan `fan` on the original:
/// the smallest prism height over the fan's triangles, or where `q` lies in no prism, the
/// distance to the nearest edge of the fan (spokes from `r` and rims opposite it, which cover
/// its vertices). Infinite for an empty fan.
pub fn local_error(original: &[Point], fan: &[[u32; 2]], q: Point, r: usize) -> f64 {
    let pr = original[r];
    let corner = |j: u32| original[j as usize];
    let heights = fan
        .iter()
        .filter_map(|&[j, k]| prism_height(sub(corner(j), pr), sub(corner(k), pr), sub(q, pr)));
    if let Some(h) = heights.min_by(f64::total_cmp) {
        return h;
    }
    fan.iter()
        .flat_map(|&[j, k]| [(pr, corner(j)), (pr, corner(k)), (corner(j), corner(k))])
        .map(|(a, b)| segment_distance(a, b, q))
        .fold(f64::INFINITY, f64::min)
}

/// The paper's prism test: `(a, b, c) = P^-1 d` with `P = [e1 e2 n]`, `e1`, `e2` the
/// triangle's edges from the reference vertex, `n` its unit normal, `d = q - p_r`. `|c|` if
/// `a >= 0, b >= 0, a + b <= 1`, else `None` (also for a triangle without area: no `n`).
fn prism_height(e1: Point, e2: Point, d: Point) -> Option<f64> {
    let m = cross(e1, e2);
    if length(m) == 0.0 {
        return None;
    }
    let n = m.map(|x| x / length(m));
    let [a, b, c] = solve([e1, e2, n], d)?;
    (a >= 0.0 && b >= 0.0 && a + b <= 1.0).then_some(c.abs())
}

/// The coefficients `x` with `x0 c0 + x1 c1 + x2 c2 = rhs` (Cramer's rule); `None` where the
/// columns are dependent.
fn solve(c: [Point; 3], rhs: Point) -> Option<Point> {
    let det = |a: Point, b: Point, d: Point| dot(a, cross(b, d));
    let whole = det(c[0], c[1], c[2]);
    (whole != 0.0).then(|| {
        [
            det(rhs, c[1], c[2]) / whole,
            det(c[0], rhs, c[2]) / whole,
            det(c[0], c[1], rhs) / whole,
        ]
    })
}

/// The distance from `p` to the segment from `a` to `b` (a point if they meet).
fn segment_distance(a: Point, b: Point, p: Point) -> f64 {
    let (ab, ap) = (sub(b, a), sub(p, a));
    let along = if dot(ab, ab) > 0.0 {
        (dot(ap, ab) / dot(ab, ab)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    length(sub(ap, ab.map(|x| x * along)))
}

/// The local error of every vertex at `positions` with references `reference` against the
/// original `mesh`; `None` for vertices no triangle uses (they are not averaged).
pub fn local_errors(mesh: &Mesh, positions: &[Point], reference: &[u32]) -> Vec<Option<f64>> {
    let original = to_points(&mesh.positions);
    let fans = fans(mesh);
    (0..positions.len())
        .map(|i| {
            let r = reference[i] as usize;
            (!fans[i].is_empty()).then(|| local_error(&original, &fans[r], positions[i], r))
        })
        .collect()
}

/// The exact distance from `q` to the original `mesh`, by brute force over its triangles:
/// the height over a triangle where `q` projects into it, else the distance to its nearest
/// edge.
pub fn exact_distance(mesh: &Mesh, q: Point) -> f64 {
    let corner = |v: u32| mesh.positions[v as usize].map(f64::from);
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(corner);
            prism_height(sub(b, a), sub(c, a), sub(q, a)).unwrap_or_else(|| {
                [(a, b), (b, c), (c, a)]
                    .iter()
                    .map(|&(u, v)| segment_distance(u, v, q))
                    .fold(f64::INFINITY, f64::min)
            })
        })
        .fold(f64::INFINITY, f64::min)
}

// ---------------------------------------------------------------- roughness and score

/// Roughness `R = sum_i n_i |L(q)_i|^2` over the 1-rings `N(i)` of `mesh` (`n_i = |N(i)|`):
/// the umbrella vectors weighted by neighbour count, in which the filters' umbrella operator
/// is self-adjoint. Isolated vertices add nothing.
pub fn roughness(mesh: &Mesh, positions: &[Point]) -> f64 {
    let rings = Rings::one_ring(mesh);
    (0..positions.len())
        .map(|i| {
            let ring = rings.ring(i);
            if ring.is_empty() {
                return 0.0;
            }
            let n = ring.len() as f64;
            let umbrella: Point = std::array::from_fn(|k| {
                ring.iter().map(|&j| positions[j as usize][k]).sum::<f64>() / n - positions[i][k]
            });
            n * dot(umbrella, umbrella)
        })
        .sum()
}

/// The paper's score (eq. 4), `S = tau K/K0 + (1 - tau) 0.5 (E/(E+1) + |V - V0|/V0)`.
/// Where a term is undefined the product's conventions hold (see [`super::ScoreTerms`]): with
/// `K0 = 0` the ratio is 1, and without a volume (open mesh, or `V0 = 0`) the accuracy half is
/// `E/(E+1)` alone.
pub fn score(k: f64, k0: f64, e: f64, volumes: Option<(f64, f64)>, tau: f64) -> f64 {
    let smoothness = if k0 > 0.0 { k / k0 } else { 1.0 };
    let error = e / (e + 1.0);
    let accuracy = match volumes {
        Some((v, v0)) if v0 != 0.0 => 0.5 * (error + ((v - v0) / v0).abs()),
        _ => error,
    };
    tau * smoothness + (1.0 - tau) * accuracy
}

/// Every measure of `positions` (one per vertex of `original`, with each vertex's drifted
/// reference `reference`) against the original, as a [`Metrics`] report (without the exact
/// distances).
pub fn measure(original: &Mesh, positions: &[Point], reference: &[u32], tau: f64) -> Metrics {
    let o = to_points(&original.positions);
    let (volume0, volume) = (volume(original, &o), volume(original, positions));
    let volumes = volume.zip(volume0);
    let (curvature0, curvature) = (curvature(original, &o), curvature(original, positions));
    let errors: Vec<f64> = local_errors(original, positions, reference)
        .into_iter()
        .flatten()
        .collect();
    let mean_error = mean(&errors);
    Metrics {
        volume,
        volume0,
        volume_change: volumes.filter(|v| v.1 != 0.0).map(|(v, v0)| (v - v0) / v0),
        curvature,
        curvature0,
        mean_error,
        max_error: errors.iter().copied().fold(0.0, f64::max),
        score: score(curvature, curvature0, mean_error, volumes, tau),
        exact_mean_error: None,
        exact_max_error: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::{double_cone, grid, tetrahedron};

    fn points(mesh: &Mesh) -> Vec<Point> {
        to_points(&mesh.positions)
    }

    #[test]
    fn volumes_of_closed_meshes_and_none_for_open_ones() {
        let tet = tetrahedron();
        let v = volume(&tet, &points(&tet)).expect("closed");
        assert!((v - 1.0 / 6.0).abs() < 1e-15);
        let open = grid(3, 3);
        assert!(!is_closed(&open));
        assert_eq!(volume(&open, &points(&open)), None);
        assert!(!is_closed(&Mesh::default()));
    }

    #[test]
    fn mixed_areas_split_obtuse_and_right_triangles() {
        let shares = |c: Point| {
            let p = [[0.0; 3], [2.0, 0.0, 0.0], c];
            [0, 1, 2].map(|k| mixed_area_share(p, k))
        };
        // Obtuse at the third corner (area 0.5): half there, quarters elsewhere.
        assert_eq!(shares([1.0, 0.5, 0.0]), [0.125, 0.125, 0.25]);
        // Right-angled at the first corner (area 2): Voronoi, the circumcentre on the
        // hypotenuse.
        let right = shares([0.0, 2.0, 0.0]);
        for (got, want) in right.iter().zip([1.0, 0.5, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{right:?}");
        }
        assert_eq!(shares([1.0, 0.0, 0.0]), [0.0; 3], "no area");
    }

    #[test]
    fn angle_defects_obey_gauss_bonnet() {
        // A closed double cone (a sphere, chi = 2) plus an isolated vertex, which has no
        // triangles and so no angles.
        let cone = double_cone(7);
        let c = vertex_curvatures(&cone, &points(&cone));
        let used: f64 = c[..c.len() - 1].iter().map(|c| c.angle_defect).sum();
        assert!((used - 4.0 * PI).abs() < 1e-12, "{used}");
        assert_eq!(c[c.len() - 1].angle_defect, 2.0 * PI);
        let k = gaussian_curvatures(&cone, &points(&cone));
        assert!(k[..k.len() - 1].iter().all(Option::is_some));
        assert_eq!(k[k.len() - 1], None);
        // An open grid: its border vertices are left out.
        let g = grid(4, 3);
        let k = gaussian_curvatures(&g, &points(&g));
        assert_eq!(k.iter().flatten().count(), 3 * 2);
    }

    #[test]
    fn local_error_is_the_nearest_prism_height_or_fan_edge() {
        // Corner 0 of the tetrahedron at the origin; its fan: the faces x = 0, y = 0, z = 0.
        let tet = tetrahedron();
        let (o, fans) = (points(&tet), fans(&tet));
        let e = local_error(&o, &fans[0], [0.2, 0.3, 0.25], 0);
        assert!((e - 0.2).abs() < 1e-12, "{e}");
        // Beyond corner 1, in no prism: the distance to corner 1.
        let e = local_error(&o, &fans[0], [2.0, -0.5, -0.5], 0);
        assert!((e - 1.5f64.sqrt()).abs() < 1e-12, "{e}");
        // The exact distance there is the same (corner 1 is the nearest point of the mesh);
        // above the far face it is the height over that face.
        assert!((exact_distance(&tet, [2.0, -0.5, -0.5]) - 1.5f64.sqrt()).abs() < 1e-12);
        let d = exact_distance(&tet, [1.0, 1.0, 1.0]);
        assert!((d - 2.0 / 3f64.sqrt()).abs() < 1e-12, "{d}");
    }

    #[test]
    fn the_reference_drifts_one_hop_per_step() {
        let mut flat = grid(6, 6);
        flat.positions.iter_mut().for_each(|p| p[2] = 0.0);
        let (o, one_ring) = (points(&flat), Rings::one_ring(&flat));
        // Vertex (3, 3) moved next to (6, 3), a little above the grid.
        let mut q = o.clone();
        q[24] = [5.9, 3.0, 0.2];
        let mut reference: Vec<u32> = (0..49).collect();
        let mut path = Vec::new();
        for _ in 0..4 {
            drift_step(&one_ring, &o, &q, &mut reference);
            path.push(reference[24]);
        }
        assert_eq!(path, [25, 26, 27, 27]);
        assert_eq!(reference[23], 23);
        let errors = local_errors(&flat, &q, &reference);
        assert!((errors[24].expect("used") - 0.2).abs() < 1e-12);
    }

    #[test]
    fn roughness_of_a_triangle_by_hand() {
        // Each corner's umbrella vector points to the midpoint of the other two:
        // 2 |(1, 1)|^2 + 2 |(-2, 1)|^2 + 2 |(1, -2)|^2 = 4 + 10 + 10.
        let mesh = Mesh::new(
            vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [7.0; 3]],
            vec![[0, 1, 2]],
        );
        assert_eq!(roughness(&mesh, &points(&mesh)), 24.0);
    }

    #[test]
    fn the_score_is_the_papers_formula() {
        let s = score(2.0, 4.0, 1.0, Some((90.0, 100.0)), 0.5);
        assert!((s - (0.5 * 0.5 + 0.5 * 0.5 * (0.5 + 0.1))).abs() < 1e-15);
        assert_eq!(score(3.0, 0.0, 3.0, None, 0.5), 0.5 + 0.5 * 0.75);
        // Nothing moved: the score is tau.
        let tet = tetrahedron();
        let m = measure(&tet, &points(&tet), &[0, 1, 2, 3], 0.3);
        assert_eq!((m.mean_error, m.volume_change), (0.0, Some(0.0)));
        assert!((m.score - 0.3).abs() < 1e-15);
    }
}
