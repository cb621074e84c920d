//! The view's own render target: a multisampled colour and depth buffer the size of the view in
//! pixels, the single-sample texture they resolve into, and the bind group that lets the
//! composite read it. Re-created only when the view's size in pixels changes.

use eframe::egui_wgpu::wgpu;

use super::pipelines::{Pipelines, DEPTH_FORMAT};

pub struct Target {
    /// The view's size in pixels this target was made for (its textures may be smaller).
    pub size: [u32; 2],
    /// The multisampled colour buffer; `None` at one sample per pixel, when the surface is
    /// drawn straight into `resolved`.
    pub multisampled: Option<wgpu::TextureView>,
    pub resolved: wgpu::TextureView,
    pub depth: wgpu::TextureView,
    /// Group 1 of the composite: `resolved`.
    pub composite_group: wgpu::BindGroup,
}

impl Target {
    /// A target of `size` pixels, each side at least 1 and at most the device's limit (the
    /// composite scales a clamped image to the view).
    pub fn new(device: &wgpu::Device, pipelines: &Pipelines, size: [u32; 2]) -> Self {
        let max = device.limits().max_texture_dimension_2d;
        let [width, height] = size.map(|side| side.clamp(1, max));
        let extent = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let samples = pipelines.samples;
        let multisampled = (samples > 1).then(|| {
            texture(
                "meshsmooth view multisampled",
                pipelines.color_format,
                samples,
                attachment,
            )
        });
        let resolved = texture(
            "meshsmooth view resolved",
            pipelines.color_format,
            1,
            attachment | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = texture("meshsmooth view depth", DEPTH_FORMAT, samples, attachment);
        let composite_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("meshsmooth view composite"),
            layout: &pipelines.composite_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&resolved),
            }],
        });
        Self {
            size,
            multisampled,
            resolved,
            depth,
            composite_group,
        }
    }
}
