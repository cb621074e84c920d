//! Windowed sinc spread over calls. Its terms are not shorter filters' results, so
//! [`super::resume`] cannot continue it; this keeps the recurrence between calls instead, for a
//! caller without threads that has a frame to draw between them.

use super::constraint::Limits;
use super::rings::Rings;
use super::sinc::Terms;
use super::{Filter, Free, Params};
use crate::mesh::{Mesh, Topology};

/// A windowed-sinc run under way: [`SincInParts::advance`] sums terms (a neighbour pass each),
/// [`SincInParts::finish`] gives [`super::smooth`]'s result, bit for bit.
pub struct SincInParts {
    /// `None` when nothing moves (no iterations, no vertices, or a topology of another mesh).
    terms: Option<Terms>,
}

impl SincInParts {
    /// Starts `params` (windowed sinc; `None` for another filter) on `mesh` with its first
    /// neighbour pass. `topology` must be built from `mesh`.
    pub fn new(mesh: &Mesh, topology: &Topology, params: &Params) -> Option<Self> {
        if params.filter != Filter::Sinc {
            return None;
        }
        let terms = Rings::new(topology, mesh.vertex_count()).and_then(|rings| {
            Terms::start(rings, &mesh.positions, params.passband, params.iterations)
        });
        Some(Self { terms })
    }

    /// Sums up to `more` further terms; returns whether every term is summed. `topology` must
    /// be the one given to [`Self::new`].
    pub fn advance(&mut self, mesh: &Mesh, topology: &Topology, more: u32) -> bool {
        let (Some(terms), Some(rings)) = (
            self.terms.as_mut(),
            Rings::new(topology, mesh.vertex_count()),
        ) else {
            return true;
        };
        terms.advance(rings, more)
    }

    /// `(neighbour passes done, passes)`.
    pub fn progress(&self) -> (u32, u32) {
        self.terms.as_ref().map_or((0, 0), Terms::progress)
    }

    /// The smoothed positions with `weights` and the bound of `params` applied, once
    /// [`Self::advance`] returned true. No observer sees them: [`super::smooth`] would report
    /// them `params.iterations` times as a step, which the caller does itself.
    pub fn finish(self, mesh: &Mesh, params: &Params, weights: Option<&[f32]>) -> Vec<[f32; 3]> {
        let original = &mesh.positions;
        let Some(terms) = self.terms else {
            return original.clone();
        };
        match Limits::new(weights, params.max_displacement, original) {
            None => terms.finish(original, &Free),
            Some(limits) => terms.finish(original, &limits),
        }
    }
}
