//! The two render pipelines of the 3D view and their one bind group layout, created once for
//! egui's framebuffer format and depth format.
//!
//! Both draw into egui's own render pass (no MSAA on the web), so their target, depth format
//! and sample count are egui's. Only WebGL2-level features are used: vertex attributes, one
//! uniform buffer, depth bias on triangles.

use std::borrow::Cow;
use std::num::NonZeroU64;

use eframe::egui_wgpu::wgpu;

use crate::view::{ViewUniforms, RENDER_SHADER};

/// Bytes per vertex of the position and normal buffers: vec4<f32>, as the GPU engine stores
/// positions (w ignored).
pub const VEC4_STRIDE: u64 = 16;
/// Bytes per vertex of the colour buffer: RGBA8.
pub const COLOR_STRIDE: u64 = 4;

/// Depth bias of the surface: the wireframe is drawn at the surface's own depth with `LessEqual`,
/// so pushing the surface back a little keeps its edges in front of it. The slope term covers
/// triangles seen at grazing angles, where a line and the surface differ most within a pixel.
/// (WebGPU allows depth bias only on triangle pipelines, so it goes on the surface.)
const SURFACE_DEPTH_BIAS: wgpu::DepthBiasState = wgpu::DepthBiasState {
    constant: 2,
    slope_scale: 1.5,
    clamp: 0.0,
};

pub struct Pipelines {
    pub bind_group_layout: wgpu::BindGroupLayout,
    /// Lit, two-sided triangles; writes depth.
    pub surface: wgpu::RenderPipeline,
    /// Edges as a line list over the same positions; tests depth, writes none.
    pub wire: wgpu::RenderPipeline,
}

/// Vertex attributes, one buffer each, at the locations shaders/render.wgsl reads.
const POSITION: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x4];
const NORMAL: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![1 => Float32x4];
const COLOR: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![2 => Unorm8x4];

fn per_vertex(
    stride: u64,
    attributes: &'static [wgpu::VertexAttribute],
) -> Option<wgpu::VertexBufferLayout<'static>> {
    Some(wgpu::VertexBufferLayout {
        array_stride: stride,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes,
    })
}

impl Pipelines {
    pub fn new(
        device: &wgpu::Device,
        target_format: wgpu::TextureFormat,
        depth_format: wgpu::TextureFormat,
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("meshsmooth view"),
            source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(RENDER_SHADER)),
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshsmooth view"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: NonZeroU64::new(std::mem::size_of::<ViewUniforms>() as u64),
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("meshsmooth view"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });

        let surface_buffers = [
            per_vertex(VEC4_STRIDE, &POSITION),
            per_vertex(VEC4_STRIDE, &NORMAL),
            per_vertex(COLOR_STRIDE, &COLOR),
        ];
        let surface = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshsmooth surface"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_surface"),
                compilation_options: Default::default(),
                buffers: &surface_buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                // Two-sided: open meshes show their inside.
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: wgpu::StencilState::default(),
                bias: SURFACE_DEPTH_BIAS,
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_surface"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    // Opaque.
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });

        let wire = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshsmooth wireframe"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_wire"),
                compilation_options: Default::default(),
                buffers: &[per_vertex(VEC4_STRIDE, &POSITION)],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::LineList,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_wire"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    // The shader writes premultiplied alpha, as egui blends.
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });

        Self {
            bind_group_layout,
            surface,
            wire,
        }
    }
}
