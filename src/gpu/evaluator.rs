//! Quality graphs and suggestions on the GPU engine: an [`Offload`] evaluator that smooths on
//! the device with the drifting reference and measures at the requested iteration counts inside
//! the same submission, reading back only each measure's per-workgroup sums.
//!
//! A run may be split into segments of a bounded size, one submission each, so the web app's
//! frames never queue behind a long run: the size adapts to how fast results come back, or
//! follows the share of each frame's device work the caller gives ([`GpuEvaluator::share_frame`],
//! as the web app does). A measure that does not fit a segment runs in parts, over the next
//! segments.
//! Natively the evaluator can block instead ([`GpuEvaluator::blocking`]), for the CLI.

use super::layout::MeasurePartial;
use super::measures::{roughness_ratio, totals};
use super::readback::Staging;
use super::smoother::Segment;
use super::work::{iteration_cost, measure_part_cost, plan_segment, AdaptiveSize};
use super::{Advance, GpuError, GpuMesh, GpuSmoother};
use crate::evaluate::{
    failed_terms, is_cumulative, terms_of, unchanged_terms, ModelRef, Offload, Request, Terms,
};
use crate::metrics::{metrics_from_sums, Original};
use crate::smooth::Params;

/// Vertex-steps in a segment at first and at least (about one iteration of a 206k-vertex
/// mesh, two whole 50-iteration runs of the 2,296-vertex sample), and at most. The floor
/// matters where round trips are long and noisy for reasons other than the work (SwiftShader's
/// slow frames): shrinking to single iterations of a small mesh would only multiply the trips.
const FIRST_SEGMENT: u64 = 250_000;
const MIN_SEGMENT: u64 = 250_000;
const MAX_SEGMENT: u64 = 1 << 40;
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
    /// The measure after `done` iterations is under way in parts: the next part to run.
    measuring: Option<usize>,
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
            measuring: None,
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

    /// Vertex-steps of the smallest segment of its run that smooths: an iteration (windowed
    /// sinc: the whole run to its next count).
    fn smallest_piece(&self, vertices: u64) -> u64 {
        let (params, at) = &self.request;
        let iteration = iteration_cost(params.filter, vertices);
        match is_cumulative(params.filter) {
            true => iteration,
            false => iteration * u64::from(at.get(self.terms.len()).copied().unwrap_or(1)),
        }
    }

    /// Vertex-steps of what is left of its run with its measures (windowed sinc: of its next
    /// count), on a mesh of `vertices` whose measure pass has `parts` parts.
    fn cost(&self, vertices: u64, parts: usize) -> u64 {
        let (params, at) = &self.request;
        let (last, measures) = match is_cumulative(params.filter) {
            true => (
                at.last().map_or(0, |&k| k - self.done),
                at.len() - self.terms.len(),
            ),
            false => (at.get(self.terms.len()).copied().unwrap_or(0), 1),
        };
        iteration_cost(params.filter, vertices) * u64::from(last)
            + measure_part_cost(vertices, parts) * (parts * measures) as u64
    }
}

/// A frame's share of the device work (see [`GpuEvaluator::share_frame`]).
#[derive(Clone, Copy, Debug, Default)]
struct FrameShare {
    budget: u64,
    spent: u64,
    full: bool,
    /// The piece held back (vertex-steps).
    held: u64,
}

/// A submitted segment: where its measures come back, and when it went out (ms).
struct InFlight {
    staging: Staging,
    to: u32,
    submitted_ms: f64,
    /// Whether the segment size limited what went out.
    full: bool,
}

