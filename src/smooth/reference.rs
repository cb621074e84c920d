//! The smoothing filters written as ALGORITHMS.md states them: plain loops, f64 throughout,
//! nothing shared with the tuned kernels beside this module. This is the definition the kernels
//! ([`super::smooth`], the GPU engine) are tested against, so it is written to be read, not to
//! be fast: every step allocates its result and nothing runs in parallel.
//!
//! Every filter is a Jacobi update (a step reads only the previous step's positions) from the
//! original positions; weights and the displacement bound act after every step, except in
//! windowed sinc, whose recurrence must see unconstrained terms (see `windowed_sinc`).

use std::f64::consts::PI;

use super::{Filter, Params};
use crate::mesh::Mesh;

/// A position in f64.
pub type Point = [f64; 3];

/// Per-vertex neighbour lists as CSR: vertex `i`'s neighbours are
/// `neighbors[offsets[i]..offsets[i + 1]]`, ascending, each once.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rings {
    pub offsets: Vec<u32>,
    pub neighbors: Vec<u32>,
}

impl Rings {
    /// The smoothing neighbourhood, from the triangles alone: the 1-ring, except that a vertex
    /// on a boundary edge (used by one triangle) sees only its neighbours across such edges, so
    /// the boundary is smoothed along itself instead of being pulled inwards.
    pub fn of(mesh: &Mesh) -> Self {
        let edges = edge_uses(mesh);
        let all = neighbour_lists(mesh.vertex_count(), edges.iter().map(|e| e.0));
        let boundary_edges = edges.iter().filter(|e| e.1 == 1).map(|e| e.0);
        let boundary = neighbour_lists(mesh.vertex_count(), boundary_edges);
        let rings =
            all.into_iter()
                .zip(boundary)
                .map(|(all, boundary)| if boundary.is_empty() { all } else { boundary });
        Self::from_lists(rings)
    }

    /// The 1-ring `N(i)` of every vertex: the vertices sharing an edge with it.
    pub fn one_ring(mesh: &Mesh) -> Self {
        let edges = edge_uses(mesh);
        Self::from_lists(neighbour_lists(
            mesh.vertex_count(),
            edges.iter().map(|e| e.0),
        ))
    }

