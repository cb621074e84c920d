//! Reading results back: copies into one MAP_READ buffer, then `map_async`. Natively the caller
//! blocks by polling the device; in the browser the mapping completes from the event loop, so
//! the readbacks' `try_take` is polled instead (once per frame, say). Only ever after a whole
//! run: nothing here waits between the steps of a run.

use std::ops::Range;
use std::sync::{Arc, Mutex};

use super::limits::POSITION_BYTES;
use super::mesh_buffers::GpuMesh;
use super::GpuError;

type MapState = Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// A staging buffer being mapped, holding copies of several buffers one after another.
pub(crate) struct Staging {
    buffer: wgpu::Buffer,
    /// Where each source's copy lies in `buffer`.
    regions: Vec<Range<u64>>,
    mapped: MapState,
}

impl Staging {
    /// Records into `encoder` copies of the first `bytes` of each source, one after another,
    /// submits it and requests the mapping. Every size must be a multiple of 4.
    pub(crate) fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut encoder: wgpu::CommandEncoder,
        label: &str,
        sources: &[(&wgpu::Buffer, u64)],
    ) -> Self {
        let sizes: Vec<u64> = sources.iter().map(|&(_, bytes)| bytes).collect();
        let staging = Self::create(device, label, &sizes);
        for (&(source, bytes), region) in sources.iter().zip(&staging.regions) {
            if bytes > 0 {
                encoder.copy_buffer_to_buffer(source, 0, &staging.buffer, region.start, bytes);
            }
        }
        queue.submit([encoder.finish()]);
        staging.request_map();
        staging
    }

    /// A staging buffer with one region per size, one after another, not yet written or
    /// mapped: record copies into [`Self::region`]s, submit them, then [`Self::request_map`].
    /// Every size must be a multiple of 4.
    pub(crate) fn create(device: &wgpu::Device, label: &str, sizes: &[u64]) -> Self {
        let mut regions = Vec::with_capacity(sizes.len());
        let mut end = 0;
        for &bytes in sizes {
            regions.push(end..end + bytes);
            end += bytes;
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            // Never empty: a mesh without vertices still gets a (useless) mapping.
            size: end.max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            regions,
            mapped: Arc::new(Mutex::new(None)),
        }
    }

    /// The buffer copies go into, and where region `k` lies in it.
    pub(crate) fn region(&self, k: usize) -> (&wgpu::Buffer, u64) {
        (&self.buffer, self.regions[k].start)
    }

    /// Requests the mapping, after the submissions that write the buffer.
    pub(crate) fn request_map(&self) {
        let done = Arc::clone(&self.mapped);
        self.buffer
            .map_async(wgpu::MapMode::Read, .., move |result| {
                if let Ok(mut slot) = done.lock() {
                    *slot = Some(result);
                }
            });
    }

    /// `read` applied to the copies (in source order) once the mapping has completed; `None`
    /// while it is pending. The buffer is unmapped afterwards, so this yields once.
    pub(crate) fn try_read<T>(
        &self,
        read: impl FnOnce(&[&[u8]]) -> Result<T, GpuError>,
    ) -> Option<Result<T, GpuError>> {
        let state = match self.mapped.lock() {
            Ok(mut state) => state.take(),
            Err(_) => return Some(Err(GpuError::Readback("mapping state poisoned".into()))),
        };
        Some(match state? {
            Err(e) => Err(GpuError::Readback(e.to_string())),
            Ok(()) => self.read_mapped(read),
        })
    }

    fn read_mapped<T>(
        &self,
        read: impl FnOnce(&[&[u8]]) -> Result<T, GpuError>,
    ) -> Result<T, GpuError> {
        let result = {
            let view = self
                .buffer
                .get_mapped_range(..)
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            let parts: Vec<&[u8]> = self
                .regions
                .iter()
                .map(|r| &view[r.start as usize..r.end as usize])
                .collect();
            read(&parts)
        };
        self.buffer.unmap();
        result
    }
}

/// Blocks until `try_take` yields (native only: the browser cannot block).
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn wait_for<T>(
    device: &wgpu::Device,
    mut try_take: impl FnMut() -> Option<Result<T, GpuError>>,
) -> Result<T, GpuError> {
    // Waiting on the latest submission runs the mapping callback. When another thread polls
    // the same device, it may have collected the callback and not yet called it when the
    // device goes idle here: keep polling briefly until it has.
    let deadline = std::time::Instant::now() + MAPPING_GRACE;
    loop {
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        if let Some(result) = try_take() {
            return result;
        }
        if std::time::Instant::now() >= deadline {
            return Err(GpuError::Readback(
                "the mapping did not complete after the device went idle".into(),
            ));
        }
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
}

/// How long a mapping may lag behind the device going idle (see [`wait_for`]).
#[cfg(not(target_arch = "wasm32"))]
const MAPPING_GRACE: std::time::Duration = std::time::Duration::from_secs(10);

fn encoder(device: &wgpu::Device) -> wgpu::CommandEncoder {
    device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("meshsmooth readback"),
    })
}

