//! The paper's local error (section 4.1): each smoothed vertex keeps a reference vertex on the
//! original mesh that drifts with it during smoothing; at the end its distance is measured to the
//! triangle fan around that reference only, by the prism test with an edge fallback.
//!
//! It measures to part of the original mesh, so it is never below the exact distance to it.

use super::exact_distance::SLIVER_SINE;
use super::prism_rows::ROW;
use super::Original;
use crate::mesh::{cross32, dot32, sub32};
use crate::smooth::{smooth, FollowPart, Follower, Params, StepObserver};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Local errors of the vertices `vertices` whose fan on the original is not empty, in order, to
/// `each(i, e)`; `reference` holds every vertex's reference.
pub(crate) fn local_errors(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    vertices: std::ops::Range<usize>,
    each: impl FnMut(usize, f64),
) {
    #[cfg(target_arch = "x86_64")]
    if super::wide::available() {
        // SAFETY: the processor has the features `vertex_local_error2_wide` is built with.
        let wide = |o: &Original, q, r| unsafe { vertex_local_error2_wide(o, q, r) };
        return local_errors_with(original, positions, reference, vertices, each, wide);
    }
    local_errors_with(
        original,
        positions,
        reference,
        vertices,
        each,
        vertex_local_error2,
    );
}

/// [`local_errors`] with the per-vertex kernel `error2` ([`vertex_local_error2`] or its wide
/// build).
#[inline(always)]
fn local_errors_with(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    vertices: std::ops::Range<usize>,
    mut each: impl FnMut(usize, f64),
    error2: impl Fn(&Original, [f32; 3], usize) -> f32,
) {
    let topology = original.topology();
    // A run of squared errors first, then their roots: the root's latency at the end of every
    // vertex would otherwise hold up the next one. (A vertex no triangle uses gets a number
    // too, the distance to itself, which is dropped.)
    const RUN: usize = 64;
    let mut squared = [0.0f32; RUN];
    let mut start = vertices.start;
    while start < vertices.end {
        let run = start..(start + RUN).min(vertices.end);
        for (i, s) in run.clone().zip(&mut squared) {
            *s = error2(original, positions[i], reference[i] as usize);
        }
        for (i, &s) in run.clone().zip(&squared) {
            if !topology.triangles_of(i).is_empty() {
                each(i, f64::from(s.sqrt()));
            }
        }
        start = run.end;
    }
}

/// Local error of a smoothed vertex at `q` whose reference vertex on the original mesh is `r`
/// (see [`vertex_local_error2`]).
pub(crate) fn vertex_local_error(original: &Original, q: [f32; 3], r: usize) -> f64 {
    f64::from(vertex_local_error2(original, q, r).sqrt())
}

/// The square of the local error of a smoothed vertex at `q` whose reference vertex on the
/// original mesh is `r`: the smallest prism height over the triangles around `r`, else the
/// distance to the fan's edges (spokes from `r` and the rim opposite it), which cover its
/// vertices.
///
/// All in f32 on edges taken from `r`, so the rounding is a few ulps of the distances
/// themselves, far below that of the f32 positions at their coordinates. A fan with a rim row
/// is one fixed loop of [`ROW`] pairs, which the processor runs as vectors.
// A call per vertex: inlined into the loop over the vertices, the same code ran half as fast.
#[inline(never)]
fn vertex_local_error2(original: &Original, q: [f32; 3], r: usize) -> f32 {
    vertex_local_error2_kernel(original, q, r)
}

/// [`vertex_local_error2`] on AVX-512 (see [`super::wide`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma")]
#[inline(never)]
fn vertex_local_error2_wide(original: &Original, q: [f32; 3], r: usize) -> f32 {
    vertex_local_error2_kernel(original, q, r)
}

