//! The paper's local error (section 4.1): each smoothed vertex keeps a reference vertex on the
//! original mesh that drifts with it during smoothing; at the end its distance is measured to the
//! triangle fan around that reference only, by the prism test with an edge fallback.
//!
//! It measures to part of the original mesh, so it is never below the exact distance to it.

use super::exact_distance::{point_segment_distance2, SLIVER_SINE};
use super::Original;
use crate::mesh::{cross, dot, sub, to_f64};
use crate::smooth::{smooth, Params, StepObserver};
use rayon::prelude::*;

/// Local errors of the vertices `vertices` whose fan on the original is not empty, in order, to
/// `each(i, e)`; `reference` holds every vertex's reference.
///
/// The prism tests of a run of vertices go in blocks of (vertex, triangle) pairs, gathered into
/// one array per coordinate so the processor tests several at a time; a vertex in no prism then
/// takes the distance to its fan's edges. The same numbers as [`vertex_local_error`], bit for bit.
pub(crate) fn local_errors(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    vertices: std::ops::Range<usize>,
    mut each: impl FnMut(usize, f64),
) {
    let original_positions = &original.mesh().positions;
    let topology = original.topology();
    let start = vertices.start;
    let mut best = vec![f64::INFINITY; vertices.len()];
    let mut block = PrismBlock::default();
    for i in vertices.clone() {
        if topology.triangles_of(i).is_empty() {
            continue;
        }
        let r = reference[i] as usize;
        let pr = to_f64(original_positions[r]);
        let d = sub(to_f64(positions[i]), pr);
        for &[j, k] in original.fan_corners(r) {
            let e1 = sub(to_f64(original_positions[j as usize]), pr);
            let e2 = sub(to_f64(original_positions[k as usize]), pr);
            if block.push((i - start) as u32, d, e1, e2) {
                block.flush(&mut best);
            }
        }
    }
    block.flush(&mut best);
    for (i, &best) in vertices.zip(&best) {
        if topology.triangles_of(i).is_empty() {
            continue;
        }
        let e = if best.is_finite() {
            best
        } else {
            fan_edge_distance(original, positions[i], reference[i] as usize)
        };
        each(i, e);
    }
}

/// Pairs of a vertex and a triangle of its reference's fan, one array per coordinate.
struct PrismBlock {
    len: usize,
    /// The pair's vertex (its place in the run).
    owner: [u32; PAIRS],
    /// `d`, `e1`, `e2` of [`prism_height`], coordinate by coordinate.
    v: [[f64; PAIRS]; 9],
}

/// Pairs per block.
const PAIRS: usize = 32;

impl Default for PrismBlock {
    fn default() -> Self {
        Self {
            len: 0,
            owner: [0; PAIRS],
            v: [[0.0; PAIRS]; 9],
        }
    }
}

impl PrismBlock {
    /// Adds a pair; returns whether the block is full.
    #[inline]
    fn push(&mut self, owner: u32, d: [f64; 3], e1: [f64; 3], e2: [f64; 3]) -> bool {
        let l = self.len;
        self.owner[l] = owner;
        for k in 0..3 {
            self.v[k][l] = d[k];
            self.v[3 + k][l] = e1[k];
            self.v[6 + k][l] = e2[k];
        }
        self.len += 1;
        self.len == PAIRS
    }

    /// Tests every pair and lowers its vertex's `best` height; empties the block. Lanes past
    /// the last pair test zeros, which have no prism, and are dropped.
    fn flush(&mut self, best: &mut [f64]) {
        let mut height = [f64::INFINITY; PAIRS];
        let v = &self.v;
        for (l, h) in height.iter_mut().enumerate() {
            let d = [v[0][l], v[1][l], v[2][l]];
            let e1 = [v[3][l], v[4][l], v[5][l]];
            let e2 = [v[6][l], v[7][l], v[8][l]];
            *h = prism_height(e1, e2, d);
        }
        for (&owner, &h) in self.owner[..self.len].iter().zip(&height) {
            let b = &mut best[owner as usize];
            *b = b.min(h);
        }
        self.len = 0;
    }
}

/// Local error of a smoothed vertex at `q` whose reference vertex on the original mesh is `r`:
/// the smallest prism height over the triangles around `r`, else the distance to the fan's edges
/// (see [`fan_edge_distance`]). One vertex at a time: [`local_errors`] is the fast way.
pub(crate) fn vertex_local_error(original: &Original, q: [f32; 3], r: usize) -> f64 {
    let positions = &original.mesh().positions;
    let pr = to_f64(positions[r]);
    let d = sub(to_f64(q), pr);
    let mut best = f64::INFINITY;
    for &[j, k] in original.fan_corners(r) {
        let e1 = sub(to_f64(positions[j as usize]), pr);
        let e2 = sub(to_f64(positions[k as usize]), pr);
        best = best.min(prism_height(e1, e2, d));
    }
    if best.is_finite() {
        return best;
    }
    fan_edge_distance(original, q, r)
}

