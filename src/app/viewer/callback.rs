//! The 3D view as an egui paint callback. The GPU resources live in egui-wgpu's
//! `callback_resources` (created once by the `Viewer`); each frame's callback carries only the
//! per-frame record and what to draw.
//!
//! `prepare` draws the mesh into the view's own multisampled target (in egui's command encoder,
//! before egui's pass), and only when something changed: egui repaints for every pointer move
//! over any widget. `paint` composites the result into egui's pass.

use eframe::egui;
use eframe::egui_wgpu::{self, wgpu, CallbackResources, CallbackTrait};

use super::buffers::MeshBuffers;
use super::context::{far_to_near, ContextMesh};
use super::pipelines::Pipelines;
use super::slice::{SliceResources, SLICES};
use super::target::Target;
use crate::view::{SliceUniforms, ViewUniforms};

/// Everything the view keeps on the GPU, stored in egui-wgpu's type map: one view per app.
pub struct ViewResources {
    pub pipelines: Pipelines,
    pub uniforms: wgpu::Buffer,
    pub view_group: wgpu::BindGroup,
    pub mesh: MeshBuffers,
    /// The case's other structures, and a count of their changes.
    pub context: Vec<ContextMesh>,
    pub context_generation: u64,
    /// Where the last checks' warnings lie (patches of structures), drawn over everything,
    /// and a count of their changes.
    pub marks: Vec<ContextMesh>,
    pub marks_generation: u64,
    /// The case's image, shown on the clipping plane, and a count of its changes.
    pub slice: Option<SliceResources>,
    pub slice_generation: u64,
    /// The per-frame record with vertex colours on, for the other structures.
    context_uniforms: wgpu::Buffer,
    context_group: wgpu::BindGroup,
    target: Option<Target>,
    /// What the target holds, to skip drawing the same frame again.
    drawn: Option<Frame>,
}

/// Everything a drawn image depends on.
#[derive(Clone, Copy, PartialEq)]
struct Frame {
    uniforms: ViewUniforms,
    wireframe: bool,
    mesh_generation: u64,
    context_generation: u64,
    marks_generation: u64,
    slice_generation: u64,
    /// Where the image's slices lie, those drawn.
    slices: [Option<SliceUniforms>; SLICES],
    /// The surfaces draw their cut outline on the clip's slice.
    outlined: bool,
    show_model: bool,
    model_closed: bool,
    size: [u32; 2],
}

