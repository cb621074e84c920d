//! The session's CPU engine: asking its workers for the current revision's result and taking
//! it back, and taking results measured elsewhere (the GPU engine's).

use super::{Session, Timings};
use crate::case::Smoothed;
use crate::evaluate::ModelRef;
use crate::metrics::{Metrics, VertexMeasures};
use crate::worker::{metrics_of, Pool, Reply};

impl Session {
    /// Makes `cpu` the CPU engine (the page's workers); a run under way is asked again.
    pub fn set_cpu_engine(&mut self, cpu: Pool) {
        self.cpu = cpu;
        self.cpu_job = None;
    }

    /// The CPU engine: its workers, what it was asked.
    pub fn cpu_engine(&self) -> &Pool {
        &self.cpu
    }

    /// Takes the CPU engine's replies and hands its idle workers their next jobs (the ones
    /// already asked for: the view's result, the searches' parameter sets to come).
    pub fn pump_cpu_engine(&mut self) {
        self.cpu.pump();
    }

    /// The CPU engine's share of a frame: asks the workers for the current revision's result
    /// unless it is there or asked, and takes it once it came (then [`CaseDocument::result`](super::CaseDocument::result) has it
    /// and its timings come back). A newer revision supersedes an older one still waiting.
    pub fn compute_cpu(&mut self) -> Option<Timings> {
        let mut done = None;
        if let Some((revision, job)) = self.cpu_job {
            match self.cpu.take_smoothed(job) {
                Some(reply) => {
                    self.cpu_job = None;
                    done = self.accept_reply(revision, reply);
                }
                // Superseded below.
                None if revision != self.doc.revision => {}
                None => return None,
            }
        }
        let asked = self.cpu_job.is_some_and(|(r, _)| r == self.doc.revision);
        if self.doc.needs_smoothing() && !asked {
            let (params, tau) = (*self.doc.params(), self.doc.tau());
            // Field by field: the CPU engine is borrowed to change.
            if let Some(m) = self.doc.models.get(self.doc.current) {
                let structure = self.doc.case.structures.get(self.doc.current);
                let model = ModelRef {
                    original: &m.original,
                    id: self.doc.model_id,
                    weights: structure.and_then(|s| s.weights.as_deref()),
                    weights_version: self.doc.weights_version,
                };
                let job = self.cpu.smooth(&model, &params, tau, true);
                if let Some((_, old)) = self.cpu_job.replace((self.doc.revision, job)) {
                    self.cpu.forget(old);
                }
            }
        }
        done
    }

    /// Takes a worker's smoothing of `revision`; the timings when it is the current one.
    fn accept_reply(&mut self, revision: u64, reply: Reply) -> Option<Timings> {
        match reply {
            Reply::Smoothed {
                positions,
                metrics,
                vertex,
                smooth_ms,
                measure_ms,
                ..
            } => {
                let metrics = match metrics_of(&metrics) {
                    Ok(m) => m,
                    Err(why) => {
                        self.error = Some(why);
                        return None;
                    }
                };
                self.accept_measured(revision, positions, metrics, vertex)
                    .then_some(Timings {
                        smooth_ms,
                        measure_ms,
                    })
            }
            Reply::Failed { why, .. } => {
                self.error = Some(format!("The CPU engine failed: {why}"));
                None
            }
            _ => None,
        }
    }

    /// Whether the CPU engine is working on the current revision's result.
    pub fn smoothing_on_cpu(&self) -> bool {
        self.cpu_job
            .is_some_and(|(r, job)| r == self.doc.revision && self.cpu.pending(job))
    }

    /// Accepts a result measured elsewhere (the GPU engine's smoothing and measure pass) for
    /// `revision`. Returns false, and keeps nothing, when the session moved on since or the
    /// arrays do not fit the model.
    pub fn accept_measured(
        &mut self,
        revision: u64,
        positions: Vec<[f32; 3]>,
        metrics: Metrics,
        vertex: VertexMeasures,
    ) -> bool {
        let result = Smoothed {
            curvature: Some(vertex.gaussian_curvature),
            ..Smoothed::new(positions, metrics, Some(vertex.local_error))
        };
        self.doc.keep_result(revision, result)
    }
}
