//! Timing the GPU engine (`meshsmooth bench --backend gpu`): a run's submission and the wait for
//! it, with the mesh already uploaded. Native only: the browser cannot wait.

use std::time::Instant;

use super::GpuError;
use super::{GpuMesh, GpuSmoother};
use crate::smooth::Params;

/// Seconds one smoothing run with `params` takes on the device, from submission to completion
/// (upload and readback excluded). Waits for earlier work first so it is not counted.
pub fn time_smoothing(
    smoother: &GpuSmoother,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &mut GpuMesh,
    params: &Params,
) -> Result<f64, GpuError> {
    let wait = |device: &wgpu::Device| {
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Device(e.to_string()))
    };
    wait(device)?;
    let start = Instant::now();
    smoother.smooth(device, queue, mesh, params)?;
    wait(device)?;
    Ok(start.elapsed().as_secs_f64())
}