/// The body of [`vertex_local_error2`], for its builds.
#[inline(always)]
fn vertex_local_error2_kernel(original: &Original, q: [f32; 3], r: usize) -> f32 {
    let positions = &original.mesh().positions;
    let pr = positions[r];
    let d = sub32(q, pr);
    let Some(row) = original.prism_row(r) else {
        return fan_local_error2(original, r, d);
    };
    // Coordinate by coordinate, slot by slot: the first edges, and the second (the next slot's).
    // Plain loops over the fixed row rather than `array::from_fn`, whose closures the compiler
    // leaves as calls once the kernel has two builds.
    let mut e1 = [[0.0f32; ROW]; 3];
    for (t, &j) in row.iter().enumerate() {
        let p = positions[j as usize];
        for c in 0..3 {
            e1[c][t] = p[c] - pr[c];
        }
    }
    let mut e2 = [[0.0f32; ROW]; 3];
    for c in 0..3 {
        for t in 0..ROW {
            e2[c][t] = e1[c][(t + 1) % ROW];
        }
    }
    let lane = |e: &[[f32; ROW]; 3], t: usize| [e[0][t], e[1][t], e[2][t]];
    let mut height2 = [0.0f32; ROW];
    for (t, h) in height2.iter_mut().enumerate() {
        *h = prism_height2(lane(&e1, t), lane(&e2, t), d);
    }
    let mut best2 = smallest(height2);
    if !best2.is_finite() {
        // In no prism. Pads name `r` itself, so their segments are spokes or the point `r`.
        let mut edge2 = [0.0f32; ROW];
        for (t, e) in edge2.iter_mut().enumerate() {
            let (a, b) = (lane(&e1, t), lane(&e2, t));
            *e = min(
                segment_distance2([0.0; 3], a, d),
                segment_distance2(a, b, d),
            );
        }
        best2 = min(smallest(edge2), dot32(d, d));
    }
    best2
}

/// [`vertex_local_error2`] for a fan without a rim row, from its lists of corners and
/// neighbours.
#[cold]
fn fan_local_error2(original: &Original, r: usize, d: [f32; 3]) -> f32 {
    let positions = &original.mesh().positions;
    let pr = positions[r];
    let edge = |j: u32| sub32(positions[j as usize], pr);
    let fan = original.fan_corners(r);
    let mut best2 = fan
        .iter()
        .map(|&[j, k]| prism_height2(edge(j), edge(k), d))
        .fold(f32::INFINITY, f32::min);
    if !best2.is_finite() {
        best2 = dot32(d, d);
        for &j in original.topology().neighbors_of(r) {
            best2 = best2.min(segment_distance2([0.0; 3], edge(j), d));
        }
        for &[j, k] in fan {
            best2 = best2.min(segment_distance2(edge(j), edge(k), d));
        }
    }
    best2
}

/// The smallest of `values`, which hold no NaN, by halves (a short chain of the processor's
/// minimum instruction; `f32::min` must also look for NaNs).
#[inline(always)]
fn smallest(values: [f32; ROW]) -> f32 {
    const { assert!(ROW == 8, "halves of four") };
    let half: [f32; 4] = std::array::from_fn(|k| min(values[k], values[k + 4]));
    min(min(half[0], half[2]), min(half[1], half[3]))
}

/// `a` or `b`, whichever is smaller, for values that hold no NaN.
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

/// The squared distance from `p` to the segment from `a` to `b` (a point if they meet).
#[inline(always)]
fn segment_distance2(a: [f32; 3], b: [f32; 3], p: [f32; 3]) -> f32 {
    let ab = sub32(b, a);
    let ap = sub32(p, a);
    let length2 = dot32(ab, ab);
    // Written so that a NaN (a segment of length 0) comes out as 0.
    let along = dot32(ap, ab) / length2;
    let along = if along > 0.0 { along } else { 0.0 };
    let along = if along < 1.0 { along } else { 1.0 };
    let x = [
        ap[0] - along * ab[0],
        ap[1] - along * ab[1],
        ap[2] - along * ab[2],
    ];
    dot32(x, x)
}