impl ViewResources {
    pub fn new(device: &wgpu::Device, pipelines: Pipelines) -> Self {
        let record = |label| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: std::mem::size_of::<ViewUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &pipelines.view_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                }],
            });
            (buffer, group)
        };
        let (uniforms, view_group) = record("meshsmooth view");
        let (context_uniforms, context_group) = record("meshsmooth view, other structures");
        Self {
            pipelines,
            uniforms,
            view_group,
            mesh: MeshBuffers::default(),
            context: Vec::new(),
            context_generation: 0,
            marks: Vec::new(),
            marks_generation: 0,
            slice: None,
            slice_generation: 0,
            context_uniforms,
            context_group,
            target: None,
            drawn: None,
        }
    }

    /// Draws the model, the other structures and the marks into the target (cleared to transparent) and
    /// resolves it.
    fn draw(&self, encoder: &mut wgpu::CommandEncoder, target: &Target, frame: &Frame) {
        let mut pass = view_pass(encoder, target);
        // A translucent model is drawn with the translucent structures, first.
        let model_translucent = frame.uniforms.base_color[3] < 1.0;
        // A closed surface's back faces lie behind its front ones, unless a plane cuts it open:
        // not drawing them spares the rasteriser about half its work; cut open, it is drawn
        // solid. Over the image's slice, the slice shows what the cut holds.
        let cut = frame.uniforms.clip[..3].iter().any(|&n| n != 0.0);
        let opaque = |closed: bool| match (frame.outlined, closed, cut) {
            (true, _, _) => &self.pipelines.surface_cut,
            (false, true, false) => &self.pipelines.front_faces,
            (false, true, true) => &self.pipelines.capped,
            (false, false, _) => &self.pipelines.surface,
        };
        pass.set_bind_group(0, &self.view_group, &[]);
        if let Some(resources) = &self.slice {
            pass.set_pipeline(&self.pipelines.slice);
            for ((_, group), _) in (resources.slices.iter())
                .zip(&frame.slices)
                .filter(|(_, s)| s.is_some())
            {
                pass.set_bind_group(1, group, &[]);
                pass.draw(0..6, 0..1);
            }
        }
        if frame.show_model && !model_translucent {
            pass.set_pipeline(opaque(frame.model_closed));
            draw_surface(&mut pass, &self.mesh);
        }
        pass.set_bind_group(0, &self.context_group, &[]);
        for context in self.context.iter().filter(|c| c.opaque) {
            pass.set_pipeline(opaque(context.closed));
            draw_surface(&mut pass, &context.buffers);
        }
        if let (true, true, Some(positions), Some(edges)) = (
            frame.wireframe,
            frame.show_model,
            &self.mesh.positions,
            &self.mesh.edges,
        ) {
            pass.set_bind_group(0, &self.view_group, &[]);
            pass.set_pipeline(&self.pipelines.wire);
            pass.set_vertex_buffer(0, positions.slice(..));
            pass.set_index_buffer(edges.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.mesh.edge_indices, 0, 0..1);
        }
        // Translucent structures last, far to near, over everything opaque.
        pass.set_pipeline(&self.pipelines.translucent);
        if frame.show_model && model_translucent {
            pass.set_bind_group(0, &self.view_group, &[]);
            draw_surface(&mut pass, &self.mesh);
        }
        pass.set_bind_group(0, &self.context_group, &[]);
        let eye = [0, 1, 2].map(|k| frame.uniforms.eye[k]);
        for i in far_to_near(&self.context, eye) {
            draw_surface(&mut pass, &self.context[i].buffers);
        }
        pass.set_pipeline(&self.pipelines.over);
        for marks in &self.marks {
            draw_surface(&mut pass, &marks.buffers);
        }
    }

    /// A software GPU (SwiftShader) compiles what runs a pipeline when a draw first uses it, on
    /// the GPU process's thread, in the frame that draws. One triangle drawn with each of the
    /// view's pipelines into a few pixels as the view is created has that done while the page
    /// starts and its first file is read, rather than in the frame that first shows a mesh.
    /// The submit also sends the pipelines themselves on, which a browser holds until a flush.
    pub fn warm_up(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<(), String> {
        const SIDE: u32 = 4;
        let p = &self.pipelines;
        let target = Target::new(device, p, [SIDE, SIDE]);
        let mut mesh = MeshBuffers::default();
        let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let normals = [[0.0, 0.0, 1.0]; 3];
        mesh.set_mesh(device, queue, &corners, &normals, &[[0, 1, 2]], &[[0, 1]])?;
        mesh.set_colors(queue, &[[255; 4]; 3])?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth view warm-up"),
        });
        {
            let mut pass = view_pass(&mut encoder, &target);
            pass.set_bind_group(0, &self.view_group, &[]);
            // Not the slice's pipelines: only a case with an image uses them.
            for pipeline in [
                &p.surface,
                &p.front_faces,
                &p.capped,
                &p.translucent,
                &p.over,
            ] {
                pass.set_pipeline(pipeline);
                draw_surface(&mut pass, &mesh);
            }
            if let (Some(positions), Some(edges)) = (&mesh.positions, &mesh.edges) {
                pass.set_pipeline(&p.wire);
                pass.set_vertex_buffer(0, positions.slice(..));
                pass.set_index_buffer(edges.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.edge_indices, 0, 0..1);
            }
        }
        // The composite, into a few pixels of egui's format as egui's pass has them.
        let out = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("meshsmooth view warm-up"),
                size: wgpu::Extent3d {
                    width: SIDE,
                    height: SIDE,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: p.color_format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&wgpu::TextureViewDescriptor::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("meshsmooth view warm-up composite"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &out,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&p.composite);
            pass.set_bind_group(0, &self.view_group, &[]);
            pass.set_bind_group(1, &target.composite_group, &[]);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The view's pass into `target`: colour cleared to transparent, depth cleared; only the
/// resolved image is kept.
fn view_pass<'e>(encoder: &'e mut wgpu::CommandEncoder, target: &Target) -> wgpu::RenderPass<'e> {
    let (color, resolve_target) = match &target.multisampled {
        Some(multisampled) => (multisampled, Some(&target.resolved)),
        None => (&target.resolved, None),
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("meshsmooth view"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                // Only the resolved image is read later.
                store: if resolve_target.is_some() {
                    wgpu::StoreOp::Discard
                } else {
                    wgpu::StoreOp::Store
                },
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &target.depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Draws `mesh`'s triangles with the pipeline and record set.
fn draw_surface(pass: &mut wgpu::RenderPass<'_>, mesh: &MeshBuffers) {
    let (Some(positions), Some(normals), Some(colors), Some(triangles)) = (
        &mesh.positions,
        &mesh.normals,
        &mesh.colors,
        &mesh.triangles,
    ) else {
        return;
    };
    pass.set_vertex_buffer(0, positions.slice(..));
    pass.set_vertex_buffer(1, normals.slice(..));
    pass.set_vertex_buffer(2, colors.slice(..));
    pass.set_index_buffer(triangles.slice(..), wgpu::IndexFormat::Uint32);
    pass.draw_indexed(0..mesh.triangle_indices, 0, 0..1);
}

/// One frame of the view.
pub struct ViewCallback {
    /// The view's rectangle in points, as egui will hand it to `paint`.
    pub rect: egui::Rect,
    pub uniforms: ViewUniforms,
    pub wireframe: bool,
    /// Whether the model itself is drawn (a case may hide it and show the others).
    pub show_model: bool,
    /// The model is closed and wound outward.
    pub model_closed: bool,
    /// Where the image's slices lie: the clipping plane's, or the three standard planes.
    pub slices: [Option<SliceUniforms>; SLICES],
    /// The surfaces draw their cut outline on the clip's slice.
    pub outlined: bool,
}

impl CallbackTrait for ViewCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(view) = resources.get_mut::<ViewResources>() else {
            return Vec::new();
        };
        // The viewport `paint` will get, computed the same way.
        let viewport = egui::epaint::ViewportInPixels::from_points(
            &self.rect,
            screen.pixels_per_point,
            screen.size_in_pixels,
        );
        if viewport.width_px <= 0 || viewport.height_px <= 0 {
            return Vec::new();
        }
        let size = [viewport.width_px as u32, viewport.height_px as u32];
        if view.target.as_ref().map(|t| t.size) != Some(size) {
            view.target = Some(Target::new(device, &view.pipelines, size));
        }
        let frame = Frame {
            uniforms: self.uniforms,
            wireframe: self.wireframe,
            mesh_generation: view.mesh.generation,
            context_generation: view.context_generation,
            marks_generation: view.marks_generation,
            slice_generation: view.slice_generation,
            slices: match view.slice {
                Some(_) => self.slices,
                None => [None; SLICES],
            },
            outlined: self.outlined && view.slice.is_some(),
            show_model: self.show_model,
            model_closed: self.model_closed,
            size,
        };
        if view.drawn == Some(frame) {
            return Vec::new();
        }
        queue.write_buffer(&view.uniforms, 0, bytemuck::bytes_of(&self.uniforms));
        let context = (self.uniforms.with_flags(crate::view::VERTEX_COLORS)).with_opacity(1.0);
        queue.write_buffer(&view.context_uniforms, 0, bytemuck::bytes_of(&context));
        if let Some(resources) = &view.slice {
            for ((buffer, _), slice) in resources.slices.iter().zip(&frame.slices) {
                if let Some(slice) = slice {
                    queue.write_buffer(buffer, 0, bytemuck::bytes_of(slice));
                }
            }
        }
        if let Some(target) = &view.target {
            view.draw(encoder, target, &frame);
        }
        view.drawn = Some(frame);
        Vec::new()
    }

    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        let Some(view) = resources.get::<ViewResources>() else {
            return;
        };
        let Some(target) = &view.target else {
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
        pass.set_pipeline(&view.pipelines.composite);
        pass.set_bind_group(0, &view.view_group, &[]);
        pass.set_bind_group(1, &target.composite_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
