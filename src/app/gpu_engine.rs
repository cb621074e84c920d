//! The WebGPU path: smoothing, the drifting reference, normals and the measure pass run as WGSL
//! compute on eframe's own device, so the view draws from the engine's buffers. Only the
//! measures and the positions (for colours, exports and the API) come back, asynchronously:
//! a frame never waits for the GPU.

use super::document::{now_ms, Document, EngineTimings};
use crate::gpu::{GpuEvaluator, GpuMesh, GpuSmoother, MeasureReadback, ResultReadback};
use crate::suggest::Offload;

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
/// frame or more later, while the CPU does a whole run of a small mesh in a millisecond or two
/// (the 2,296-vertex sample's local search: 0.24 s on the CPU natively; on SwiftShader WebGPU
/// at 5 frames/s, one request in three frames).
const GPU_GUIDANCE_MIN_VERTICES: usize = 50_000;

/// Where the background's runs go: `?guidance=gpu` or `?guidance=cpu` in the page's query
/// decides, else the mesh size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidancePolicy {
    BySize,
    Gpu,
    Cpu,
}

impl GuidancePolicy {
    pub fn from_query() -> Self {
        match super::page::query_value("guidance").as_deref() {
            Some("gpu") => GuidancePolicy::Gpu,
            Some("cpu") => GuidancePolicy::Cpu,
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
    in_flight: Option<InFlight>,
    /// The revision of the latest run submitted (its positions are in the buffers).
    submitted: Option<u64>,
    /// The session's weights version the mesh's weight buffer holds: uploaded once per change.
    weights_uploaded: Option<u64>,
    /// The background's runs (graphs, suggestions): its own copy of the model on the device,
    /// so they never disturb what is drawn. `None` once it has failed.
    evaluator: Option<GpuEvaluator>,
    policy: GuidancePolicy,
}

impl GpuEngine {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let smoother = GpuSmoother::new(device);
        Self {
            device: device.clone(),
            queue: queue.clone(),
            mesh: None,
            in_flight: None,
            submitted: None,
            weights_uploaded: None,
            evaluator: Some(GpuEvaluator::new(device, queue, &smoother, now_ms)),
            policy: GuidancePolicy::from_query(),
            smoother,
        }
    }

    /// The evaluator for the background's runs on a mesh of `vertices`, while it works and
    /// when the policy puts them on the GPU.
    pub fn evaluator(&mut self, vertices: usize) -> Option<&mut dyn Offload> {
        if !self.policy.on_gpu(vertices) {
            return None;
        }
        self.evaluator.as_mut().map(|e| e as &mut dyn Offload)
    }

    /// Why the background's evaluator failed (it is dropped then: the CPU takes over).
    pub fn take_evaluator_failure(&mut self) -> Option<String> {
        let why = self.evaluator.as_ref()?.failure()?;
        self.evaluator = None;
        Some(why)
    }

    /// The revision whose run the buffers hold (submitted; maybe not finished yet).
    pub fn submitted(&self) -> Option<u64> {
        self.submitted
    }

    /// The buffers of the latest run: positions and normals, vec4 per vertex.
    pub fn buffers(&self) -> Option<(&wgpu::Buffer, &wgpu::Buffer)> {
        let (_, mesh) = self.mesh.as_ref()?;
        Some((mesh.positions_buffer(), mesh.normals_buffer()?))
    }

    /// One frame's work: collects a finished run into the session, and submits a run for the
    /// current parameters when the session needs one and none is in flight ([`Self::submitted`]
    /// then names its revision: its positions and normals are in [`Self::buffers`]); a new model
    /// is uploaded in a frame of its own first. Returns what went to the device. An error (a mesh
    /// over the device's limits, a lost device) comes back for the caller to fall back to the
    /// CPU engine.
    pub fn step(&mut self, doc: &mut Document) -> Result<Sent, String> {
        self.collect(doc)?;
        if self.in_flight.is_some() || !doc.session.needs_smoothing() {
            return Ok(Sent::Nothing);
        }
        let Some(model) = doc.session.model() else {
            return Ok(Sent::Nothing);
        };
        let generation = doc.model_generation;
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
            return Ok(Sent::Model);
        }
        let Some((_, mesh)) = self.mesh.as_mut() else {
            return Ok(Sent::Nothing);
        };
        let params = *doc.session.params();
        let started_ms = now_ms();
        let e = |e: crate::gpu::GpuError| e.to_string();
        let weights_version = doc.session.weights_version();
        if self.weights_uploaded != Some(weights_version) {
            mesh.set_weights(&self.queue, doc.session.weights())
                .map_err(e)?;
            self.weights_uploaded = Some(weights_version);
        }
        self.smoother
            .smooth(&self.device, &self.queue, mesh, &params)
            .map_err(e)?;
        self.smoother
            .compute_normals(&self.device, &self.queue, mesh)
            .map_err(e)?;
        let measures = self
            .smoother
            .measure(&self.device, &self.queue, mesh, true)
            .map_err(e)?;
        let positions = ResultReadback::start(&self.device, &self.queue, mesh).map_err(e)?;
        self.submitted = Some(doc.session.revision());
        self.in_flight = Some(InFlight {
            generation,
            revision: doc.session.revision(),
            started_ms,
            positions,
            measures,
            result: None,
        });
        Ok(Sent::Run)
    }

    /// Takes a finished run's results into the session (a run for an older revision is
    /// dropped: the next step submits the current one).
    fn collect(&mut self, doc: &mut Document) -> Result<(), String> {
        let Some(run) = self.in_flight.as_mut() else {
            return Ok(());
        };
        if run.generation != doc.model_generation {
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
        let Some(model) = doc.session.model() else {
            self.in_flight = None;
            return Ok(());
        };
        let measured = match run.measures.try_take(&model.original, doc.session.tau()) {
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
            .session
            .accept_measured(run.revision, positions, measured.metrics, vertex)
        {
            doc.timings = Some(EngineTimings::Gpu {
                run_ms: now_ms() - run.started_ms,
            });
        }
        Ok(())
    }
}
