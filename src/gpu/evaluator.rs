//! Quality graphs and suggestions on the GPU engine: an [`Offload`] evaluator that smooths on
//! the device with the drifting reference and measures at the requested iteration counts inside
//! the same submission, reading back only each measure's per-workgroup sums.
//!
//! A run may be split into segments of a bounded size, one submission each, so the web app's
//! frames never queue behind a long run; the segment size adapts to how fast results come back.
//! Natively the evaluator can block instead ([`GpuEvaluator::blocking`]), for the CLI.

use super::layout::MeasurePartial;
use super::measures::totals;
use super::readback::Staging;
use super::smoother::Segment;
use super::{GpuError, GpuMesh, GpuSmoother};
use crate::metrics::{metrics_from_sums, Original};
use crate::smooth::{Filter, Params};
use crate::suggest::{
    failed_terms, is_cumulative, terms_of, unchanged_terms, ModelRef, Offload, Terms,
};

/// Vertex-iterations in a segment at first (five iterations of a 206k-vertex mesh), and the
/// largest. Results come back two or three calls (frames) after their submission however small
/// the work (the browser maps buffers between frames), so the size grows while results come
/// back that soon and only shrinks when a segment keeps many frames waiting (a software adapter
/// such as SwiftShader), down to one iteration.
const FIRST_SEGMENT: u64 = 1_000_000;
const MAX_SEGMENT: u64 = 1 << 31;

/// A request under way: its parameters, what is measured so far, and the segment in flight.
struct Job {
    model: u64,
    weights_version: u64,
    params: Params,
    at: Vec<u32>,
    terms: Vec<Terms>,
    /// Iterations of the current run done (cumulative filters).
    done: u32,
    in_flight: Option<InFlight>,
}

/// A submitted segment: where its measures come back, and how long they are taking.
struct InFlight {
    staging: Staging,
    to: u32,
    /// Calls that found it unfinished.
    polls: u32,
}

/// The GPU engine as an evaluator for [`crate::suggest`]'s tasks, on the device handed in. It
/// keeps its own copy of the model on the device (uploaded once per model id), so it never
/// disturbs what a renderer draws.
pub struct GpuEvaluator {
    device: wgpu::Device,
    queue: wgpu::Queue,
    smoother: GpuSmoother,
    mesh: Option<(u64, GpuMesh)>,
    weights_version: Option<u64>,
    job: Option<Job>,
    blocking: bool,
    /// Vertex-iterations per submission; `None`: whole runs.
    segment: Option<u64>,
    failure: Option<GpuError>,
    /// Smoothing runs finished (windowed sinc: one per count).
    pub runs: usize,
}

