//! The WebGPU path: smoothing, the drifting reference, normals and the measure pass run as WGSL
//! compute on eframe's own device, so the view draws from the engine's buffers. Only the
//! measures and the positions (for colours, exports and the API) come back, asynchronously:
//! a frame never waits for the GPU.
//!
//! A run goes to the device in pieces (some iterations, the normals, parts of the measure), as
//! much per frame as keeps the frame's own work near [`crate::gpu::FRAME_WORK_MS`] (the
//! background's runs get what is left): the device runs its queue in order, so a frame drawn
//! after a whole run on a slow (software) adapter would wait for all of it. On a fast one the
//! pieces grow until a run fits a frame or two.
//!
//! Nothing new goes out while the device still runs the work of an earlier frame: the browser
//! does not wait for the queue, so without this the work of several frames piles up in it and
//! every frame drawn meanwhile waits for all of it.

use super::backend::EngineTimings;
use super::document::{now_ms, Document};
use crate::gpu::{
    FrameWork, GpuEvaluator, GpuMesh, GpuSmoother, MeasureReadback, ResultReadback, RunPieces,
};
use crate::suggest::Offload;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Frames whose device work may be unfinished when the next frame sends more.
const FRAMES_AHEAD: usize = 1;

/// A run being sent to the device in pieces, for one session revision.
struct Running {
    generation: u64,
    revision: u64,
    started_ms: f64,
    pieces: RunPieces,
}

/// A run submitted for one session revision, its results still on the way back.
struct InFlight {
    /// The document's model generation and session revision it was submitted for.
    generation: u64,
    revision: u64,
    started_ms: f64,
    positions: ResultReadback,
    measures: MeasureReadback,
    result: Option<Vec<[f32; 3]>>,
}

/// Meshes from this many vertices have the background's runs on the GPU by default. Below it
/// the CPU, sliced into the frame budget, finishes sooner: a GPU request's results come back a
/// frame or more later, while the CPU does a whole run of a small mesh within a frame.
const GPU_GUIDANCE_MIN_VERTICES: usize = 50_000;

/// Where the background's runs go: `?guidance=gpu` or `?guidance=cpu` in the page's query
/// decides, else the CPU on a software adapter, else the mesh size. A software adapter runs
/// the kernels on the same CPU, only slower than the engine's own loops (the quality graphs
/// on SwiftShader got through a fraction of the samples the CPU engine did in the same time,
/// at the same frame times).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidancePolicy {
    BySize,
    Gpu,
    Cpu,
}

impl GuidancePolicy {
    pub fn from_query(software_adapter: bool) -> Self {
        match super::query::param("guidance").as_deref() {
            Some("gpu") => GuidancePolicy::Gpu,
            Some("cpu") => GuidancePolicy::Cpu,
            _ if software_adapter => GuidancePolicy::Cpu,
            _ => GuidancePolicy::BySize,
        }
    }

    /// Whether a mesh of `vertices` has its background runs on the GPU.
    pub fn on_gpu(self, vertices: usize) -> bool {
        match self {
            GuidancePolicy::BySize => vertices >= GPU_GUIDANCE_MIN_VERTICES,
            GuidancePolicy::Gpu => true,
            GuidancePolicy::Cpu => false,
        }
    }
}

/// What a frame sent to the device (see [`GpuEngine::step`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sent {
    Nothing,
    /// A newly opened model's buffers.
    Model,
    /// A smoothing run with its measures.
    Run,
}

pub struct GpuEngine {
    device: wgpu::Device,
    queue: wgpu::Queue,
    smoother: GpuSmoother,
    /// The open model on the GPU, with the document's model generation it belongs to.
    mesh: Option<(u64, GpuMesh)>,
    running: Option<Running>,
    in_flight: Option<InFlight>,
    /// How much of a run goes out per frame.
    frame_work: FrameWork,
    /// The revision of the latest run submitted (its positions are in the buffers).
    submitted: Option<u64>,
    /// The session's weights version the mesh's weight buffer holds: uploaded once per change.
    weights_uploaded: Option<u64>,
    /// The background's runs (graphs, suggestions): its own copy of the model on the device,
    /// so they never disturb what is drawn. `None` once it has failed.
    evaluator: Option<GpuEvaluator>,
    policy: GuidancePolicy,
    device_work: DeviceWork,
}

/// The frames whose device work is unfinished: a frame that finds [`FRAMES_AHEAD`] of them
/// waits, sending nothing.
#[derive(Default)]
struct DeviceWork {
    /// Counted down as the device reports each frame's work done.
    unfinished: Arc<AtomicUsize>,
    /// This frame waits for the device.
    waiting: bool,
    /// This frame sent work not counted yet.
    sent: bool,
}