/// xyz of `n` `vec4<f32>` (copied out, so the mapping's alignment does not matter).
fn vec3s(bytes: &[u8], n: usize) -> Vec<[f32; 3]> {
    let vec4: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(bytes);
    vec4.iter().take(n).map(|p| [p[0], p[1], p[2]]).collect()
}

/// A readback of positions in flight.
pub struct PositionReadback {
    staging: Staging,
    vertex_count: usize,
}

impl PositionReadback {
    /// Copies `mesh`'s latest positions (after the work already submitted) into a new staging
    /// buffer and requests its mapping.
    pub fn start(device: &wgpu::Device, queue: &wgpu::Queue, mesh: &GpuMesh) -> Self {
        let n = mesh.vertex_count();
        let sources = [(mesh.positions_buffer(), n as u64 * POSITION_BYTES)];
        Self {
            staging: Staging::start(
                device,
                queue,
                encoder(device),
                "meshsmooth position readback",
                &sources,
            ),
            vertex_count: n,
        }
    }

    /// The positions once the mapping has completed; `None` while it is pending.
    pub fn try_take(&self) -> Option<Result<Vec<[f32; 3]>, GpuError>> {
        self.staging
            .try_read(|parts| Ok(vec3s(parts[0], self.vertex_count)))
    }

    /// Blocks until the positions are back (native only: the browser cannot block).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait(self, device: &wgpu::Device) -> Result<Vec<[f32; 3]>, GpuError> {
        wait_for(device, || self.try_take())
    }
}

/// A run's result as the CPU measures want it: positions and each vertex's reference vertex on
/// the original mesh (for [`crate::metrics::measure`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SmoothResult {
    pub positions: Vec<[f32; 3]>,
    pub reference: Vec<u32>,
}

/// A readback of positions and reference vertices together, in flight: one copy, one mapping.
pub struct ResultReadback {
    staging: Staging,
    vertex_count: usize,
}

impl ResultReadback {
    /// Copies `mesh`'s latest positions and reference vertices (after the work already
    /// submitted) into a new staging buffer and requests its mapping. Needs a mesh uploaded
    /// with its measures.
    pub fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
    ) -> Result<Self, GpuError> {
        let surface = mesh.surface()?;
        let n = mesh.vertex_count();
        let sources = [
            (mesh.positions_buffer(), n as u64 * POSITION_BYTES),
            (&surface.reference, n as u64 * 4),
        ];
        Ok(Self {
            staging: Staging::start(
                device,
                queue,
                encoder(device),
                "meshsmooth result readback",
                &sources,
            ),
            vertex_count: n,
        })
    }

    /// Positions and references once the mapping has completed; `None` while it is pending.
    pub fn try_take(&self) -> Option<Result<SmoothResult, GpuError>> {
        self.staging.try_read(|parts| {
            Ok(SmoothResult {
                positions: vec3s(parts[0], self.vertex_count),
                reference: bytemuck::pod_collect_to_vec(parts[1]),
            })
        })
    }

    /// Blocks until the result is back (native only: the browser cannot block).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait(self, device: &wgpu::Device) -> Result<SmoothResult, GpuError> {
        wait_for(device, || self.try_take())
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

/// The positions and reference vertices of `mesh`'s latest run, blocking. Native only.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_result(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &GpuMesh,
) -> Result<SmoothResult, GpuError> {
    ResultReadback::start(device, queue, mesh)?.wait(device)
}

/// The vertex normals of the latest [`super::GpuSmoother::compute_normals`], blocking (for
/// tests and tools; a renderer binds [`GpuMesh::normals_buffer`] instead). Native only.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_normals(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &GpuMesh,
) -> Result<Vec<[f32; 3]>, GpuError> {
    let n = mesh.vertex_count();
    let sources = [(&mesh.surface()?.normals, n as u64 * POSITION_BYTES)];
    let staging = Staging::start(
        device,
        queue,
        encoder(device),
        "meshsmooth normal readback",
        &sources,
    );
    wait_for(device, || staging.try_read(|parts| Ok(vec3s(parts[0], n))))
}
