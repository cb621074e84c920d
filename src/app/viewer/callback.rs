//! The 3D view as an egui paint callback: the GPU resources live in egui-wgpu's
//! `callback_resources` (created once by the `Viewer`), and each frame's callback carries only
//! the per-frame record and what to draw.

use eframe::egui_wgpu::{self, wgpu, CallbackResources, CallbackTrait};

use super::buffers::MeshBuffers;
use super::pipelines::Pipelines;
use crate::view::ViewUniforms;

/// Everything the view keeps on the GPU, stored in egui-wgpu's type map: one view per app.
pub struct ViewResources {
    pub pipelines: Pipelines,
    pub uniforms: wgpu::Buffer,
    pub bind_group: wgpu::BindGroup,
    pub mesh: MeshBuffers,
}

impl ViewResources {
    pub fn new(
        device: &wgpu::Device,
        target_format: wgpu::TextureFormat,
        depth_format: wgpu::TextureFormat,
    ) -> Self {
        let pipelines = Pipelines::new(device, target_format, depth_format);
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshsmooth view uniforms"),
            size: std::mem::size_of::<ViewUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("meshsmooth view"),
            layout: &pipelines.bind_group_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        Self {
            pipelines,
            uniforms,
            bind_group,
            mesh: MeshBuffers::default(),
        }
    }
}

/// One frame of the view.
pub struct ViewCallback {
    pub uniforms: ViewUniforms,
    pub wireframe: bool,
}

impl CallbackTrait for ViewCallback {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(view) = resources.get::<ViewResources>() {
            queue.write_buffer(&view.uniforms, 0, bytemuck::bytes_of(&self.uniforms));
        }
        Vec::new()
    }

    fn paint(
        &self,
        info: eframe::egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        let Some(view) = resources.get::<ViewResources>() else {
            return;
        };
        let mesh = &view.mesh;
        let (Some(positions), Some(normals), Some(colors), Some(triangles)) = (
            &mesh.positions,
            &mesh.normals,
            &mesh.colors,
            &mesh.triangles,
        ) else {
            return;
        };
        // egui's pass is shared: draw only inside our rectangle, clipped as egui clips it.
        let viewport = info.viewport_in_pixels();
        let clip = info.clip_rect_in_pixels();
        if viewport.width_px <= 0
            || viewport.height_px <= 0
            || clip.width_px <= 0
            || clip.height_px <= 0
        {
            return;
        }
        pass.set_viewport(
            viewport.left_px as f32,
            viewport.top_px as f32,
            viewport.width_px as f32,
            viewport.height_px as f32,
            0.0,
            1.0,
        );
        pass.set_scissor_rect(
            clip.left_px as u32,
            clip.top_px as u32,
            clip.width_px as u32,
            clip.height_px as u32,
        );
        pass.set_bind_group(0, &view.bind_group, &[]);

        pass.set_pipeline(&view.pipelines.surface);
        pass.set_vertex_buffer(0, positions.slice(..));
        pass.set_vertex_buffer(1, normals.slice(..));
        pass.set_vertex_buffer(2, colors.slice(..));
        pass.set_index_buffer(triangles.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..mesh.triangle_indices, 0, 0..1);

        if let (true, Some(edges)) = (self.wireframe, &mesh.edges) {
            pass.set_pipeline(&view.pipelines.wire);
            pass.set_vertex_buffer(0, positions.slice(..));
            pass.set_index_buffer(edges.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.edge_indices, 0, 0..1);
        }
    }
}
