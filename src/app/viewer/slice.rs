//! The image's slice on the GPU: its grey levels as a 3D texture, sampled trilinearly, and the
//! record of where the slice lies this frame.

use eframe::egui_wgpu::wgpu;

use crate::view::{SliceTexture, SliceUniforms};

/// Slices drawn at once: the clip's, or the three standard planes.
pub const SLICES: usize = 3;

/// The image's texture and, per slice, its record and bind group.
pub struct SliceResources {
    pub slices: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
}

impl SliceResources {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        image: &SliceTexture<'_>,
    ) -> Self {
        let [width, height, depth] = image.dims.map(|d| d as u32);
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("meshsmooth image"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        queue.write_texture(
            texture.as_image_copy(),
            &image.voxels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width),
                rows_per_image: Some(height),
            },
            size,
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("meshsmooth image"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let slice = || {
            let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("meshsmooth slice"),
                size: std::mem::size_of::<SliceUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("meshsmooth slice"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: uniforms.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::Sampler(&sampler),
                    },
                ],
            });
            (uniforms, group)
        };
        Self {
            slices: (0..SLICES).map(|_| slice()).collect(),
        }
    }
}
