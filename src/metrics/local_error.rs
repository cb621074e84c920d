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

/// Local error of a smoothed vertex at `q` whose reference vertex on the original mesh is `r`:
/// the smallest prism height over the triangles around `r`, else the distance to the fan's edges
/// (spokes from `r` and the rim opposite it), which covers its vertices.
#[inline]
pub(crate) fn vertex_local_error(original: &Original, q: [f32; 3], r: usize) -> f64 {
    let positions = &original.mesh().positions;
    let fan = original.fan_corners(r);
    let q = to_f64(q);
    let pr = to_f64(positions[r]);
    let d = sub(q, pr);
    let mut best = f64::INFINITY;
    for &[j, k] in fan {
        let e1 = sub(to_f64(positions[j as usize]), pr);
        let e2 = sub(to_f64(positions[k as usize]), pr);
        if let Some(h) = prism_height(e1, e2, d) {
            best = best.min(h);
        }
    }
    if best.is_finite() {
        return best;
    }
    // The reference vertex itself: all there is for a vertex no triangle uses.
    let mut best2 = dot(d, d);
    for &j in original.topology().neighbors_of(r) {
        best2 = best2.min(point_segment_distance2(
            q,
            pr,
            to_f64(positions[j as usize]),
        ));
    }
    for &[j, k] in fan {
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
/// inside test needs no division. Returns `|c|` when `a, b >= 0` and `a + b <= 1`. A degenerate or
/// sliver triangle (`P` not safely invertible) has no prism; its edges still count.
#[inline]
fn prism_height(e1: [f64; 3], e2: [f64; 3], d: [f64; 3]) -> Option<f64> {
    let m = cross(e1, e2);
    let m2 = dot(m, m);
    let a = dot(cross(d, e2), m);
    let b = dot(cross(e1, d), m);
    let inside = a >= 0.0 && b >= 0.0 && a + b <= m2;
    (inside && m2 > SLIVER_SINE * SLIVER_SINE * dot(e1, e1) * dot(e2, e2))
        .then(|| dot(d, m).abs() / m2.sqrt())
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
                for ((r, a), q) in references.iter_mut().zip(anchors).zip(positions) {
                    if distance2(*q, [a[0], a[1], a[2]]) <= a[3] {
                        continue;
                    }
                    (*r, *a) = drift_step(original, *q, *r);
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