impl GpuEvaluator {
    /// An evaluator that never waits: runs go out in segments and [`Offload::measure`] answers
    /// `None` until the results are back (poll it once per frame).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, smoother: &GpuSmoother) -> Self {
        Self {
            device: device.clone(),
            queue: queue.clone(),
            smoother: smoother.clone(),
            mesh: None,
            weights_version: None,
            job: None,
            blocking: false,
            segment: Some(FIRST_SEGMENT),
            failure: None,
            runs: 0,
        }
    }

    /// An evaluator that submits whole runs and waits for each (native only).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn blocking(device: &wgpu::Device, queue: &wgpu::Queue, smoother: &GpuSmoother) -> Self {
        Self {
            blocking: true,
            segment: None,
            ..Self::new(device, queue, smoother)
        }
    }

    /// Bounds every submission to about `vertex_iterations` (at least one iteration), or lifts
    /// the bound (`None`); adaptation then starts from there.
    pub fn set_segment(&mut self, vertex_iterations: Option<u64>) {
        self.segment = vertex_iterations;
    }

    /// The model on the device for `model`, uploaded (or its weights updated) when it changed.
    fn prepare(&mut self, model: &ModelRef<'_>) -> Result<(), GpuError> {
        if self.mesh.as_ref().map(|m| m.0) != Some(model.id) {
            self.mesh = None;
            self.job = None;
            let uploaded = self
                .smoother
                .upload_with_measures(&self.device, model.original)?;
            self.mesh = Some((model.id, uploaded));
            self.weights_version = None;
        }
        if self.weights_version != Some(model.weights_version) {
            if let Some((_, mesh)) = self.mesh.as_mut() {
                mesh.set_weights(&self.queue, model.weights)?;
            }
            self.weights_version = Some(model.weights_version);
        }
        Ok(())
    }

    fn fail(&mut self, e: GpuError, count: usize) -> Option<Vec<Terms>> {
        self.failure = Some(e);
        self.job = None;
        Some(failed_terms(count))
    }

    /// Submits the job's next segment: cumulative filters up to the next counts that fit the
    /// segment size; windowed sinc one count (one whole run).
    fn submit_next(&mut self, vertices: u64) -> Result<(), GpuError> {
        let (Some(job), Some((_, mesh))) = (self.job.as_mut(), self.mesh.as_mut()) else {
            return Ok(());
        };
        let remaining = &job.at[job.terms.len()..];
        let Some(&last) = remaining.last() else {
            return Ok(());
        };
        let (from, to, measure_at) = if is_cumulative(job.params.filter) {
            let steps = if job.params.filter == Filter::Taubin {
                2
            } else {
                1
            };
            let per_iteration = (vertices * steps).max(1);
            let most = self
                .segment
                .map_or(u64::from(last), |s| (s / per_iteration).max(1));
            let to = (u64::from(job.done) + most).min(u64::from(last)) as u32;
            let upto = remaining.iter().take_while(|&&k| k <= to).count();
            (job.done, to, &remaining[..upto])
        } else {
            (0, remaining[0], &remaining[..1])
        };
        let bytes =
            u64::from(mesh.surface()?.partial_count) * std::mem::size_of::<MeasurePartial>() as u64;
        let sizes = vec![bytes; measure_at.len()];
        let staging = Staging::create(&self.device, "meshsmooth evaluator readback", &sizes);
        let segment = Segment {
            from,
            to,
            measure_at,
            into: Some((&staging, 0)),
        };
        self.smoother
            .smooth_segment(&self.device, &self.queue, mesh, &job.params, &segment)?;
        staging.request_map();
        job.in_flight = Some(InFlight {
            staging,
            to,
            polls: 0,
        });
        Ok(())
    }

    /// Collects the segment in flight when it is back; `Ok(false)` while it is not.
    fn collect(&mut self, original: &Original) -> Result<bool, GpuError> {
        let Some(job) = self.job.as_mut() else {
            return Ok(true);
        };
        let Some(flight) = job.in_flight.as_mut() else {
            return Ok(true);
        };
        let read = flight.staging.try_read(|parts| {
            Ok(parts
                .iter()
                .map(|bytes| {
                    let partials: Vec<MeasurePartial> = bytemuck::pod_collect_to_vec(bytes);
                    terms_of(&metrics_from_sums(original, &totals(&partials), 0.5))
                })
                .collect::<Vec<Terms>>())
        });
        let Some(terms) = read else {
            flight.polls += 1;
            return Ok(false);
        };
        let terms = terms?;
        let (to, polls) = (flight.to, flight.polls);
        job.in_flight = None;
        job.terms.extend(terms);
        job.done = to;
        if !is_cumulative(job.params.filter) {
            self.runs += 1;
        }
        // Back within the usual latency: segments may grow; one that kept many frames waiting
        // shrinks, down to the floor.
        if let Some(s) = self.segment.as_mut() {
            *s = match polls {
                0..=2 => (*s * 2).min(MAX_SEGMENT),
                3..=5 => *s,
                _ => (*s / 2).max(1),
            };
        }
        Ok(true)
    }

    #[cfg(not(target_arch = "wasm32"))]
    fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.to_string()))
    }

    #[cfg(target_arch = "wasm32")]
    fn wait(&self) -> Result<(), GpuError> {
        Ok(())
    }
}

impl Offload for GpuEvaluator {
    fn measure(&mut self, model: &ModelRef<'_>, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        if self.failure.is_some() {
            return Some(failed_terms(at.len()));
        }
        if let Err(e) = self.prepare(model) {
            return self.fail(e, at.len());
        }
        let same = self.job.as_ref().is_some_and(|j| {
            j.model == model.id
                && j.weights_version == model.weights_version
                && j.params == *params
                && j.at == at
        });
        if !same {
            // Zero iterations is the original mesh, whose terms are known exactly.
            let zeros = at.iter().take_while(|&&k| k == 0).count();
            self.job = Some(Job {
                model: model.id,
                weights_version: model.weights_version,
                params: *params,
                at: at.to_vec(),
                terms: vec![unchanged_terms(model.original); zeros],
                done: 0,
                in_flight: None,
            });
        }
        let vertices = model.original.mesh().vertex_count() as u64;
        loop {
            match self.collect(model.original) {
                Err(e) => return self.fail(e, at.len()),
                Ok(false) if self.blocking => {
                    if let Err(e) = self.wait() {
                        return self.fail(e, at.len());
                    }
                    continue;
                }
                Ok(false) => return None,
                Ok(true) => {}
            }
            let job = self.job.as_ref()?;
            if job.terms.len() == at.len() {
                let job = self.job.take()?;
                if is_cumulative(params.filter) && job.done > 0 {
                    self.runs += 1;
                }
                return Some(job.terms);
            }
            if let Err(e) = self.submit_next(vertices) {
                return self.fail(e, at.len());
            }
            if !self.blocking {
                return None;
            }
        }
    }

    fn waiting(&self) -> bool {
        !self.blocking && self.job.as_ref().is_some_and(|j| j.in_flight.is_some())
    }

    fn failure(&self) -> Option<String> {
        self.failure.as_ref().map(|e| e.to_string())
    }
}
