//! The 3D view's render pipelines: the surface and the wireframe draw into the view's own
//! multisampled target; the composite copies its resolved image into egui's render pass.
//!
//! egui's pass on the web has one sample per pixel, which leaves silhouettes and lines jagged;
//! jaggies on a staircase mesh would pass for the very artefacts the app smooths. Only
//! WebGL2-level features are used: vertex attributes, one uniform buffer, a sampled texture,
//! 4x MSAA (which WebGPU and WebGL2 both guarantee for 8-bit RGBA).

use std::borrow::Cow;
use std::num::NonZeroU64;

use eframe::egui_wgpu::wgpu;

use crate::view::{SliceUniforms, ViewUniforms, RENDER_SHADER};

/// Bytes per vertex of the position and normal buffers: vec4<f32>, as the GPU engine stores
/// positions (w ignored).
pub const VEC4_STRIDE: u64 = 16;
/// Bytes per vertex of the colour buffer: RGBA8.
pub const COLOR_STRIDE: u64 = 4;

/// The view's own depth buffer.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24Plus;

/// Samples per pixel of the view's target when the device allows it.
const MSAA_SAMPLES: u32 = 4;

pub struct Pipelines {
    /// Group 0: the per-frame `View` record.
    pub view_layout: wgpu::BindGroupLayout,
    /// Group 1 of the composite: the resolved image.
    pub composite_layout: wgpu::BindGroupLayout,
    /// Group 1 of the slice: where it lies, the image and its sampler.
    pub slice_layout: wgpu::BindGroupLayout,
    /// Lit, two-sided triangles; writes depth.
    pub surface: wgpu::RenderPipeline,
    /// The same, front faces only: for closed surfaces wound outward, none cut open.
    pub front_faces: wgpu::RenderPipeline,
    /// The same, translucent: blended over what is drawn, tests depth, writes none.
    pub translucent: wgpu::RenderPipeline,
    /// The same, blended over everything whatever lies in front: marks that must show
    /// where they lie hidden (inside another structure).
    pub over: wgpu::RenderPipeline,
    /// Two-sided surfaces over the image's slice: their cut outline drawn on it.
    pub surface_cut: wgpu::RenderPipeline,
    /// Closed surfaces cut open by the clipping plane, drawn solid (their cut face filled).
    pub capped: wgpu::RenderPipeline,
    /// The image's slice on the clipping plane; opaque, writes depth.
    pub slice: wgpu::RenderPipeline,
    /// Edges as a line list over the same positions; tests depth, writes none.
    pub wire: wgpu::RenderPipeline,
    /// The resolved image into egui's pass.
    pub composite: wgpu::RenderPipeline,
    /// Samples per pixel of the surface and wireframe target.
    pub samples: u32,
    /// Format of the view's colour target: egui's, so the shader's encoding is egui's too.
    pub color_format: wgpu::TextureFormat,
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

/// 4x when the adapter can multisample both the colour format and the depth format, else 1;
/// 1 on a software adapter (SwiftShader in headless Chromium), where every sample costs CPU
/// time: orbiting a large mesh there takes about twice as long a frame at 4x.
fn sample_count(adapter: &wgpu::Adapter, color_format: wgpu::TextureFormat) -> u32 {
    if crate::gpu::is_software_adapter(&adapter.get_info()) {
        return 1;
    }
    let supports = |format| {
        adapter
            .get_texture_format_features(format)
            .flags
            .sample_count_supported(MSAA_SAMPLES)
    };
    if supports(color_format) && supports(DEPTH_FORMAT) {
        MSAA_SAMPLES
    } else {
        1
    }
}

impl Pipelines {
    /// Pipelines for egui's framebuffer format and egui's depth format (`None` when egui's
    /// pass has no depth buffer; the composite must match the pass it draws in).
    pub fn new(
        device: &wgpu::Device,
        adapter: &wgpu::Adapter,
        target_format: wgpu::TextureFormat,
        egui_depth_format: Option<wgpu::TextureFormat>,
    ) -> Self {
        let samples = sample_count(adapter, target_format);
        let build = Builder::new(device, target_format, samples);
        let less = wgpu::CompareFunction::Less;
        // The shader writes premultiplied alpha.
        let blend = Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
        let back = Some(wgpu::Face::Back);
        Self {
            // Two-sided: open meshes show their inside.
            surface: build.surface("meshsmooth surface", None, true, less, None),
            front_faces: build.surface("meshsmooth front faces", back, true, less, None),
            translucent: build.triangles(
                "meshsmooth translucent surface",
                None,
                Builder::depth(false, less),
                blend,
                "fs_translucent",
            ),
            over: build.surface(
                "meshsmooth surface over all",
                None,
                false,
                wgpu::CompareFunction::Always,
                blend,
            ),
            surface_cut: build
                .two_sided_with_depth("meshsmooth surface over a slice", "fs_surface_cut"),
            capped: build.two_sided_with_depth("meshsmooth capped surface", "fs_surface_capped"),
            slice: build.slice(),
            wire: build.wire(),
            composite: build.composite(egui_depth_format),
            samples,
            color_format: target_format,
            view_layout: build.view_layout,
            composite_layout: build.composite_layout,
            slice_layout: build.slice_layout,
        }
    }
}

/// What every pipeline of the view shares: the shader, the bind group layouts, the sample
/// count and egui's colour format.
struct Builder<'a> {
    device: &'a wgpu::Device,
    module: wgpu::ShaderModule,
    view_layout: wgpu::BindGroupLayout,
    composite_layout: wgpu::BindGroupLayout,
    slice_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    composite_pipeline_layout: wgpu::PipelineLayout,
    slice_pipeline_layout: wgpu::PipelineLayout,
    multisample: wgpu::MultisampleState,
    target_format: wgpu::TextureFormat,
}

