//! Timing the GPU engine (`meshsmooth bench --backend gpu`): a run's submission and the wait for
//! it, with the mesh already uploaded; and a measure pass with its small readback. Native only:
//! the browser cannot wait.

use std::time::Instant;

use super::GpuError;
use super::{GpuMesh, GpuSmoother};
use crate::metrics::Original;
use crate::smooth::Params;

fn wait(device: &wgpu::Device) -> Result<(), GpuError> {
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Device(e.to_string()))
}

/// Seconds one smoothing run with `params` takes on the device, from submission to completion
/// (upload and readback excluded). Waits for earlier work first so it is not counted.
pub fn time_smoothing(
    smoother: &GpuSmoother,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &mut GpuMesh,
    params: &Params,
) -> Result<f64, GpuError> {
    wait(device)?;
    let start = Instant::now();
    smoother.smooth(device, queue, mesh, params)?;
    wait(device)?;
    Ok(start.elapsed().as_secs_f64())
}

/// Seconds one measure pass over `mesh`'s latest result takes, from submission until its sums
/// are back on the host and reported against `original` (per-vertex arrays not read back).
/// Waits for earlier work first so it is not counted.
pub fn time_measures(
    smoother: &GpuSmoother,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &GpuMesh,
    original: &Original,
) -> Result<f64, GpuError> {
    wait(device)?;
    let start = Instant::now();
    smoother
        .measure(device, queue, mesh, false)?
        .wait(device, original, 0.5)?;
    Ok(start.elapsed().as_secs_f64())
}
