//! The other structures of a case, drawn around the one being smoothed: each in its own colour
//! and opacity, uploaded once per change of the case (not per frame).

use eframe::egui_wgpu::wgpu;

use super::buffers::MeshBuffers;

/// A structure to draw beside the model: its surface and display colour (sRGB, alpha the
/// opacity).
pub struct ContextSurface<'a> {
    pub positions: &'a [[f32; 3]],
    pub triangles: &'a [[u32; 3]],
    pub color: [u8; 4],
    /// Closed and wound outward: its back faces are never seen unless a plane cuts it.
    pub closed: bool,
}

/// One such structure on the GPU.
pub struct ContextMesh {
    pub buffers: MeshBuffers,
    pub opaque: bool,
    pub closed: bool,
    /// The middle of its bounding box: translucent structures are drawn far to near.
    pub centre: [f32; 3],
}

impl ContextMesh {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        surface: &ContextSurface<'_>,
    ) -> Result<Self, String> {
        let normals = crate::mesh::vertex_normals(surface.positions, surface.triangles);
        let mut buffers = MeshBuffers::default();
        buffers.set_mesh(
            device,
            queue,
            surface.positions,
            &normals,
            surface.triangles,
            &[],
        )?;
        buffers.set_colors(queue, &vec![surface.color; surface.positions.len()])?;
        Ok(Self {
            buffers,
            opaque: surface.color[3] == 255,
            closed: surface.closed,
            centre: centre(surface.positions),
        })
    }

    /// A new colour and opacity for the whole structure.
    pub fn recolor(&mut self, queue: &wgpu::Queue, color: [u8; 4]) -> Result<(), String> {
        let count = self.buffers.vertex_count as usize;
        self.buffers.set_colors(queue, &vec![color; count])?;
        self.opaque = color[3] == 255;
        Ok(())
    }
}

/// Every one of `surfaces` on the GPU, or why not.
pub fn upload_all(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    surfaces: &[ContextSurface<'_>],
) -> Result<Vec<ContextMesh>, String> {
    (surfaces.iter())
        .map(|s| ContextMesh::new(device, queue, s))
        .collect()
}

fn centre(positions: &[[f32; 3]]) -> [f32; 3] {
    crate::mesh::bounding_box(positions).map_or([0.0; 3], |(lo, hi)| {
        [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]))
    })
}

/// The order to draw translucent structures in: farthest from `eye` first.
pub fn far_to_near(meshes: &[ContextMesh], eye: [f32; 3]) -> Vec<usize> {
    let distance2 = |c: [f32; 3]| (0..3).map(|k| (c[k] - eye[k]).powi(2)).sum::<f32>();
    let mut order: Vec<usize> = (0..meshes.len()).filter(|&i| !meshes[i].opaque).collect();
    order.sort_by(|&a, &b| distance2(meshes[b].centre).total_cmp(&distance2(meshes[a].centre)));
    order
}