/// The GPU engine as an evaluator for the searches' tasks, on the device handed in. It
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
    /// Vertex-steps per submission, adapting to the round trips; `None`: whole runs.
    segment: Option<AdaptiveSize>,
    /// This frame's share of the device work, when the caller shares it out (it then sizes
    /// the segments instead of the round trips).
    frame: Option<FrameShare>,
    /// The caller's clock (ms).
    clock: fn() -> f64,
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
            segment: Some(Self::adaptive(FIRST_SEGMENT)),
            frame: None,
            clock,
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

    /// Bounds every submission to about `vertex_steps` (at least one iteration or one part of
    /// a measure; adaptation may make them smaller), or lifts the bound (`None`: whole runs).
    pub fn set_segment(&mut self, vertex_steps: Option<u64>) {
        self.segment =
            vertex_steps.map(|s| AdaptiveSize::new(s, MIN_SEGMENT.min(s), s, TARGET_WORK_MS));
    }

    /// Sizes this frame's segments to `budget` vertex-steps in all instead of by the round
    /// trips: a segment whose smallest piece (an iteration, a part of a measure) is larger
    /// waits for a frame with room. See [`Self::frame_spent`].
    pub fn share_frame(&mut self, budget: u64) {
        self.frame = Some(FrameShare {
            budget,
            ..FrameShare::default()
        });
    }

    /// What happened since [`Self::share_frame`]: vertex-steps sent, whether the share
    /// limited them, and the piece held back for want of room (0: none).
    pub fn frame_spent(&self) -> (u64, bool, u64) {
        self.frame
            .map_or((0, false, 0), |f| (f.spent, f.full || f.held > 0, f.held))
    }

    fn adaptive(first: u64) -> AdaptiveSize {
        AdaptiveSize::new(first, MIN_SEGMENT, MAX_SEGMENT, TARGET_WORK_MS)
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
    /// segment size (`budget`, vertex-steps; `None`: the whole run), a measure that does not
    /// fit going on in parts over the next segments; windowed sinc one count (one whole run).
    fn submit_next(&mut self, j: usize, budget: Option<u64>) -> Result<Advance, GpuError> {
        let (Some(job), Some((_, mesh))) = (self.jobs.get_mut(j), self.mesh.as_mut()) else {
            return Ok(Advance::default());
        };
        let vertices = mesh.vertex_count() as u64;
        let (params, at) = &job.request;
        let remaining = &at[job.terms.len()..];
        if remaining.is_empty() {
            return Ok(Advance::default());
        }
        // Another run since this one's last segment left other positions on the device:
        // run again from the original (measuring only what is missing).
        let resumes = self.last_run.as_ref() == Some(&(job.model, job.request.clone()));
        if !resumes {
            job.measuring = None;
        }
        let bytes = mesh.surface()?.partial_bytes();
        let parts = GpuSmoother::measure_part_count(mesh)?;
        if let Some(next) = job.measuring {
            let gpu = (&self.device, &self.queue, &self.smoother);
            return measure_parts(gpu, self.clock, job, mesh, next, budget);
        }
        let iteration = iteration_cost(params.filter, vertices);
        let measure = measure_part_cost(vertices, parts) * parts as u64;
        let (from, to, upto, full) = if is_cumulative(params.filter) {
            let from = if resumes { job.done } else { 0 };
            let plan = plan_segment(from, remaining, iteration, measure, budget);
            job.measuring = plan.then_measure.then_some(0);
            (from, plan.to, plan.measured, plan.full)
        } else {
            (0, remaining[0], 1, false)
        };
        let measure_at = &remaining[..upto];
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
            full,
        });
        Ok(Advance {
            spent: u64::from(to - from) * iteration + upto as u64 * measure,
            full,
        })
    }

    /// Submits job `asked`'s next segment and, when it finishes its run, whole runs of the
    /// upcoming requests while they fit the rest of the segment size.
    fn submit(&mut self, asked: usize, model: &ModelRef<'_>) -> Result<(), GpuError> {
        let vertices = model.original.mesh().vertex_count() as u64;
        let budget = match self.frame {
            Some(f) => Some(f.budget.saturating_sub(f.spent)),
            None => self.segment.map(|s| s.size),
        };
        if let (Some(f), Some(left), Some((_, mesh))) = (self.frame.as_mut(), budget, &self.mesh) {
            let job = &self.jobs[asked];
            let smallest = match job.measuring {
                Some(_) => measure_part_cost(vertices, GpuSmoother::measure_part_count(mesh)?),
                None => job.smallest_piece(vertices),
            };
            if left < smallest {
                f.held = f.held.max(smallest);
                return Ok(());
            }
        }
        let sent = self.submit_next(asked, budget)?;
        let mut spent = sent.spent;
        // Other runs may follow only once this one is complete: a later segment goes on from
        // the state it leaves on the device.
        let job = &self.jobs[asked];
        let to = job.in_flight.as_ref().map(|f| f.to);
        let unfinished = to != job.request.1.last().copied() || job.measuring.is_some();
        let packs = budget.is_some() && !(is_cumulative(job.request.0.filter) && unfinished);
        if packs {
            let parts = match &self.mesh {
                Some((_, mesh)) => GpuSmoother::measure_part_count(mesh)?,
                None => 0,
            };
            let left = budget.unwrap_or(0);
            for request in std::mem::take(&mut self.upcoming) {
                let known = self
                    .jobs
                    .iter()
                    .any(|j| j.is(model, &request.0, &request.1));
                if known {
                    continue;
                }
                let job = Job::new(model, request);
                let cost = job.cost(vertices, parts);
                if job.answered() {
                    self.jobs.push(job);
                    continue;
                }
                let whole = is_cumulative(job.request.0.filter) || job.request.1.len() == 1;
                if spent + cost > left || !whole {
                    break;
                }
                self.jobs.push(job);
                let j = self.jobs.len() - 1;
                spent += self.submit_next(j, None)?.spent;
            }
        }
        if let Some(f) = self.frame.as_mut() {
            f.spent += spent;
            f.full |= sent.full;
        }
        Ok(())
    }

    /// Collects every segment that is back; returns the round trip (ms) of job `asked`'s
    /// segment when it came back in this call, and whether the segment size limited it.
    fn collect(
        &mut self,
        original: &Original,
        asked: usize,
    ) -> Result<Option<(f64, bool)>, GpuError> {
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
                        let metrics = metrics_from_sums(original, &totals(&partials), 0.5);
                        terms_of(&metrics, roughness_ratio(original, &partials))
                    })
                    .collect::<Vec<Terms>>())
            });
            let Some(terms) = read else {
                continue;
            };
            let terms = terms?;
            let (to, round_trip, full) = (flight.to, now - flight.submitted_ms, flight.full);
            job.in_flight = None;
            job.terms.extend(terms);
            job.done = to;
            if !is_cumulative(job.request.0.filter) || job.answered() {
                self.runs += 1;
            }
            if j == asked {
                asked_back = Some((round_trip, full));
            }
        }
        Ok(asked_back)
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
                Ok(Some((round_trip, full))) => {
                    // A frame's share, when given, sizes the segments instead.
                    if let (Some(size), None) = (self.segment.as_mut(), self.frame) {
                        size.adapt(round_trip, full);
                    }
                }
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
        let held = self.frame.is_some_and(|f| f.held > 0);
        !self.blocking && (held || self.jobs.iter().any(|j| j.in_flight.is_some()))
    }

    fn failure(&self) -> Option<String> {
        self.failure.as_ref().map(|e| e.to_string())
    }
}