    /// The neighbours of vertex `i`.
    pub fn ring(&self, i: usize) -> &[u32] {
        &self.neighbors[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    fn from_lists(lists: impl IntoIterator<Item = Vec<u32>>) -> Self {
        let mut rings = Self {
            offsets: vec![0],
            neighbors: Vec::new(),
        };
        for list in lists {
            rings.neighbors.extend(list);
            rings.offsets.push(rings.neighbors.len() as u32);
        }
        rings
    }
}

/// Every undirected edge `[a, b]` (`a < b`) with the number of triangles that use it,
/// ascending. A triangle with a repeated corner contributes only its distinct edges.
pub fn edge_uses(mesh: &Mesh) -> Vec<([u32; 2], usize)> {
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for t in &mesh.triangles {
        let mut own: Vec<[u32; 2]> = (0..3)
            .map(|k| (t[k], t[(k + 1) % 3]))
            .filter(|(a, b)| a != b)
            .map(|(a, b)| [a.min(b), a.max(b)])
            .collect();
        own.sort();
        own.dedup();
        edges.extend(own);
    }
    edges.sort();
    let mut uses: Vec<([u32; 2], usize)> = Vec::new();
    for e in edges {
        match uses.last_mut() {
            Some((last, count)) if *last == e => *count += 1,
            _ => uses.push((e, 1)),
        }
    }
    uses
}

/// Each vertex's neighbours across `edges` (ascending edges give ascending lists).
fn neighbour_lists(n: usize, edges: impl Iterator<Item = [u32; 2]>) -> Vec<Vec<u32>> {
    let mut lists = vec![Vec::new(); n];
    for [a, b] in edges {
        lists[a as usize].push(b);
        lists[b as usize].push(a);
    }
    for list in &mut lists {
        list.sort();
    }
    lists
}

/// `mesh`'s positions smoothed with `params` from the original positions. `weights`, when
/// given, has one entry in [0, 1] per vertex.
pub fn smooth(mesh: &Mesh, params: &Params, weights: Option<&[f32]>) -> Vec<Point> {
    smooth_steps(mesh, params, weights, |_| {})
}

/// [`smooth`], showing the positions after every step to `each_step`: what the drifting
/// reference of the local error follows. Taubin has two steps per iteration, the others one.
/// Windowed sinc's partial sums are not meshes, so it shows its result once per degree, as
/// the engine does.
pub fn smooth_steps(
    mesh: &Mesh,
    params: &Params,
    weights: Option<&[f32]>,
    mut each_step: impl FnMut(&[Point]),
) -> Vec<Point> {
    let rings = Rings::of(mesh);
    let original = to_points(&mesh.positions);
    let limits = Limits {
        original: &original,
        weights,
        max_displacement: params.max_displacement.map(f64::from),
    };
    if params.filter == Filter::Sinc {
        let q = windowed_sinc(&rings, &original, params, &limits);
        for _ in 0..params.iterations {
            each_step(&q);
        }
        return q;
    }
    let (alpha, beta) = (f64::from(params.alpha), f64::from(params.beta));
    // Laplace: one umbrella step per iteration; Taubin: a shrinking lambda step, then an
    // inflating mu step.
    let factors = match params.filter {
        Filter::Taubin => vec![f64::from(params.lambda), f64::from(params.mu)],
        _ => vec![f64::from(params.lambda)],
    };
    let mut q = original.clone();
    for _ in 0..params.iterations {
        if params.filter == Filter::Hc {
            q = hc_step(&rings, &q, (alpha, beta), &limits);
            each_step(&q);
            continue;
        }
        for &factor in &factors {
            q = umbrella_step(&rings, &q, factor, &limits);
            each_step(&q);
        }
    }
    q
}

/// `points` in f64.
pub fn to_points(points: &[[f32; 3]]) -> Vec<Point> {
    points.iter().map(|p| p.map(f64::from)).collect()
}

/// The mean of `q` over `ring` (not empty).
fn mean(ring: &[u32], q: &[Point]) -> Point {
    let mut sum = [0.0; 3];
    for &j in ring {
        for k in 0..3 {
            sum[k] += q[j as usize][k];
        }
    }
    sum.map(|s| s / ring.len() as f64)
}

/// One step `q += factor * L(q)` with `L(q)_i = mean_{N(i)} q - q_i`. Isolated vertices have
/// no `L` and never move.
fn umbrella_step(rings: &Rings, q: &[Point], factor: f64, limits: &Limits) -> Vec<Point> {
    (0..q.len())
        .map(|i| {
            let ring = rings.ring(i);
            if ring.is_empty() {
                return q[i];
            }
            let m = mean(ring, q);
            let proposed = std::array::from_fn(|k| q[i][k] + factor * (m[k] - q[i][k]));
            limits.apply(i, q[i], proposed)
        })
        .collect()
}

/// One Laplace+HC iteration (Vollmer, Mencl and Mueller 1999), in its two passes:
/// `p_i = mean_{N(i)} q`, `b_i = p_i - (alpha o_i + (1 - alpha) q_i)`, then
/// `q_i = p_i - (beta b_i + (1 - beta) mean_{N(i)} b)`. The second pass needs every `b`,
/// so the first runs over all vertices before it.
fn hc_step(rings: &Rings, q: &[Point], (alpha, beta): (f64, f64), limits: &Limits) -> Vec<Point> {
    let o = limits.original;
    let n = q.len();
    // An isolated vertex is its own `p` (it never moves), so its `b` is 0.
    let p: Vec<Point> = (0..n)
        .map(|i| match rings.ring(i) {
            [] => q[i],
            ring => mean(ring, q),
        })
        .collect();
    let b: Vec<Point> = (0..n)
        .map(|i| std::array::from_fn(|k| p[i][k] - (alpha * o[i][k] + (1.0 - alpha) * q[i][k])))
        .collect();
    (0..n)
        .map(|i| {
            let ring = rings.ring(i);
            if ring.is_empty() {
                return q[i];
            }
            let mb = mean(ring, &b);
            let proposed =
                std::array::from_fn(|k| p[i][k] - (beta * b[i][k] + (1.0 - beta) * mb[k]));
            limits.apply(i, q[i], proposed)
        })
        .collect()
}

/// Windowed sinc (Taubin 1996, as VTK's vtkWindowedSincPolyDataFilter): `sum_k c_k T_k(M) x`
/// with `M = I + L/2` and `T_k` the Chebyshev polynomials, by the three-term recurrence
/// `T_0 x = x`, `T_1 x = M x`, `T_{k+1} x = 2 M T_k x - T_{k-1} x`.
///
/// Coordinates are taken about the bounding box's centre, as VTK's NormalizeCoordinates does;
/// this matters because the series' gain at frequency 0 is 1 only to about 1e-3, so without
/// it the mesh would move towards the origin. (VTK also scales to the unit cube, which cancels
/// exactly in a linear filter.) Weights and the bound act on the final displacement from the
/// original: inside the recurrence they would make it no longer a polynomial in `L`.
fn windowed_sinc(rings: &Rings, o: &[Point], params: &Params, limits: &Limits) -> Vec<Point> {
    let c = sinc_coefficients(params.iterations as usize, f64::from(params.passband));
    let centre = bounding_box_centre(o);
    let x: Vec<Point> = o
        .iter()
        .map(|p| std::array::from_fn(|k| p[k] - centre[k]))
        .collect();
    let mut sum: Vec<Point> = x.iter().map(|p| p.map(|v| c[0] * v)).collect();
    let (mut previous, mut current) = (x.clone(), x);
    for (k, &ck) in c.iter().enumerate().skip(1) {
        let next: Vec<Point> = if k == 1 {
            half_umbrella(rings, &current)
        } else {
            let m = half_umbrella(rings, &current);
            (0..m.len())
                .map(|i| std::array::from_fn(|d| 2.0 * m[i][d] - previous[i][d]))
                .collect()
        };
        for (s, t) in sum.iter_mut().zip(&next) {
            for d in 0..3 {
                s[d] += ck * t[d];
            }
        }
        (previous, current) = (current, next);
    }
    (0..o.len())
        .map(|i| {
            // `L` is 0 there, but the series' gain at 0 is not exactly 1: keep them in place.
            if rings.ring(i).is_empty() {
                return o[i];
            }
            let estimate = std::array::from_fn(|d| centre[d] + sum[i][d]);
            limits.apply(i, o[i], estimate)
        })
        .collect()
}

/// `M y = y + L(y) / 2` (`y` itself on isolated vertices).
fn half_umbrella(rings: &Rings, y: &[Point]) -> Vec<Point> {
    (0..y.len())
        .map(|i| match rings.ring(i) {
            [] => y[i],
            ring => {
                let m = mean(ring, y);
                std::array::from_fn(|k| y[i][k] + 0.5 * (m[k] - y[i][k]))
            }
        })
        .collect()
}

fn bounding_box_centre(points: &[Point]) -> Point {
    std::array::from_fn(|k| {
        let lo = points.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = points
            .iter()
            .map(|p| p[k])
            .fold(f64::NEG_INFINITY, f64::max);
        if lo <= hi {
            (lo + hi) / 2.0
        } else {
            0.0
        }
    })
}

/// Nuttall window terms, VTK's default window.
const NUTTALL: [f64; 4] = [0.355768, 0.487396, 0.144232, 0.012604];

/// The windowed-sinc coefficients `c_0..=c_n` for degree `n`, as VTK chooses them: the
/// Nuttall-windowed ideal low-pass with cut-off `theta + sigma`, `theta = acos(1 - passband/2)`,
/// where `sigma` is VTK's Newton-like search for unit gain at the pass-band edge. Where that
/// search fails (or lands where the gain at frequency 0 is off by more than 1%), `sigma = 0`
/// and the coefficients scaled to unit gain at 0, so the mesh neither grows nor shrinks.
pub fn sinc_coefficients(n: usize, passband: f64) -> Vec<f64> {
    let theta = (1.0 - passband / 2.0).acos();
    let mut sigma = 0.0;
    let mut c = windowed_low_pass(n, theta + sigma);
    // VTK only searches from degree 2 on, within 1e-3 and at most 500 steps.
    let mut found = false;
    for _ in 0..if n >= 2 { 500 } else { 0 } {
        let gain = response_at(&c, theta);
        if (gain - 1.0).abs() < 1e-3 {
            found = true;
            break;
        }
        sigma -= (gain - 1.0) / vtk_slope(&c, theta);
        if !sigma.is_finite() {
            break;
        }
        c = windowed_low_pass(n, theta + sigma);
    }
    let dc: f64 = c.iter().sum();
    if !found || (dc - 1.0).abs() > 1e-2 {
        c = windowed_low_pass(n, theta);
        let dc: f64 = c.iter().sum();
        c.iter_mut().for_each(|x| *x /= dc);
    }
    c
}

/// `w_i s_i`: the Nuttall window over `0..=n` (falling to 0 at `n + 1`) times the ideal
/// low-pass with cut-off angle `cutoff`, `s_0 = cutoff / pi`, `s_i = 2 sin(i cutoff) / (i pi)`.
fn windowed_low_pass(n: usize, cutoff: f64) -> Vec<f64> {
    (0..=n)
        .map(|i| {
            let x = PI * i as f64 / (n + 1) as f64;
            let w: f64 = (0..4).map(|m| NUTTALL[m] * (m as f64 * x).cos()).sum();
            let ideal = if i == 0 {
                cutoff / PI
            } else {
                2.0 * (i as f64 * cutoff).sin() / (i as f64 * PI)
            };
            w * ideal
        })
        .collect()
}

/// The series' gain at the frequency whose Chebyshev angle is `theta`: `sum c_i cos(i theta)`.
fn response_at(c: &[f64], theta: f64) -> f64 {
    (0..c.len()).map(|i| c[i] * (i as f64 * theta).cos()).sum()
}

/// The slope VTK's search divides by: the x-derivative of the series without its top term,
/// `sum_{i<n} c_i T_i'(x)` with `T_i'(cos t) = i sin(i t) / sin t`, plus the half of the
/// derivative series' first coefficient that VTK leaves unhalved (`sum` of `i c_i`, odd `i`).
/// Not the derivative in sigma: matching VTK's step is what makes it land on VTK's sigma.
fn vtk_slope(c: &[f64], theta: f64) -> f64 {
    let n = c.len() - 1;
    (1..n)
        .map(|i| {
            let fi = i as f64;
            let derivative = c[i] * fi * (fi * theta).sin() / theta.sin();
            let unhalved = if i % 2 == 1 { fi * c[i] } else { 0.0 };
            derivative + unhalved
        })
        .sum()
}

/// Per-vertex weights and the displacement bound: where a vertex goes once its filter has
/// proposed a position.
struct Limits<'a> {
    original: &'a [Point],
    weights: Option<&'a [f32]>,
    max_displacement: Option<f64>,
}

impl Limits<'_> {
    /// The vertex moves `w_i` of the way from `current` to `proposed`, then is pulled back onto
    /// the ball of radius `max_displacement` around its original position.
    fn apply(&self, i: usize, current: Point, proposed: Point) -> Point {
        let w = self.weights.map_or(1.0, |w| f64::from(w[i]));
        let moved: Point = std::array::from_fn(|k| current[k] + w * (proposed[k] - current[k]));
        let Some(d_max) = self.max_displacement else {
            return moved;
        };
        let o = self.original[i];
        let offset: Point = std::array::from_fn(|k| moved[k] - o[k]);
        let length = offset.iter().map(|x| x * x).sum::<f64>().sqrt();
        if length <= d_max {
            return moved;
        }
        std::array::from_fn(|k| o[k] + offset[k] * d_max / length)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::{double_cone, grid};

    fn params(filter: Filter, iterations: u32) -> Params {
        Params {
            iterations,
            ..Params::defaults(filter)
        }
    }

    /// Two triangles sharing the edge 1-2, and an isolated vertex 4.
    fn two_triangles() -> Mesh {
        Mesh::new(
            vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 1.0],
                [9.0; 3],
            ],
            vec![[0, 1, 2], [1, 3, 2]],
        )
    }

    #[test]
    fn boundary_vertices_see_only_their_boundary_neighbours() {
        let mesh = two_triangles();
        let rings = Rings::of(&mesh);
        // The shared edge 1-2 is interior; every vertex lies on the boundary.
        assert_eq!(rings.ring(0), [1, 2]);
        assert_eq!(rings.ring(1), [0, 3]);
        assert_eq!(rings.ring(2), [0, 3]);
        assert_eq!(rings.ring(3), [1, 2]);
        assert!(rings.ring(4).is_empty());
        assert_eq!(Rings::one_ring(&mesh).ring(1), [0, 2, 3]);
        // A closed mesh: every ring is the 1-ring.
        let cone = double_cone(6);
        assert_eq!(Rings::of(&cone), Rings::one_ring(&cone));
        assert_eq!(Rings::of(&cone).ring(0), [2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn one_laplace_step_moves_towards_the_neighbour_mean() {
        let mesh = two_triangles();
        let mut p = params(Filter::Laplace, 1);
        p.lambda = 0.25;
        let q = smooth(&mesh, &p, None);
        // Vertex 1 at (1,0,0); its neighbours 0 and 3 average (0.5, 0.5, 0.5).
        assert_eq!(q[1], [0.875, 0.125, 0.125]);
        assert_eq!(q[4], [9.0; 3], "isolated");
    }

    #[test]
    fn taubin_takes_two_steps_per_iteration() {
        let mesh = grid(4, 3);
        let taubin = params(Filter::Taubin, 1);
        let mut steps = Vec::new();
        let q = smooth_steps(&mesh, &taubin, None, |q| steps.push(q.to_vec()));
        assert_eq!(steps.len(), 2);
        let rings = Rings::of(&mesh);
        let free = Limits {
            original: &[],
            weights: None,
            max_displacement: None,
        };
        let (lambda, mu) = (f64::from(taubin.lambda), f64::from(taubin.mu));
        let first = umbrella_step(&rings, &to_points(&mesh.positions), lambda, &free);
        assert_eq!(steps[0], first);
        assert_eq!(q, umbrella_step(&rings, &first, mu, &free));
    }

    #[test]
    fn hc_with_beta_one_and_alpha_one_returns_to_the_original() {
        // beta = 1: q = p - b = alpha o + (1 - alpha) q; with alpha = 1 that is o itself.
        let mesh = grid(5, 4);
        let mut p = params(Filter::Hc, 3);
        (p.alpha, p.beta) = (1.0, 1.0);
        let q = smooth(&mesh, &p, None);
        for (a, b) in q.iter().zip(to_points(&mesh.positions)) {
            assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-12));
        }
        // alpha = 0, beta = 0: q = p - mean b, with b = p - q.
        (p.alpha, p.beta, p.iterations) = (0.0, 0.0, 1);
        let q = smooth(&mesh, &p, None);
        let o = to_points(&mesh.positions);
        let rings = Rings::of(&mesh);
        let pm: Vec<Point> = (0..o.len()).map(|i| mean(rings.ring(i), &o)).collect();
        let b: Vec<Point> = (0..o.len())
            .map(|i| std::array::from_fn(|k| pm[i][k] - o[i][k]))
            .collect();
        let mb = mean(rings.ring(7), &b);
        let want: Point = std::array::from_fn(|k| pm[7][k] - mb[k]);
        assert!((0..3).all(|k| (q[7][k] - want[k]).abs() < 1e-12));
    }

    #[test]
    fn weights_scale_each_step_and_the_bound_holds() {
        let mesh = grid(6, 5);
        let n = mesh.vertex_count();
        let weights: Vec<f32> = (0..n).map(|i| (i % 3) as f32 / 2.0).collect();
        let mut p = params(Filter::Laplace, 1);
        let free = smooth(&mesh, &p, None);
        let weighted = smooth(&mesh, &p, Some(&weights));
        let o = to_points(&mesh.positions);
        for i in 0..n {
            let w = f64::from(weights[i]);
            for k in 0..3 {
                let want = o[i][k] + w * (free[i][k] - o[i][k]);
                assert!((weighted[i][k] - want).abs() < 1e-12);
            }
        }
        p.iterations = 20;
        p.max_displacement = Some(0.05);
        for filter in Filter::ALL {
            p.filter = filter;
            let q = smooth(&mesh, &p, None);
            let far = (0..n)
                .map(|i| {
                    (0..3)
                        .map(|k| (q[i][k] - o[i][k]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .fold(0.0, f64::max);
            // The bound as the engine stores it, an f32.
            let d_max = f64::from(0.05f32);
            assert!(far <= d_max + 1e-12 && far > 0.04, "{filter}: {far}");
        }
    }

    #[test]
    fn sinc_coefficients_pass_the_band_and_keep_the_mean() {
        let c = sinc_coefficients(20, 0.1);
        let theta = (1.0f64 - 0.05).acos();
        assert!((response_at(&c, theta) - 1.0).abs() < 1e-3);
        assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-2);
        // VTK 9.7's sigma for these settings, measured from its frequency response.
        assert!((c[0] * PI - theta - 0.4647048).abs() < 1e-6);
        // Degree 1 has nothing to search: unit gain at frequency 0.
        let c = sinc_coefficients(1, 0.1);
        assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn sinc_moves_no_isolated_vertex_and_keeps_a_flat_grid_flat() {
        let mut mesh = grid(6, 6);
        mesh.positions.iter_mut().for_each(|p| p[2] = 3.0);
        mesh.positions.push([1.0, 2.0, 3.0]);
        let q = smooth(&mesh, &params(Filter::Sinc, 20), None);
        assert_eq!(q.last(), Some(&[1.0, 2.0, 3.0]));
        assert!(q.iter().all(|p| (p[2] - 3.0).abs() < 1e-12));
    }
}
