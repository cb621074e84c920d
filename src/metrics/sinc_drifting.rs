//! [`super::smooth_drifting`] for windowed sinc, spread over calls: the filter's neighbour
//! passes, then the drifting reference's steps towards the result (one per degree, as the
//! filter reports them to its observer), a few pieces per call.

use super::{DriftState, DriftingReference, Original};
use crate::smooth::{Params, SincInParts};

/// A windowed-sinc run with its drifting reference, under way between calls.
pub struct SincDrifting {
    /// The recurrence, until every term is summed.
    sinc: Option<SincInParts>,
    positions: Vec<[f32; 3]>,
    drift: DriftState,
    /// Drift steps taken of `params.iterations`.
    drifted: u32,
    iterations: u32,
}

impl SincDrifting {
    /// Starts `params` (windowed sinc; `None` for another filter) on the original mesh.
    pub fn new(original: &Original, params: &Params) -> Option<Self> {
        let sinc = SincInParts::new(original.mesh(), original.topology(), params)?;
        Some(Self {
            sinc: Some(sinc),
            positions: Vec::new(),
            drift: DriftState::start(original),
            drifted: 0,
            iterations: params.iterations,
        })
    }

    /// Up to `pieces` more pieces of work (a neighbour pass or a drift step each, about the
    /// same cost); returns whether the run is done. `params` and `weights` must stay the same.
    pub fn advance(
        &mut self,
        original: &Original,
        params: &Params,
        weights: Option<&[f32]>,
        pieces: u32,
    ) -> bool {
        let (mesh, topology) = (original.mesh(), original.topology());
        let mut left = pieces.max(1);
        if let Some(mut sinc) = self.sinc.take() {
            let before = sinc.progress().0;
            if !sinc.advance(mesh, topology, left) {
                self.sinc = Some(sinc);
                return false;
            }
            left = left.saturating_sub(sinc.progress().0 - before);
            self.positions = sinc.finish(mesh, params, weights);
        }
        let steps = left.min(self.iterations - self.drifted);
        let mut drift = DriftingReference::resume(original, std::mem::take(&mut self.drift));
        for _ in 0..steps {
            drift.update(&self.positions);
        }
        self.drift = drift.into_state();
        self.drifted += steps;
        self.drifted == self.iterations
    }

    /// `(pieces done, pieces)`: the passes, then the drift steps.
    pub fn progress(&self) -> (u32, u32) {
        let passes = match &self.sinc {
            Some(sinc) => sinc.progress().0,
            None => self.iterations,
        };
        (passes + self.drifted, 2 * self.iterations)
    }

    /// The positions and the drift (its references: [`super::smooth_drifting`]'s, bit for
    /// bit), once [`Self::advance`] returned true.
    pub fn into_result(self) -> (Vec<[f32; 3]>, DriftState) {
        (self.positions, self.drift)
    }
}
