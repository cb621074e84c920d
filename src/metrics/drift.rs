//! The drifting reference neighbourhood of the paper's local error (section 4.1): each smoothed
//! vertex keeps a reference vertex on the original mesh that follows it, one hop per smoothing
//! step; the local error ([`super::local_error`]) then measures to the fan around it.

use super::Original;
use crate::smooth::{smooth, FollowPart, Follower, Params, StepObserver};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

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

    /// The references `reference` (one per vertex of `original`, each a vertex of it), every
    /// vertex anchored at its reference: the same drift from here on as with the anchors the
    /// run had (those only spare ring checks), for a state kept without them.
    pub fn at_home(original: &Original, reference: Vec<u32>) -> Self {
        let anchors = reference
            .iter()
            .map(|&r| home_anchor(original, r as usize))
            .collect();
        Self { reference, anchors }
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
        // `nearest_other.min(dj)` as a select (never NaN, so a NaN `dj` is passed over as
        // `min` does): wasm has no instruction for Rust's `f32::min` and calls a function.
        nearest_other = if dj < nearest_other {
            dj
        } else {
            nearest_other
        };
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
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
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
