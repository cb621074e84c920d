//! Reading positions back: a copy into a MAP_READ buffer, then `map_async`. Natively the caller
//! blocks by polling the device; in the browser the mapping completes from the event loop, so
//! [`PositionReadback::try_take`] is polled instead. Only ever after a whole run.

use std::sync::{Arc, Mutex};

use super::limits::POSITION_BYTES;
use super::mesh_buffers::GpuMesh;
use super::GpuError;

type MapState = Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// A readback in flight: the staging buffer and the state its mapping callback fills in.
pub struct PositionReadback {
    staging: wgpu::Buffer,
    vertex_count: usize,
    mapped: MapState,
}

impl PositionReadback {
    /// Copies `mesh`'s latest positions (after the work already submitted) into a new staging
    /// buffer and requests its mapping.
    pub fn start(device: &wgpu::Device, queue: &wgpu::Queue, mesh: &GpuMesh) -> Self {
        let n = mesh.vertex_count();
        let size = (n.max(1) as u64) * POSITION_BYTES;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshsmooth position readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth readback"),
        });
        encoder.copy_buffer_to_buffer(mesh.positions_buffer(), 0, &staging, 0, size);
        queue.submit([encoder.finish()]);
        let mapped: MapState = Arc::new(Mutex::new(None));
        let done = Arc::clone(&mapped);
        staging.map_async(wgpu::MapMode::Read, .., move |result| {
            if let Ok(mut slot) = done.lock() {
                *slot = Some(result);
            }
        });
        Self {
            staging,
            vertex_count: n,
            mapped,
        }
    }

    /// The positions once the mapping has completed; `None` while it is pending.
    pub fn try_take(&self) -> Option<Result<Vec<[f32; 3]>, GpuError>> {
        let state = match self.mapped.lock() {
            Ok(mut state) => state.take(),
            Err(_) => return Some(Err(GpuError::Readback("mapping state poisoned".into()))),
        };
        Some(match state? {
            Err(e) => Err(GpuError::Readback(e.to_string())),
            Ok(()) => self.copy_out(),
        })
    }

    fn copy_out(&self) -> Result<Vec<[f32; 3]>, GpuError> {
        let positions = {
            let view = self
                .staging
                .get_mapped_range(..)
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            // Copies out, so the mapping's alignment does not matter.
            let vec4: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&view);
            vec4.iter()
                .take(self.vertex_count)
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        };
        self.staging.unmap();
        Ok(positions)
    }

    /// Blocks until the positions are back (native only: the browser cannot block).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait(self, device: &wgpu::Device) -> Result<Vec<[f32; 3]>, GpuError> {
        // Waiting on the latest submission runs the mapping callback; a second wait covers a
        // submission made by another thread in between.
        for _ in 0..2 {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            if let Some(result) = self.try_take() {
                return result;
            }
        }
        Err(GpuError::Readback(
            "the mapping did not complete after the device went idle".into(),
        ))
    }
}

/// The positions of `mesh`'s latest run (or its original positions before any), blocking until
/// the GPU has finished. Native only.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_positions(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &GpuMesh,
) -> Result<Vec<[f32; 3]>, GpuError> {
    PositionReadback::start(device, queue, mesh).wait(device)
}