/// The distance from `q` to the edges of the fan around `r` (spokes from `r` and the rim
/// opposite it), which covers its vertices; just to `r` for a vertex no triangle uses.
#[cold]
fn fan_edge_distance(original: &Original, q: [f32; 3], r: usize) -> f64 {
    let positions = &original.mesh().positions;
    let q = to_f64(q);
    let pr = to_f64(positions[r]);
    let d = sub(q, pr);
    let mut best2 = dot(d, d);
    for &j in original.topology().neighbors_of(r) {
        best2 = best2.min(point_segment_distance2(
            q,
            pr,
            to_f64(positions[j as usize]),
        ));
    }
    for &[j, k] in original.fan_corners(r) {
        best2 = best2.min(point_segment_distance2(
            q,
            to_f64(positions[j as usize]),
            to_f64(positions[k as usize]),
        ));
    }
    best2.sqrt()
}

/// The paper's prism test, `(a, b, c) = P^-1 d` with `P = [e1 e2 n]`, `e1`, `e2` the triangle's
/// edges from the reference vertex and `d = q - p_r`. By Cramer's rule with `m = e1 x e2`
/// (`n = m / |m|`): `a = (d x e2).m / |m|^2`, `b = (e1 x d).m / |m|^2`, `c = d.m / |m|`, so the
/// inside test needs no division. Returns `|c|` when `a, b >= 0` and `a + b <= 1`, else
/// infinity. A degenerate or sliver triangle (`P` not safely invertible) has no prism; its edges
/// still count. Selects rather than branches, so a block of pairs runs as vectors.
#[inline]
fn prism_height(e1: [f64; 3], e2: [f64; 3], d: [f64; 3]) -> f64 {
    let m = cross(e1, e2);
    let m2 = dot(m, m);
    let a = dot(cross(d, e2), m);
    let b = dot(cross(e1, d), m);
    let inside = (a >= 0.0) & (b >= 0.0) & (a + b <= m2);
    let solid = m2 > SLIVER_SINE * SLIVER_SINE * dot(e1, e1) * dot(e2, e2);
    let h = dot(d, m).abs() / m2.sqrt();
    if inside & solid {
        h
    } else {
        f64::INFINITY
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
#[derive(Clone, Debug)]
pub struct DriftingReference<'a> {
    original: &'a Original,
    reference: Vec<u32>,
    /// Per vertex `[x, y, z, radius^2]` (see the type's notes).
    anchors: Vec<[f32; 4]>,
}

impl<'a> DriftingReference<'a> {
    /// Every vertex starts at itself.
    pub fn new(original: &'a Original) -> Self {
        Self::resume(original, identity(original.mesh().vertex_count()))
    }

    /// Continues a drift from `reference` (an earlier state of one, one entry per vertex): a
    /// run spread over several calls keeps its references between them.
    pub fn resume(original: &'a Original, reference: Vec<u32>) -> Self {
        assert_eq!(
            reference.len(),
            original.mesh().vertex_count(),
            "one reference per vertex"
        );
        let anchors = reference
            .iter()
            .map(|&r| home_anchor(original, r as usize))
            .collect();
        Self {
            original,
            reference,
            anchors,
        }
    }

    /// Back to the start, for a new smoothing run from the original positions.
    pub fn reset(&mut self) {
        for (i, (r, a)) in self.reference.iter_mut().zip(&mut self.anchors).enumerate() {
            *r = i as u32;
            *a = home_anchor(self.original, i);
        }
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
        self.reference
            .par_chunks_mut(DRIFT_CHUNK)
            .zip(self.anchors.par_chunks_mut(DRIFT_CHUNK))
            .zip(positions.par_chunks(DRIFT_CHUNK))
            .for_each(|((references, anchors), positions)| {
                // First which vertices left their anchors, without a branch per vertex (whether
                // one did is a coin toss while the mesh moves), then their rings.
                let mut moved = [0u16; DRIFT_CHUNK];
                let mut count = 0;
                for (k, (a, q)) in anchors.iter().zip(positions).enumerate() {
                    moved[count] = k as u16;
                    // Written so that a NaN position counts as moved.
                    let stays = distance2(*q, [a[0], a[1], a[2]]) <= a[3];
                    count += usize::from(!stays);
                }
                for &k in &moved[..count] {
                    let k = k as usize;
                    (references[k], anchors[k]) = drift_step(original, positions[k], references[k]);
                }
            });
    }

    /// The current reference vertex of every vertex.
    pub fn reference(&self) -> &[u32] {
        &self.reference
    }

    pub fn into_reference(self) -> Vec<u32> {
        self.reference
    }
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

impl StepObserver for DriftingReference<'_> {
    fn after_step(&mut self, positions: &[[f32; 3]]) {
        self.update(positions);
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
