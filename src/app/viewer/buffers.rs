//! The model on the GPU: vertex buffers (positions, normals, colours) and index buffers
//! (triangles, edges). Each is kept while its size stays the same, so new positions for the
//! same model are written in place; a model of another size replaces them.

use eframe::egui_wgpu::wgpu;
use wgpu::util::DeviceExt;

use super::pipelines::{COLOR_STRIDE, VEC4_STRIDE};

/// Everything the draw calls need; `None` buffers belong to an empty model.
#[derive(Default)]
pub struct MeshBuffers {
    pub positions: Option<wgpu::Buffer>,
    pub normals: Option<wgpu::Buffer>,
    /// Created zeroed with the model and written only when a colour map is set: with no colours
    /// the shader ignores it (a uniform flag), so nothing is uploaded per frame.
    pub colors: Option<wgpu::Buffer>,
    pub triangles: Option<wgpu::Buffer>,
    pub edges: Option<wgpu::Buffer>,
    pub vertex_count: u32,
    pub triangle_indices: u32,
    pub edge_indices: u32,
    /// Counts every change of the buffers' contents, so a drawn image knows it is stale.
    pub generation: u64,
}

/// Positions or normals as the vertex buffers hold them: vec4 with w = 0.
fn vec4s(v: &[[f32; 3]]) -> Vec<[f32; 4]> {
    v.iter().map(|&[x, y, z]| [x, y, z, 0.0]).collect()
}

/// Writes `bytes` into the buffer in `slot` when it has exactly that size, otherwise replaces
/// it with a new one holding them; empty contents leave no buffer.
fn write_or_replace(
    slot: &mut Option<wgpu::Buffer>,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    usage: wgpu::BufferUsages,
    bytes: &[u8],
) {
    if bytes.is_empty() {
        *slot = None;
        return;
    }
    match slot {
        Some(buffer) if buffer.size() == bytes.len() as u64 => queue.write_buffer(buffer, 0, bytes),
        _ => {
            *slot = Some(
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: usage | wgpu::BufferUsages::COPY_DST,
                }),
            );
        }
    }
}

impl MeshBuffers {
    /// A new model. Fails, leaving the previous model in place, when a buffer would exceed the
    /// device's limits or the counts do not fit the index type.
    pub fn set_mesh(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
    ) -> Result<(), String> {
        if normals.len() != positions.len() {
            return Err(format!(
                "{} normals for {} vertices",
                normals.len(),
                positions.len()
            ));
        }
        let too_many = || "the mesh has more than 4 billion vertices or indices".to_string();
        let vertex_count = u32::try_from(positions.len()).map_err(|_| too_many())?;
        let triangle_indices = u32::try_from(triangles.len() * 3).map_err(|_| too_many())?;
        let edge_indices = u32::try_from(edges.len() * 2).map_err(|_| too_many())?;
        let largest = (u64::from(vertex_count) * VEC4_STRIDE)
            .max(u64::from(triangle_indices) * 4)
            .max(u64::from(edge_indices) * 4);
        let limit = device.limits().max_buffer_size;
        if largest > limit {
            return Err(format!(
                "the mesh needs a {:.0} MB buffer; this GPU allows {:.0} MB",
                largest as f64 / 1e6,
                limit as f64 / 1e6
            ));
        }

        self.vertex_count = vertex_count;
        self.triangle_indices = triangle_indices;
        self.edge_indices = edge_indices;
        let index = wgpu::BufferUsages::INDEX;
        write_or_replace(
            &mut self.triangles,
            device,
            queue,
            "meshsmooth view triangles",
            index,
            bytemuck::cast_slice(triangles),
        );
        write_or_replace(
            &mut self.edges,
            device,
            queue,
            "meshsmooth view edges",
            index,
            bytemuck::cast_slice(edges),
        );
        self.colors = (vertex_count > 0).then(|| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("meshsmooth view colours"),
                size: u64::from(vertex_count) * COLOR_STRIDE,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        self.set_positions(device, queue, positions, normals)
    }

    /// New positions and normals for the same model.
    pub fn set_positions(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
    ) -> Result<(), String> {
        self.check_vertex_count("positions", positions.len())?;
        self.check_vertex_count("normals", normals.len())?;
        // Vertex buffers are also copy destinations for positions computed on the GPU.
        let vertex = wgpu::BufferUsages::VERTEX;
        write_or_replace(
            &mut self.positions,
            device,
            queue,
            "meshsmooth view positions",
            vertex,
            bytemuck::cast_slice(&vec4s(positions)),
        );
        write_or_replace(
            &mut self.normals,
            device,
            queue,
            "meshsmooth view normals",
            vertex,
            bytemuck::cast_slice(&vec4s(normals)),
        );
        self.generation += 1;
        Ok(())
    }

    /// Copies positions and normals from vec4 buffers on the same device, GPU to GPU.
    pub fn copy_positions_from(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        positions: &wgpu::Buffer,
        normals: &wgpu::Buffer,
    ) -> Result<(), String> {
        let (Some(own_positions), Some(own_normals)) = (&self.positions, &self.normals) else {
            // An empty model: nothing to copy.
            return Ok(());
        };
        let bytes = u64::from(self.vertex_count) * VEC4_STRIDE;
        for (what, source) in [("position", positions), ("normal", normals)] {
            if source.size() < bytes {
                return Err(format!(
                    "the {what} buffer holds {} bytes; {} vertices need {bytes}",
                    source.size(),
                    self.vertex_count
                ));
            }
            if !source.usage().contains(wgpu::BufferUsages::COPY_SRC) {
                return Err(format!(
                    "the {what} buffer cannot be copied from (no COPY_SRC)"
                ));
            }
        }
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth view positions from the engine"),
        });
        encoder.copy_buffer_to_buffer(positions, 0, own_positions, 0, bytes);
        encoder.copy_buffer_to_buffer(normals, 0, own_normals, 0, bytes);
        queue.submit([encoder.finish()]);
        self.generation += 1;
        Ok(())
    }

    /// Writes per-vertex RGBA8 colours.
    pub fn set_colors(&mut self, queue: &wgpu::Queue, colors: &[[u8; 4]]) -> Result<(), String> {
        self.check_vertex_count("colours", colors.len())?;
        if let Some(buffer) = &self.colors {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(colors));
        }
        self.generation += 1;
        Ok(())
    }

    fn check_vertex_count(&self, what: &str, count: usize) -> Result<(), String> {
        if count == self.vertex_count as usize {
            Ok(())
        } else {
            Err(format!(
                "{count} {what} for a model of {} vertices",
                self.vertex_count
            ))
        }
    }
}
