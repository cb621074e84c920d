//! The GPU smoothing engine (wgpu: WebGPU in the browser, Vulkan/Metal/DX12/GL natively). It
//! imports wgpu but not egui, so the app, the CLI and the tests share it; each hands in its own
//! `wgpu::Device` and `wgpu::Queue`.
//!
//! A mesh is uploaded once ([`GpuSmoother::upload`] -> [`GpuMesh`]: positions as `vec4<f32>`, the
//! smoothing ring as CSR, the original positions, the weights); a run records every iteration
//! into one submission and never reads back in between; [`read_positions`] (native) or
//! [`PositionReadback`] (anywhere) bring the result back. The kernels in shaders/*.wgsl mirror
//! the CPU reference in [`crate::smooth`] operation for operation, and tests/gpu_filters.rs
//! holds them to it on a software adapter.
//!
//! For the app, a mesh uploaded with [`GpuSmoother::upload_with_measures`] also keeps
//! everything on the GPU that a frame needs without a round trip per step: runs drift each
//! vertex's reference vertex as [`crate::metrics::DriftingReference`] does;
//! [`GpuSmoother::compute_normals`] fills [`GpuMesh::normals_buffer`] and
//! [`GpuSmoother::measure`] the per-vertex measures and the [`crate::metrics::Metrics`]
//! numbers (local error, curvature, volume). Positions and normals can be bound as vertex
//! buffers; [`ResultReadback`] brings positions and references back together for the CPU
//! measures, [`MeasureReadback`] the GPU's; both are polled, never waited on, in the browser.
//!
//! Layout: `layout` (what Rust and WGSL share), `shaders` (sources), `pipelines` (layouts and
//! pipelines, per device), `mesh_buffers` (per mesh), `surface` (per mesh, for the drift,
//! normals and measures), `limits` (what fits), `smoother` (runs and surface passes),
//! `readback` and `measures` (results back); natively also `device` (adapter choice) and
//! `bench`.

mod adapter;
mod error;
mod evaluator;
mod layout;
mod limits;
mod measures;
mod mesh_buffers;
mod pieces;
mod pipelines;
mod readback;
pub mod shaders;
mod smoother;
mod surface;
mod work;

#[cfg(not(target_arch = "wasm32"))]
mod bench;
#[cfg(not(target_arch = "wasm32"))]
mod device;

pub use adapter::is_software_adapter;
pub use error::GpuError;
pub use evaluator::GpuEvaluator;
pub use layout::WORKGROUP_SIZE;
pub use measures::{GpuMeasures, MeasureReadback};
pub use mesh_buffers::GpuMesh;
pub use pieces::{Advance, RunPieces};
pub use readback::{PositionReadback, ResultReadback, SmoothResult};
pub use smoother::GpuSmoother;
pub use work::{FrameWork, FRAME_WORK_MS};

#[cfg(not(target_arch = "wasm32"))]
pub use bench::{time_measures, time_smoothing};
#[cfg(not(target_arch = "wasm32"))]
pub use device::{request_native_device, request_native_device_with_limits, GpuContext};
#[cfg(not(target_arch = "wasm32"))]
pub use readback::{read_normals, read_positions, read_result};