impl DeviceWork {
    fn begin_frame(&mut self, queue: &wgpu::Queue) {
        // A frame that ended without counting its work (it skipped the background) counts now.
        self.end_frame(queue);
        self.waiting = self.unfinished.load(Ordering::SeqCst) >= FRAMES_AHEAD;
    }

    /// Counts the frame's work, once all of it is submitted, as unfinished until the device
    /// reports it done.
    fn end_frame(&mut self, queue: &wgpu::Queue) {
        if !std::mem::take(&mut self.sent) {
            return;
        }
        self.unfinished.fetch_add(1, Ordering::SeqCst);
        let unfinished = Arc::clone(&self.unfinished);
        queue.on_submitted_work_done(move || {
            unfinished.fetch_sub(1, Ordering::SeqCst);
        });
    }
}

impl GpuEngine {
    /// The engine on eframe's device; `software_adapter`: the device is a software rasteriser
    /// (see [`GuidancePolicy::from_query`]).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, software_adapter: bool) -> Self {
        let smoother = GpuSmoother::new(device);
        Self {
            device: device.clone(),
            queue: queue.clone(),
            mesh: None,
            running: None,
            in_flight: None,
            frame_work: FrameWork::default(),
            submitted: None,
            weights_uploaded: None,
            evaluator: Some(GpuEvaluator::new(device, queue, &smoother, now_ms)),
            policy: GuidancePolicy::from_query(software_adapter),
            smoother,
            device_work: DeviceWork::default(),
        }
    }

    /// The evaluator for the background's runs on a mesh of `vertices`, while it works and
    /// when the policy puts them on the GPU, with what is left of this frame's device work
    /// (report what it sent with [`Self::guidance_sent`]).
    pub fn evaluator(&mut self, vertices: usize) -> Option<&mut dyn Offload> {
        if !self.policy.on_gpu(vertices) {
            return None;
        }
        // A run for the view waiting for room comes first: the background waits with it.
        let left = match self.frame_work.holding() || self.device_work.waiting {
            true => 0,
            false => self.frame_work.left(),
        };
        let evaluator = self.evaluator.as_mut()?;
        evaluator.share_frame(left);
        Some(evaluator as &mut dyn Offload)
    }

    /// Counts what the evaluator sent in this frame into the frame's work; the frame's device
    /// work is all submitted then (call it last).
    pub fn guidance_sent(&mut self) {
        if let Some(e) = &self.evaluator {
            let (steps, full, held) = e.frame_spent();
            self.frame_work.sent(steps, full);
            if held > 0 {
                self.frame_work.hold(held);
            }
            self.device_work.sent |= steps > 0;
        }
        self.device_work.end_frame(&self.queue);
    }

    /// Why the background's evaluator failed (it is dropped then: the CPU takes over).
    pub fn take_evaluator_failure(&mut self) -> Option<String> {
        let why = self.evaluator.as_ref()?.failure()?;
        self.evaluator = None;
        Some(why)
    }

    /// Starts a run for the current revision when the document needs one and none is under
    /// way; a new model is uploaded first, in a frame of its own. `Some` is what the frame
    /// sent when it goes no further.
    fn start_run(&mut self, doc: &Document) -> Result<Option<Sent>, String> {
        let generation = doc.session().case().model_id();
        if self
            .running
            .as_ref()
            .is_some_and(|r| r.generation != generation)
        {
            self.running = None;
        }
        if self.running.is_none() {
            if !doc.session().case().needs_smoothing() {
                return Ok(Some(Sent::Nothing));
            }
            let Some(model) = doc.session().case().model() else {
                return Ok(Some(Sent::Nothing));
            };
            if self.mesh.as_ref().map(|m| m.0) != Some(generation) {
                self.mesh = None;
                self.submitted = None;
                self.weights_uploaded = None;
                let uploaded = self
                    .smoother
                    .upload_with_measures(&self.device, &model.original)
                    .map_err(|e| e.to_string())?;
                self.mesh = Some((generation, uploaded));
                // A large model's upload fills a frame: its first run goes out with the next one.
                return Ok(Some(Sent::Model));
            }
            self.running = Some(Running {
                generation,
                revision: doc.session().case().revision(),
                started_ms: now_ms(),
                pieces: RunPieces::new(doc.session().case().params()),
            });
        }
        Ok(None)
    }

    /// The revision whose run the buffers hold for the document's model `generation`
    /// (submitted; maybe not finished yet). `None` while the engine still holds the model
    /// before: a new model can reach the view before the engine takes it up.
    pub fn submitted(&self, generation: u64) -> Option<u64> {
        self.submitted.filter(|_| self.holds(generation))
    }

    fn holds(&self, generation: u64) -> bool {
        self.mesh.as_ref().is_some_and(|(g, _)| *g == generation)
    }

    /// The buffers of the latest run of model `generation`: positions and normals, vec4 per
    /// vertex; `None` while the next run is under way in them, or for another model.
    pub fn buffers(&self, generation: u64) -> Option<(&wgpu::Buffer, &wgpu::Buffer)> {
        if self.running.is_some() || !self.holds(generation) {
            return None;
        }
        let (_, mesh) = self.mesh.as_ref()?;
        Some((mesh.positions_buffer(), mesh.normals_buffer()?))
    }

    /// One frame's work: collects a finished run into the session, and sends the next pieces
    /// of a run for the current parameters when the session needs one and no results are on
    /// the way back ([`Self::submitted`] names the revision once its positions and normals
    /// are in [`Self::buffers`]); a new model is uploaded in a frame of its own first. Returns
    /// what went to the device. An error (a mesh over the device's limits, a lost device) comes
    /// back for the caller to fall back to the CPU engine.
    pub fn step(&mut self, doc: &mut Document) -> Result<Sent, String> {
        self.frame_work.begin_frame(now_ms());
        self.device_work.begin_frame(&self.queue);
        self.collect(doc)?;
        if self.in_flight.is_some() || self.device_work.waiting {
            return Ok(Sent::Nothing);
        }
        if let Some(sent) = self.start_run(doc)? {
            return Ok(sent);
        }
        let (Some((_, mesh)), Some(run)) = (self.mesh.as_mut(), self.running.as_mut()) else {
            return Ok(Sent::Nothing);
        };
        let e = |e: crate::gpu::GpuError| e.to_string();
        let weights_version = doc.session().case().weights_version();
        if self.weights_uploaded != Some(weights_version) {
            mesh.set_weights(&self.queue, doc.session().case().weights())
                .map_err(e)?;
            self.weights_uploaded = Some(weights_version);
        }
        let smallest = run.pieces.next_cost(mesh).map_err(e)?;
        if self.frame_work.left() < smallest {
            // Too large for this frame: the frames until there is room save up for it.
            self.frame_work.hold(smallest);
            return Ok(Sent::Nothing);
        }
        let advance = run
            .pieces
            .advance(
                &self.smoother,
                &self.device,
                &self.queue,
                mesh,
                self.frame_work.left(),
            )
            .map_err(e)?;
        self.frame_work.sent(advance.spent, advance.full);
        self.device_work.sent = true;
        let stale = run.revision != doc.session().case().revision();
        if run.pieces.smoothed() && stale {
            // The parameters moved on: show where these took the mesh, skip its measures.
            self.submitted = Some(run.revision);
            self.running = None;
        } else if run.pieces.done() {
            let (positions, measures) = run
                .pieces
                .read_back(&self.device, &self.queue, mesh)
                .map_err(e)?;
            self.submitted = Some(run.revision);
            self.in_flight = Some(InFlight {
                generation: run.generation,
                revision: run.revision,
                started_ms: run.started_ms,
                positions,
                measures,
                result: None,
            });
            self.running = None;
        }
        Ok(Sent::Run)
    }

    /// Takes a finished run's results into the session (a run for an older revision is
    /// dropped: the next step submits the current one).
    fn collect(&mut self, doc: &mut Document) -> Result<(), String> {
        let Some(run) = self.in_flight.as_mut() else {
            return Ok(());
        };
        if run.generation != doc.session().case().model_id() {
            // A run for a model that is no longer open: its measures belong to another
            // original. Dropping it drops its pending mappings.
            self.in_flight = None;
            return Ok(());
        }
        if run.result.is_none() {
            match run.positions.try_take() {
                None => return Ok(()),
                Some(r) => run.result = Some(r.map_err(|e| e.to_string())?.positions),
            }
        }
        let Some(model) = doc.session().case().model() else {
            self.in_flight = None;
            return Ok(());
        };
        let measured = match run
            .measures
            .try_take(&model.original, doc.session().case().tau())
        {
            None => return Ok(()),
            Some(m) => m.map_err(|e| e.to_string())?,
        };
        let Some(run) = self.in_flight.take() else {
            return Ok(());
        };
        let (Some(positions), Some(vertex)) = (run.result, measured.vertex) else {
            return Err("the GPU measure pass returned no per-vertex measures".into());
        };
        if doc
            .session_mut()
            .accept_measured(run.revision, positions, measured.metrics, vertex)
        {
            doc.timings = Some(EngineTimings::Gpu {
                run_ms: now_ms() - run.started_ms,
            });
        }
        Ok(())
    }
}