/// The paper's prism test, `(a, b, c) = P^-1 d` with `P = [e1 e2 n]`, `e1`, `e2` the triangle's
/// edges from the reference vertex and `d = q - p_r`. By Cramer's rule with `m = e1 x e2`
/// (`n = m / |m|`): `a = (d x e2).m / |m|^2`, `b = (e1 x d).m / |m|^2`, `c = d.m / |m|`, so the
/// inside test needs no division. Returns `c^2` when `a, b >= 0` and `a + b <= 1`, else
/// infinity. A degenerate or sliver triangle (`P` not safely invertible) has no prism; its edges
/// still count. Selects rather than branches, so a row of pairs runs as vectors.
#[inline(always)]
fn prism_height2(e1: [f32; 3], e2: [f32; 3], d: [f32; 3]) -> f32 {
    let m = cross32(e1, e2);
    let m2 = dot32(m, m);
    let a = dot32(cross32(d, e2), m);
    let b = dot32(cross32(e1, d), m);
    let inside = (a >= 0.0) & (b >= 0.0) & (a + b <= m2);
    const SLIVER2: f32 = (SLIVER_SINE * SLIVER_SINE) as f32;
    let solid = m2 > SLIVER2 * dot32(e1, e1) * dot32(e2, e2);
    let c = dot32(d, m);
    let h2 = c * (c / m2);
    if inside & solid {
        h2
    } else {
        f32::INFINITY
    }
}

/// Vertices per parallel task of a drift step.
const DRIFT_CHUNK: usize = 2048;

/// The drifting reference neighbourhood: after every smoothing step, each vertex's reference moves
/// to whichever of the reference and its 1-ring on the original mesh is closest to the vertex's
/// current position (one hop per step). Use it as the smoothing run's [`StepObserver`].
///
/// Most vertices keep their reference from one step to the next, and a step moves them little, so
/// each vertex also keeps an anchor: a point and a radius such that anywhere within the radius of
/// the point, the reference is still strictly the closest of its ring. A vertex within its anchor's
/// radius skips the ring. The anchors only save work: the references are those of checking every
/// ring at every step.
#[derive(Debug)]
pub struct DriftingReference<'a> {
    original: &'a Original,
    reference: Vec<u32>,
    /// Per vertex `[x, y, z, radius^2]` (see the type's notes).
    anchors: Vec<[f32; 4]>,
    /// Vertices that left their anchors in the latest step (each checked its ring).
    ring_checks: AtomicUsize,
}

impl Clone for DriftingReference<'_> {
    fn clone(&self) -> Self {
        Self {
            original: self.original,
            reference: self.reference.clone(),
            anchors: self.anchors.clone(),
            ring_checks: AtomicUsize::new(self.ring_checks()),
        }
    }
}

/// What a drift carries from one piece of a run to the next, for a run spread over several
/// calls (the web app spreads one over frames): each vertex's reference and its anchor. The
/// references alone would give the same drift, but every vertex would start the next piece
/// from its home anchor, and most would check their rings again.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DriftState {
    reference: Vec<u32>,
    anchors: Vec<[f32; 4]>,
}

impl DriftState {
    /// Every vertex of `original` at itself, as a run starts.
    pub fn start(original: &Original) -> Self {
        let n = original.mesh().vertex_count();
        Self {
            reference: identity(n),
            anchors: (0..n).map(|i| home_anchor(original, i)).collect(),
        }
    }

    /// The current reference vertex of every vertex.
    pub fn reference(&self) -> &[u32] {
        &self.reference
    }

    pub fn into_reference(self) -> Vec<u32> {
        self.reference
    }
}

impl<'a> DriftingReference<'a> {
    /// Every vertex starts at itself.
    pub fn new(original: &'a Original) -> Self {
        Self::resume(original, DriftState::start(original))
    }

