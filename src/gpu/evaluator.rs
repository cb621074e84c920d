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
    failed_terms, is_cumulative, terms_of, unchanged_terms, ModelRef, Offload, Request, Terms,
};

/// Vertex-iterations in a segment at first and at least (about one iteration of a 206k-vertex
/// mesh, two whole 50-iteration runs of the 2,296-vertex sample), and at most. The floor
/// matters where round trips are long and noisy for reasons other than the work (SwiftShader's
/// slow frames): shrinking to single iterations of a small mesh would only multiply the trips.
const FIRST_SEGMENT: u64 = 250_000;
const MIN_SEGMENT: u64 = 250_000;
const MAX_SEGMENT: u64 = 1 << 31;
/// The device time a segment should take (ms). Results come back some frames after their
/// submission however small the work (the browser maps buffers between frames): the shortest
/// round trip seen stands for that latency, and what a segment takes beyond it for its work.
const TARGET_WORK_MS: f64 = 30.0;

/// A request under way or answered but not yet asked for: its parameters, what is measured so
/// far, and the segment in flight.
struct Job {
    model: u64,
    weights_version: u64,
    request: Request,
    terms: Vec<Terms>,
    /// Iterations of the current run done (cumulative filters).
    done: u32,
    in_flight: Option<InFlight>,
}

impl Job {
    fn new(model: &ModelRef<'_>, request: Request) -> Self {
        // Zero iterations (or steps that move nothing) give the original mesh, whose terms are
        // known exactly.
        let zeros = request.0.unchanged_counts(&request.1);
        Self {
            model: model.id,
            weights_version: model.weights_version,
            terms: vec![unchanged_terms(model.original); zeros],
            request,
            done: 0,
            in_flight: None,
        }
    }

    fn is(&self, model: &ModelRef<'_>, params: &Params, at: &[u32]) -> bool {
        self.model == model.id
            && self.weights_version == model.weights_version
            && self.request.0 == *params
            && self.request.1 == at
    }

    fn answered(&self) -> bool {
        self.terms.len() == self.request.1.len()
    }

    /// Vertex-iterations of what is left of its run (windowed sinc: of its next count).
    fn cost(&self, vertices: u64) -> u64 {
        let (params, at) = &self.request;
        let last = match is_cumulative(params.filter) {
            true => at.last().map_or(0, |&k| k - self.done),
            false => at.get(self.terms.len()).copied().unwrap_or(0),
        };
        vertices * steps_per_iteration(params.filter) * u64::from(last)
    }
}

/// Smoothing steps in one iteration: Taubin's lambda and mu steps, one for the others (the
/// unit of a segment's size).
fn steps_per_iteration(filter: Filter) -> u64 {
    if filter == Filter::Taubin {
        2
    } else {
        1
    }
}

/// A submitted segment: where its measures come back, and when it went out (ms).
struct InFlight {
    staging: Staging,
    to: u32,
    submitted_ms: f64,
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
    /// The request asked for, and the requests prefetched with it (several whole runs go to
    /// the device at once when they fit a segment).
    jobs: Vec<Job>,
    /// The requests the task said will follow.
    upcoming: Vec<Request>,
    /// The model and request whose run was submitted last (its state is on the device).
    last_run: Option<(u64, Request)>,
    blocking: bool,
    /// Vertex-iterations per submission; `None`: whole runs.
    segment: Option<u64>,
    /// The caller's clock (ms) and the shortest round trip seen.
    clock: fn() -> f64,
    latency_ms: Option<f64>,
    failure: Option<GpuError>,
    /// Smoothing runs finished (windowed sinc: one per count).
    pub runs: usize,
}

