//! Which engine smooths on the page, and how long its last result took (the status bar's
//! figures).

use crate::session::Timings;

/// Which engine smooths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// WGSL compute on the page's WebGPU device.
    WebGpu,
    /// The CPU engine in WebAssembly (where WebGPU is missing).
    Cpu,
}

impl Backend {
    /// The name the embedding API's `backend()` returns.
    pub fn name(self) -> &'static str {
        match self {
            Backend::WebGpu => "webgpu",
            Backend::Cpu => "cpu",
        }
    }
}

/// How long the last result took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EngineTimings {
    /// The CPU engine: smoothing and the measure pass, each on its own.
    Cpu(Timings),
    /// The GPU engine: from submitting the run (smoothing, drift, normals, measures) to
    /// having its results back on the CPU.
    Gpu { run_ms: f64 },
}

impl EngineTimings {
    pub fn describe(&self) -> String {
        match self {
            EngineTimings::Cpu(t) => format!(
                "{:.1} ms smoothing, {:.1} ms measures",
                t.smooth_ms, t.measure_ms
            ),
            EngineTimings::Gpu { run_ms } => {
                format!("{run_ms:.1} ms smoothing + measures on the GPU, with readback")
            }
        }
    }
}
