//! What the background's jobs run on: the CPU engine's workers, or the offload (the GPU
//! engine) the caller lends. Either answers later; the jobs ask again at the next call.

use crate::evaluate::{ModelRef, Offload, Offloaded};
use crate::suggest::{Memoized, TermsMemo};
use crate::worker::Pool;

/// A job under way, with when it began.
pub(super) struct Running<T> {
    pub(super) task: T,
    /// When the first piece of work began (ms).
    pub(super) started_ms: Option<f64>,
}

impl<T> Running<T> {
    pub(super) fn new(task: T) -> Self {
        Self {
            task,
            started_ms: None,
        }
    }

    /// The evaluator for this job's next piece of work: the offload when one is lent, else
    /// the CPU engine's workers; either answers what the memo knows without measuring.
    pub(super) fn evaluator<'a>(
        &'a mut self,
        engine: &'a mut Engine<'_, '_>,
    ) -> (&'a mut T, Memoized<'a, Offloaded<'a>>) {
        self.started_ms.get_or_insert_with(engine.clock);
        let offload: &mut dyn Offload = match engine.offload.as_deref_mut() {
            Some(offload) => offload,
            None => &mut *engine.cpu,
        };
        let ev = Offloaded {
            offload,
            model: engine.model,
        };
        (
            &mut self.task,
            Memoized {
                memo: &mut *engine.memo,
                inner: ev,
            },
        )
    }
}

/// What one call's work runs on: the model, the clock, the CPU engine's workers and the
/// offload when the caller lends one.
pub(super) struct Engine<'m, 'o> {
    pub(super) model: ModelRef<'m>,
    pub(super) clock: &'m dyn Fn() -> f64,
    pub(super) cpu: &'m mut Pool,
    pub(super) offload: Option<&'o mut dyn Offload>,
    /// Terms measured before, for this model, weights and engine.
    pub(super) memo: &'m mut TermsMemo,
}
