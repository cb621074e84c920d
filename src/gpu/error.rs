//! Errors of the GPU engine, each handled once by the caller (CLI message, app fallback to the
//! CPU engine).

use crate::smooth::ParamError;

/// What can keep the GPU engine from running or from returning positions.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GpuError {
    /// No adapter (GPU or software) with compute shaders and WebGPU's default limits.
    #[error("no GPU adapter with compute shaders and WebGPU's default limits was found{0}")]
    NoAdapter(String),
    #[error("the GPU device could not be created: {0}")]
    Device(String),
    /// The mesh needs more than one of the device's limits allows; checked before any upload.
    #[error(
        "mesh too large for the GPU: {what} needs {needed} but the device's {limit} is {allowed}"
    )]
    TooLarge {
        /// What needs it (e.g. "the positions of 9000000 vertices").
        what: String,
        /// The wgpu/WebGPU limit's name, e.g. `max_storage_buffer_binding_size`.
        limit: &'static str,
        needed: u64,
        allowed: u64,
    },
    /// The topology does not describe the mesh's vertices (built for another mesh).
    #[error("the topology does not match the mesh ({0})")]
    TopologyMismatch(String),
    #[error("{given} weights given for a mesh of {vertices} vertices: one per vertex is needed")]
    WeightCount { given: usize, vertices: usize },
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The drift, normals and measures need the buffers of
    /// [`super::GpuSmoother::upload_with_measures`].
    #[error("the mesh was uploaded without its measures (use upload_with_measures)")]
    NoMeasures,
    /// Reading positions back failed (device lost, mapping refused).
    #[error("reading positions back from the GPU failed: {0}")]
    Readback(String),
}