    /// Continues a drift from `state`, which an earlier piece of the same run on `original`
    /// left ([`Self::into_state`]).
    pub fn resume(original: &'a Original, state: DriftState) -> Self {
        let n = original.mesh().vertex_count();
        assert!(
            state.reference.len() == n && state.anchors.len() == n,
            "one reference and one anchor per vertex"
        );
        Self {
            original,
            reference: state.reference,
            anchors: state.anchors,
            ring_checks: AtomicUsize::new(0),
        }
    }

    /// The state to [`Self::resume`] from in the next piece of the run.
    pub fn into_state(self) -> DriftState {
        DriftState {
            reference: self.reference,
            anchors: self.anchors,
        }
    }

    /// How many vertices checked their rings in the latest step: a few thousand on a 200k mesh
    /// that smooths, nearly all of them on one the filter blows up.
    pub fn ring_checks(&self) -> usize {
        self.ring_checks.load(Ordering::Relaxed)
    }

    /// Back to the start, for a new smoothing run from the original positions.
    pub fn reset(&mut self) {
        let start = DriftState::start(self.original);
        (self.reference, self.anchors) = (start.reference, start.anchors);
    }

    /// One drift step for the positions `positions` (one per vertex of the original mesh).
    pub fn update(&mut self, positions: &[[f32; 3]]) {
        assert_eq!(
            positions.len(),
            self.reference.len(),
            "positions must belong to the original mesh"
        );
        let original = self.original;
        // Plain loops over runs of vertices: rayon's per-item closures cost more than the work.
        let checks = self
            .reference
            .par_chunks_mut(DRIFT_CHUNK)
            .zip(self.anchors.par_chunks_mut(DRIFT_CHUNK))
            .zip(positions.par_chunks(DRIFT_CHUNK))
            .map(|((references, anchors), positions)| {
                drift_run(original, references, anchors, positions, |&q| q)
            })
            .sum();
        self.ring_checks.store(checks, Ordering::Relaxed);
    }

    /// The current reference vertex of every vertex.
    pub fn reference(&self) -> &[u32] {
        &self.reference
    }

    pub fn into_reference(self) -> Vec<u32> {
        self.reference
    }
}

/// One drift step for a run of vertices: their references, anchors and new positions (read
/// by `xyz`). Returns how many checked their rings.
fn drift_run<P>(
    original: &Original,
    references: &mut [u32],
    anchors: &mut [[f32; 4]],
    positions: &[P],
    xyz: impl Fn(&P) -> [f32; 3],
) -> usize {
    let mut checks = 0;
    let blocks = references
        .chunks_mut(DRIFT_CHUNK)
        .zip(anchors.chunks_mut(DRIFT_CHUNK))
        .zip(positions.chunks(DRIFT_CHUNK));
    for ((references, anchors), positions) in blocks {
        // First which vertices left their anchors, without a branch per vertex (whether one
        // did is a coin toss while the mesh moves), then their rings.
        let mut moved = [0u16; DRIFT_CHUNK];
        let mut count = 0;
        for (k, (a, q)) in anchors.iter().zip(positions).enumerate() {
            moved[count] = k as u16;
            // Written so that a NaN position counts as moved.
            let stays = distance2(xyz(q), [a[0], a[1], a[2]]) <= a[3];
            count += usize::from(!stays);
        }
        for &k in &moved[..count] {
            let k = k as usize;
            (references[k], anchors[k]) = drift_step(original, xyz(&positions[k]), references[k]);
        }
        checks += count;
    }
    checks
}

/// The anchor of a vertex whose reference `r` may be anywhere: the reference's own position and
/// its stay radius (see `Original`).
fn home_anchor(original: &Original, r: usize) -> [f32; 4] {
    let p = original.mesh().positions[r];
    [p[0], p[1], p[2], original.stay_radius2()[r]]
}