/// Sends the next parts of `job`'s measure pass after its smoothing reached `job.done`, from
/// part `next`, within `budget`; its sums are read back after the last part.
fn measure_parts(
    (device, queue, smoother): (&wgpu::Device, &wgpu::Queue, &GpuSmoother),
    clock: fn() -> f64,
    job: &mut Job,
    mesh: &mut GpuMesh,
    next: usize,
    budget: Option<u64>,
) -> Result<Advance, GpuError> {
    let vertices = mesh.vertex_count() as u64;
    let bytes = mesh.surface()?.partial_bytes();
    let parts = GpuSmoother::measure_part_count(mesh)?;
    // Parts of the measure after `done` iterations, its sums read back after the last.
    let part_cost = measure_part_cost(vertices, parts);
    let count = budget.map_or(parts, |b| (b / part_cost).max(1) as usize);
    let end = (next + count).min(parts);
    smoother.measure_parts(device, queue, mesh, next..end)?;
    let finished = end == parts;
    let sizes: &[u64] = if finished { &[bytes] } else { &[] };
    let staging = Staging::create(device, "meshsmooth evaluator readback", sizes);
    if finished {
        let mut encoder = device.create_command_encoder(&Default::default());
        let (buffer, offset) = staging.region(0);
        encoder.copy_buffer_to_buffer(&mesh.surface()?.partials, 0, buffer, offset, bytes);
        queue.submit([encoder.finish()]);
    }
    staging.request_map();
    job.measuring = (!finished).then_some(end);
    let full = count < parts - next;
    job.in_flight = Some(InFlight {
        staging,
        to: job.done,
        submitted_ms: clock(),
        full,
    });
    Ok(Advance {
        spent: (end - next) as u64 * part_cost,
        full,
    })
}
