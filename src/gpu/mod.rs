//! The GPU smoothing engine (wgpu: WebGPU in the browser, Vulkan/Metal/DX12/GL natively). It
//! imports wgpu but not egui, so the app, the CLI and the tests share it; each hands in its own
//! `wgpu::Device` and `wgpu::Queue`.
//!
//! A mesh is uploaded once ([`GpuSmoother::upload`] -> [`GpuMesh`]: positions as vec4<f32>, the
//! smoothing ring as CSR, the original positions, the weights); a run records every iteration
//! into one submission and never reads back in between; [`read_positions`] (native) or
//! [`PositionReadback`] (anywhere) bring the result back. The kernels in shaders/*.wgsl mirror
//! the CPU reference in [`crate::smooth`] operation for operation, and tests/gpu_filters.rs
//! holds them to it on a software adapter.
//!
//! Layout: `layout` (what Rust and WGSL share), `shaders` (sources), `pipelines` (layouts and
//! pipelines, per device), `mesh_buffers` (per mesh), `limits` (what fits), `smoother` (runs),
//! `readback`; natively also `device` (adapter choice) and `bench`. Measures can be added as
//! further kernels binding the same mesh buffers ([`GpuMesh::positions_buffer`] and co.).

mod error;
mod layout;
mod limits;
mod mesh_buffers;
mod pipelines;
mod readback;
pub mod shaders;
mod smoother;

#[cfg(not(target_arch = "wasm32"))]
mod bench;
#[cfg(not(target_arch = "wasm32"))]
mod device;

pub use error::GpuError;
pub use layout::WORKGROUP_SIZE;
pub use mesh_buffers::GpuMesh;
pub use readback::PositionReadback;
pub use smoother::GpuSmoother;

#[cfg(not(target_arch = "wasm32"))]
pub use bench::time_smoothing;
#[cfg(not(target_arch = "wasm32"))]
pub use device::{request_native_device, request_native_device_with_limits, GpuContext};
#[cfg(not(target_arch = "wasm32"))]
pub use readback::read_positions;