#[inline]
fn distance2(q: [f32; 3], p: [f32; 3]) -> f32 {
    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// One step of the drift for a vertex at `q` with reference `r`, checking the whole ring: the new
/// reference and its anchor.
///
/// If the reference stays, with `D_r` its distance and `D_min` the nearest neighbour's, then
/// wherever `q` moves by less than `(D_min - D_r) / 2`, every neighbour stays farther than the
/// reference (triangle inequality). The anchor at `q` takes 0.45 of that gap less `1e-4 D_min`:
/// far more than the rounding of the f32 distances, so the comparisons the full check would
/// make give the same answer within it. A new reference is anchored at home.
#[inline]
fn drift_step(original: &Original, q: [f32; 3], r: u32) -> (u32, [f32; 4]) {
    let positions = &original.mesh().positions;
    // Ties keep the current reference, so a vertex that did not move stays put.
    let mut best = r;
    let mut best_d2 = distance2(q, positions[r as usize]);
    let mut nearest_other = f32::INFINITY;
    for &j in original.topology().neighbors_of(r as usize) {
        let dj = distance2(q, positions[j as usize]);
        let closer = dj < best_d2;
        best = if closer { j } else { best };
        best_d2 = if closer { dj } else { best_d2 };
        nearest_other = nearest_other.min(dj);
    }
    if best != r {
        return (best, home_anchor(original, best as usize));
    }
    let (d_r, d_min) = (best_d2.sqrt(), nearest_other.sqrt());
    let radius = 0.45 * (d_min - d_r) - 1e-4 * d_min;
    if radius > 0.0 && radius.is_finite() {
        (r, [q[0], q[1], q[2], radius * radius])
    } else {
        (r, home_anchor(original, r as usize))
    }
}

/// The drift follows every step inside the engine's passes ([`Follower`]); it wants no
/// positions laid out.
impl StepObserver for DriftingReference<'_> {
    fn watches(&self) -> bool {
        false
    }

    fn follower(&mut self) -> Option<&mut dyn Follower> {
        Some(self)
    }
}

impl Follower for DriftingReference<'_> {
    fn parts(&mut self, run: usize) -> Vec<FollowPart<'_>> {
        let original = self.original;
        let checks = &self.ring_checks;
        checks.store(0, Ordering::Relaxed);
        self.reference
            .chunks_mut(run)
            .zip(self.anchors.chunks_mut(run))
            .map(|(references, anchors)| {
                Box::new(move |positions: &[[f32; 4]]| {
                    let n = drift_run(original, references, anchors, positions, |q| {
                        [q[0], q[1], q[2]]
                    });
                    checks.fetch_add(n, Ordering::Relaxed);
                }) as FollowPart
            })
            .collect()
    }
}

/// Smooths the original mesh with `params` (and `weights`, one per vertex, when given) with the
/// drifting reference watching every step: the smoothed positions and each vertex's reference,
/// ready for [`super::measure`]. The one way every caller (CLI, app, suggestions) smooths
/// before measuring, so all report the same numbers.
pub fn smooth_drifting(
    original: &Original,
    params: &Params,
    weights: Option<&[f32]>,
) -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut drift = DriftingReference::new(original);
    let positions = smooth(
        original.mesh(),
        original.topology(),
        params,
        weights,
        &mut drift,
    );
    (positions, drift.into_reference())
}

