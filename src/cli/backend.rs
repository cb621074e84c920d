//! `--backend cpu|gpu`: which engine smooths and measures for `smooth`, `sweep`, `suggest` and
//! `bench`. The GPU engine runs on this machine's wgpu adapter (Vulkan, Metal, DX12 or GL; a
//! software one such as lavapipe works too, slowly).

use crate::gpu::{self, GpuContext, GpuEvaluator, GpuSmoother};
use crate::metrics::{self, Metrics, Original};
use crate::smooth::{Filter, Params};
use crate::suggest::{
    search_evaluator, Evaluator, MeshEvaluator, ModelRef, Offload, Offloaded, SearchMethod,
};

/// Which engine does the work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Backend {
    Cpu,
    Gpu,
}

impl Backend {
    pub(super) fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Gpu => "gpu",
        }
    }
}

pub(super) fn parse_backend(name: &str) -> Result<Backend, String> {
    match name {
        "cpu" => Ok(Backend::Cpu),
        "gpu" => Ok(Backend::Gpu),
        other => Err(format!("unknown backend '{other}': use cpu or gpu")),
    }
}

/// The GPU engine on this machine's device, for one command.
pub(super) struct GpuEngine {
    pub context: GpuContext,
    pub smoother: GpuSmoother,
}

impl GpuEngine {
    pub(super) fn open() -> Result<Self, String> {
        let context = gpu::request_native_device().map_err(|e| format!("--backend gpu: {e}"))?;
        let smoother = GpuSmoother::new(&context.device);
        Ok(Self { context, smoother })
    }

    /// The adapter, as the reports name it.
    pub(super) fn adapter(&self) -> String {
        let info = &self.context.adapter_info;
        format!("{} ({:?}, {:?})", info.name, info.device_type, info.backend)
    }
}

/// The engine one command works on: the CPU, or the GPU engine opened once for it.
pub(super) enum Engine {
    Cpu,
    Gpu(Box<GpuEngine>),
}

impl Engine {
    pub(super) fn open(backend: Backend) -> Result<Self, String> {
        Ok(match backend {
            Backend::Cpu => Engine::Cpu,
            Backend::Gpu => Engine::Gpu(Box::new(GpuEngine::open()?)),
        })
    }

    pub(super) fn backend(&self) -> Backend {
        match self {
            Engine::Cpu => Backend::Cpu,
            Engine::Gpu(_) => Backend::Gpu,
        }
    }

    /// Runs `work` (a sweep; a search of a filter's parameters by a method) with an evaluator
    /// of `original`.
    pub(super) fn with_evaluator<R>(
        &self,
        original: &Original,
        search: Option<(Filter, SearchMethod)>,
        work: impl FnOnce(&mut dyn Evaluator) -> R,
    ) -> Result<R, String> {
        match self {
            Engine::Cpu => {
                let mut evaluator = match search {
                    Some((filter, method)) => search_evaluator(original, None, filter, method),
                    None => MeshEvaluator::new(original, None),
                }
                .map_err(|e| e.to_string())?;
                Ok(work(&mut evaluator))
            }
            Engine::Gpu(engine) => {
                let (device, queue) = (&engine.context.device, &engine.context.queue);
                let mut gpu_evaluator = GpuEvaluator::blocking(device, queue, &engine.smoother);
                let result = work(&mut Offloaded {
                    offload: &mut gpu_evaluator,
                    model: ModelRef {
                        original,
                        id: 0,
                        weights: None,
                        weights_version: 0,
                    },
                });
                match gpu_evaluator.failure() {
                    Some(why) => Err(format!("the GPU engine failed: {why}")),
                    None => Ok(result),
                }
            }
        }
    }

    /// Smooths from the original with the drifting reference, then measures.
    pub(super) fn smooth_and_measure(
        &self,
        original: &Original,
        params: &Params,
        tau: f64,
    ) -> Result<(Vec<[f32; 3]>, Metrics), String> {
        match self {
            Engine::Cpu => {
                let (positions, reference) = metrics::smooth_drifting(original, params, None);
                let metrics = metrics::measure(original, &positions, &reference, tau);
                Ok((positions, metrics))
            }
            Engine::Gpu(engine) => {
                let (device, queue) = (&engine.context.device, &engine.context.queue);
                let e = |e: gpu::GpuError| format!("the GPU engine failed: {e}");
                let mut mesh = engine
                    .smoother
                    .upload_with_measures(device, original)
                    .map_err(e)?;
                engine
                    .smoother
                    .smooth(device, queue, &mut mesh, params)
                    .map_err(e)?;
                let measured = engine
                    .smoother
                    .measure(device, queue, &mesh, false)
                    .map_err(e)?
                    .wait(device, original, tau)
                    .map_err(e)?;
                let positions = gpu::read_positions(device, queue, &mesh).map_err(e)?;
                Ok((positions, measured.metrics))
            }
        }
    }
}