impl<'a> Builder<'a> {
    fn new(device: &'a wgpu::Device, target_format: wgpu::TextureFormat, samples: u32) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("meshsmooth view"),
            source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(RENDER_SHADER)),
        });
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
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
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshsmooth view composite"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                // Loaded texel by texel, never filtered.
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("meshsmooth view"),
            bind_group_layouts: &[Some(&view_layout)],
            immediate_size: 0,
        });
        let composite_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("meshsmooth view composite"),
                bind_group_layouts: &[Some(&view_layout), Some(&composite_layout)],
                immediate_size: 0,
            });
        let slice_layout = slice_layout(device);
        let slice_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("meshsmooth slice"),
                bind_group_layouts: &[Some(&view_layout), Some(&slice_layout)],
                immediate_size: 0,
            });
        Self {
            device,
            module,
            view_layout,
            composite_layout,
            slice_layout,
            layout,
            composite_pipeline_layout,
            slice_pipeline_layout,
            multisample: wgpu::MultisampleState {
                count: samples,
                ..Default::default()
            },
            target_format,
        }
    }

    /// The view's depth buffer, tested with `compare`, written when `write`.
    fn depth(write: bool, compare: wgpu::CompareFunction) -> Option<wgpu::DepthStencilState> {
        Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(write),
            depth_compare: Some(compare),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        })
    }

    /// egui's colour format, blended by `blend`.
    fn target(&self, blend: Option<wgpu::BlendState>) -> [Option<wgpu::ColorTargetState>; 1] {
        [Some(wgpu::ColorTargetState {
            format: self.target_format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })]
    }

    /// Lit triangles from positions, normals and colours.
    fn surface(
        &self,
        label: &str,
        cull_mode: Option<wgpu::Face>,
        write_depth: bool,
        compare: wgpu::CompareFunction,
        blend: Option<wgpu::BlendState>,
    ) -> wgpu::RenderPipeline {
        self.triangles(
            label,
            cull_mode,
            Self::depth(write_depth, compare),
            blend,
            "fs_surface",
        )
    }

    /// Two-sided, opaque, depth written by `fragment` (a cut's outline or cap lies off the
    /// triangles' own depth).
    fn two_sided_with_depth(&self, label: &str, fragment: &str) -> wgpu::RenderPipeline {
        let depth = Self::depth(true, wgpu::CompareFunction::Less);
        self.triangles(label, None, depth, None, fragment)
    }

    fn triangles(
        &self,
        label: &str,
        cull_mode: Option<wgpu::Face>,
        depth_stencil: Option<wgpu::DepthStencilState>,
        blend: Option<wgpu::BlendState>,
        fragment: &str,
    ) -> wgpu::RenderPipeline {
        let buffers = [
            per_vertex(VEC4_STRIDE, &POSITION),
            per_vertex(VEC4_STRIDE, &NORMAL),
            per_vertex(COLOR_STRIDE, &COLOR),
        ];
        (self.device).create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&self.layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_surface"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode,
                ..Default::default()
            },
            depth_stencil,
            multisample: self.multisample,
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &self.target(blend),
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// The image's slice: a quad from the slice record, no vertex buffers.
    fn slice(&self) -> wgpu::RenderPipeline {
        (self.device).create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshsmooth slice"),
            layout: Some(&self.slice_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_slice"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Self::depth(true, wgpu::CompareFunction::Less),
            multisample: self.multisample,
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_slice"),
                compilation_options: Default::default(),
                targets: &self.target(None),
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// Edges as a line list over the surface's positions.
    fn wire(&self) -> wgpu::RenderPipeline {
        (self.device).create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshsmooth wireframe"),
            layout: Some(&self.layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_wire"),
                compilation_options: Default::default(),
                buffers: &[per_vertex(VEC4_STRIDE, &POSITION)],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::LineList,
                ..Default::default()
            },
            // Lines are pulled towards the eye in the shader (`WIRE_PULL`), so the surface
            // they lie on does not hide them while anything nearer still does.
            depth_stencil: Self::depth(false, wgpu::CompareFunction::LessEqual),
            multisample: self.multisample,
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_wire"),
                compilation_options: Default::default(),
                // The shader writes premultiplied alpha, as egui blends.
                targets: &self.target(Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)),
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// The resolved image into egui's pass, whose depth buffer (if any) it must match.
    fn composite(&self, egui_depth_format: Option<wgpu::TextureFormat>) -> wgpu::RenderPipeline {
        (self.device).create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("meshsmooth view composite"),
            layout: Some(&self.composite_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_composite"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            // egui's pass: its depth buffer (if any) is neither tested nor written.
            depth_stencil: egui_depth_format.map(|format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_composite"),
                compilation_options: Default::default(),
                // Opaque: the shader lays the view over its background.
                targets: &self.target(None),
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// Group 1 of the slice: its record (binding 1), the image as a 3D texture of grey levels
/// (filtered: trilinear between voxels) and its sampler.
fn slice_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("meshsmooth slice"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: NonZeroU64::new(std::mem::size_of::<SliceUniforms>() as u64),
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D3,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 3,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    })
}