/// `0, 1, ..., n - 1`: every vertex its own reference (nothing has drifted).
pub fn identity(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::{double_cone, grid, tetrahedron};
    use crate::mesh::Topology;

    /// Points near and far from `p`: inside some prisms, and in none.
    fn around(p: [f32; 3]) -> impl Iterator<Item = [f32; 3]> {
        let offsets = [
            [0.0, 0.0, 0.0],
            [0.05, 0.02, 0.3],
            [0.2, -0.1, -0.25],
            [-0.3, 0.35, 0.1],
            [0.6, 0.1, -0.05],
            [2.0, 1.0, 0.5],
            [-1.5, 0.2, -2.0],
            [0.0, 0.0, 3.0],
        ];
        offsets
            .into_iter()
            .map(move |o| [p[0] + o[0], p[1] + o[1], p[2] + o[2]])
    }

    #[test]
    fn rim_rows_measure_what_the_lists_of_corners_do() {
        for (mesh, rowless) in [(tetrahedron(), 0), (grid(5, 4), 0), (double_cone(10), 3)] {
            let topology = Topology::build(&mesh);
            let original = Original::new(&mesh, &topology);
            let mut without = 0;
            for (r, &p) in mesh.positions.iter().enumerate() {
                if original.prism_row(r).is_none() {
                    without += 1;
                    continue;
                }
                for q in around(p) {
                    let by_row = vertex_local_error(&original, q, r);
                    let by_list = f64::from(fan_local_error2(&original, r, sub32(q, p)).sqrt());
                    // Prism heights are the same numbers; an edge may be walked the other way.
                    assert!(
                        (by_row - by_list).abs() <= 1e-6 * by_list.max(1.0),
                        "vertex {r} at {q:?}: {by_row} by its row, {by_list} by its list"
                    );
                }
            }
            assert_eq!(without, rowless, "vertices read from their list of corners");
        }
    }

    #[test]
    fn the_error_is_the_distance_to_the_nearest_part_of_the_fan() {
        // The tetrahedron's corner 0 at the origin; its fan: the faces x = 0, y = 0 and z = 0.
        let mesh = tetrahedron();
        let topology = Topology::build(&mesh);
        let original = Original::new(&mesh, &topology);
        // Over all three faces (inside each prism): the height over the nearest, x = 0.
        let e = vertex_local_error(&original, [0.2, 0.3, 0.25], 0);
        assert!((e - 0.2).abs() < 1e-7, "{e}");
        // Off every prism, beyond corner 1: the distance to corner 1, the fan's nearest point.
        let e = vertex_local_error(&original, [2.0, -0.5, -0.5], 0);
        assert!((e - 1.5f64.sqrt()).abs() < 1e-7, "{e}");
    }
}

#[cfg(test)]
mod resume_tests {
    use super::*;
    use crate::smooth::{Filter, Params};

    /// The positions after each iteration of HC on the bundled sample.
    fn steps(original: &Original, iterations: u32) -> Vec<Vec<[f32; 3]>> {
        struct Keep(Vec<Vec<[f32; 3]>>);
        impl StepObserver for Keep {
            fn after_iteration(&mut self, _: u32, positions: &[[f32; 3]]) {
                self.0.push(positions.to_vec());
            }
        }
        let mut params = Params::defaults(Filter::Hc);
        params.iterations = iterations;
        let mut keep = Keep(Vec::new());
        smooth(
            original.mesh(),
            original.topology(),
            &params,
            None,
            &mut keep,
        );
        keep.0
    }

    #[test]
    fn a_drift_resumed_from_its_state_goes_on_as_if_never_stopped() {
        let bytes = include_bytes!("../../web/sample/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "sample.ply").unwrap();
        let original = Original::new(&mesh, &crate::mesh::Topology::build(&mesh));
        let steps = steps(&original, 12);
        let mut whole = DriftingReference::new(&original);
        let mut pieces = DriftingReference::new(&original);
        for (k, positions) in steps.iter().enumerate() {
            whole.update(positions);
            if k % 3 == 0 {
                pieces = DriftingReference::resume(&original, pieces.into_state());
            }
            pieces.update(positions);
            assert_eq!(pieces.reference(), whole.reference(), "step {k}");
            // The anchors came along: no vertex checks its ring again for having stopped.
            assert_eq!(pieces.ring_checks(), whole.ring_checks(), "step {k}");
        }
        assert!(
            whole.ring_checks() < mesh.vertex_count() / 2,
            "most vertices stay within their anchors"
        );
        let state = whole.into_state();
        assert_eq!(state.clone().into_reference(), state.reference());
    }
}