impl GpuEvaluator {
    /// An evaluator that never waits: runs go out in segments sized by `clock` (milliseconds)
    /// and [`Offload::measure`] answers `None` until the results are back (poll it once per
    /// frame).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        smoother: &GpuSmoother,
        clock: fn() -> f64,
    ) -> Self {
        Self {
            device: device.clone(),
            queue: queue.clone(),
            smoother: smoother.clone(),
            mesh: None,
            weights_version: None,
            jobs: Vec::new(),
            upcoming: Vec::new(),
            last_run: None,
            blocking: false,
            segment: Some(FIRST_SEGMENT),
            clock,
            latency_ms: None,
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
            ..Self::new(device, queue, smoother, || 0.0)
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
            self.jobs.clear();
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
        self.jobs.clear();
        Some(failed_terms(count))
    }

    /// Submits job `j`'s next segment: cumulative filters up to the next counts that fit the
    /// segment size (`budget`, vertex-iterations; `None`: the whole run); windowed sinc one
    /// count (one whole run).
    fn submit_next(&mut self, j: usize, budget: Option<u64>) -> Result<(), GpuError> {
        let (Some(job), Some((_, mesh))) = (self.jobs.get_mut(j), self.mesh.as_mut()) else {
            return Ok(());
        };
        let vertices = mesh.vertex_count() as u64;
        let (params, at) = &job.request;
        let remaining = &at[job.terms.len()..];
        let Some(&last) = remaining.last() else {
            return Ok(());
        };
        let (from, to, measure_at) = if is_cumulative(params.filter) {
            let per_iteration = (vertices * steps_per_iteration(params.filter)).max(1);
            let most = budget.map_or(u64::from(last), |s| (s / per_iteration).max(1));
            let to = (u64::from(job.done) + most).min(u64::from(last)) as u32;
            let upto = remaining.iter().take_while(|&&k| k <= to).count();
            // Another run since this one's last segment left other positions on the device:
            // run again from the original (measuring only what is missing).
            let resumes = self.last_run.as_ref() == Some(&(job.model, job.request.clone()));
            let from = if resumes { job.done } else { 0 };
            (from, to, &remaining[..upto])
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
            .smooth_segment(&self.device, &self.queue, mesh, params, &segment)?;
        staging.request_map();
        self.last_run = Some((job.model, job.request.clone()));
        job.in_flight = Some(InFlight {
            staging,
            to,
            submitted_ms: (self.clock)(),
        });
        Ok(())
    }

    /// Submits job `asked`'s next segment and, when it finishes its run, whole runs of the
    /// upcoming requests while they fit the rest of the segment size.
    fn submit(&mut self, asked: usize, model: &ModelRef<'_>) -> Result<(), GpuError> {
        let vertices = model.original.mesh().vertex_count() as u64;
        let cost = self.jobs[asked].cost(vertices);
        self.submit_next(asked, self.segment)?;
        let Some(mut left) = self.segment.map(|s| s.saturating_sub(cost)) else {
            return Ok(());
        };
        // Other runs may follow only once this one is complete: a later segment goes on from
        // the state it leaves on the device.
        let job = &self.jobs[asked];
        let to = job.in_flight.as_ref().map(|f| f.to);
        if is_cumulative(job.request.0.filter) && to != job.request.1.last().copied() {
            return Ok(());
        }
        for request in std::mem::take(&mut self.upcoming) {
            let known = self
                .jobs
                .iter()
                .any(|j| j.is(model, &request.0, &request.1));
            if known {
                continue;
            }
            let job = Job::new(model, request);
            let cost = job.cost(vertices);
            if job.answered() {
                self.jobs.push(job);
                continue;
            }
            if cost > left || !(is_cumulative(job.request.0.filter) || job.request.1.len() == 1) {
                break;
            }
            left -= cost;
            self.jobs.push(job);
            let j = self.jobs.len() - 1;
            self.submit_next(j, None)?;
        }
        Ok(())
    }

    /// Collects every segment that is back; returns the round trip (ms) of job `asked`'s
    /// segment when it came back in this call.
    fn collect(&mut self, original: &Original, asked: usize) -> Result<Option<f64>, GpuError> {
        let now = (self.clock)();
        let mut asked_back = None;
        for (j, job) in self.jobs.iter_mut().enumerate() {
            let Some(flight) = job.in_flight.as_mut() else {
                continue;
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
                continue;
            };
            let terms = terms?;
            let (to, round_trip) = (flight.to, now - flight.submitted_ms);
            job.in_flight = None;
            job.terms.extend(terms);
            job.done = to;
            if !is_cumulative(job.request.0.filter) || job.answered() {
                self.runs += 1;
            }
            if j == asked {
                asked_back = Some(round_trip);
            }
        }
        Ok(asked_back)
    }

    /// Sizes the next segments from a round trip of `round_trip_ms`: twice as large while the
    /// work in it (beyond the shortest round trip seen) stays well under [`TARGET_WORK_MS`],
    /// half as large when it is well over, down to [`MIN_SEGMENT`] (or the size set, when
    /// smaller).
    fn adapt(&mut self, round_trip_ms: f64) {
        let latency = self
            .latency_ms
            .map_or(round_trip_ms, |l| l.min(round_trip_ms));
        self.latency_ms = Some(latency);
        let work = round_trip_ms - latency;
        if let Some(s) = self.segment.as_mut() {
            if work < TARGET_WORK_MS / 2.0 {
                *s = (*s * 2).min(MAX_SEGMENT);
            } else if work > 2.0 * TARGET_WORK_MS {
                *s = (*s / 2).max(MIN_SEGMENT.min(*s));
            }
        }
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
        // Keep what is asked, prefetched or on the device; forget the rest.
        let upcoming = &self.upcoming;
        self.jobs.retain(|j| {
            j.in_flight.is_some()
                || j.is(model, params, at)
                || upcoming.iter().any(|(p, a)| j.is(model, p, a))
        });
        let asked = match self.jobs.iter().position(|j| j.is(model, params, at)) {
            Some(j) => j,
            None => {
                self.jobs.push(Job::new(model, (*params, at.to_vec())));
                self.jobs.len() - 1
            }
        };
        loop {
            match self.collect(model.original, asked) {
                Err(e) => return self.fail(e, at.len()),
                Ok(Some(round_trip)) => self.adapt(round_trip),
                Ok(None) => {}
            }
            let job = &self.jobs[asked];
            if job.answered() {
                let job = self.jobs.remove(asked);
                return Some(job.terms);
            }
            if job.in_flight.is_none() {
                if let Err(e) = self.submit(asked, model) {
                    return self.fail(e, at.len());
                }
            }
            if !self.blocking {
                return None;
            }
            if let Err(e) = self.wait() {
                return self.fail(e, at.len());
            }
        }
    }

    fn wants_prefetch(&self) -> bool {
        !self.blocking
    }

    fn prefetch(&mut self, _model: &ModelRef<'_>, requests: &[Request]) {
        self.upcoming = requests.to_vec();
    }

    fn waiting(&self) -> bool {
        !self.blocking && self.jobs.iter().any(|j| j.in_flight.is_some())
    }

    fn failure(&self) -> Option<String> {
        self.failure.as_ref().map(|e| e.to_string())
    }
}
