//! What the background's jobs run on: the CPU engine sliced to each call's budget, or the
//! offload (the GPU engine) the caller lends.

use crate::smooth::Params;
use crate::suggest::{
    Evaluator, Memoized, ModelRef, Offload, Offloaded, Request, Sliced, SlicedRuns, Terms,
    TermsMemo,
};

/// A job under way with the sliced-run state it keeps between calls.
pub(super) struct Running<T> {
    pub(super) task: T,
    pub(super) runs: SlicedRuns,
    /// When the first piece of work began (ms).
    pub(super) started_ms: Option<f64>,
}

impl<T> Running<T> {
    pub(super) fn new(task: T) -> Self {
        Self {
            task,
            runs: SlicedRuns::default(),
            started_ms: None,
        }
    }

    /// The evaluator for this job's next piece of work: the offload when one is lent, else
    /// the CPU engine sliced to the budget; either answers what the memo knows without
    /// measuring.
    pub(super) fn evaluator<'a>(
        &'a mut self,
        engine: &'a mut Engine<'_, '_>,
    ) -> Option<(&'a mut T, Memoized<'a, JobEvaluator<'a>>)> {
        self.started_ms.get_or_insert_with(engine.clock);
        let model = engine.model;
        let ev = match engine.offload.as_deref_mut() {
            Some(offload) => JobEvaluator::Offload(Offloaded { offload, model }),
            None => JobEvaluator::Cpu(
                Sliced::new(
                    model.original,
                    model.weights,
                    &mut self.runs,
                    engine.clock,
                    engine.budget_ms,
                )
                .ok()?,
            ),
        };
        Some((
            &mut self.task,
            Memoized {
                memo: &mut *engine.memo,
                inner: ev,
            },
        ))
    }
}

/// What one call's work runs on: the model, the clock and budget (CPU), and the offload when
/// the caller lends one.
pub(super) struct Engine<'m, 'o> {
    pub(super) model: ModelRef<'m>,
    pub(super) clock: &'m dyn Fn() -> f64,
    pub(super) budget_ms: f64,
    pub(super) offload: Option<&'o mut dyn Offload>,
    /// Terms measured before, for this model, weights and engine.
    pub(super) memo: &'m mut TermsMemo,
}

/// A job's evaluator for one call.
pub(super) enum JobEvaluator<'a> {
    Cpu(Sliced<'a>),
    Offload(Offloaded<'a>),
}

impl Evaluator for JobEvaluator<'_> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        match self {
            JobEvaluator::Cpu(ev) => ev.measure(params, at),
            JobEvaluator::Offload(ev) => ev.measure(params, at),
        }
    }

    fn wants_prefetch(&self) -> bool {
        match self {
            JobEvaluator::Cpu(ev) => ev.wants_prefetch(),
            JobEvaluator::Offload(ev) => ev.wants_prefetch(),
        }
    }

    fn prefetch(&mut self, requests: &[Request]) {
        match self {
            JobEvaluator::Cpu(ev) => ev.prefetch(requests),
            JobEvaluator::Offload(ev) => ev.prefetch(requests),
        }
    }
}
