//! Bind group layouts and compute pipelines, created once per device and shared by every mesh.
//!
//! Group 0 (the mesh) is the same for every kernel: the step parameters at a dynamic offset, the
//! ring CSR, the original positions and the weights. Group 1 holds the positions a kernel reads
//! around each vertex and the ones it writes; its shape depends on the kernel.
//!
//! The surface kernels (drift, normals, measures) have their own group 0: the per-mesh constants
//! (uniform), then the mesh arrays they read, then what they write. Their group 1 is the one
//! position buffer they look at.

use std::num::NonZeroU64;

use super::layout::{MeasurePart, StepParams, SurfaceParams};
use super::shaders::{Kernel, DRIFT, HC, MEASURE, NORMALS, SINC, UMBRELLA};

#[derive(Clone)]
pub(crate) struct Layouts {
    /// Group 0: step parameters (uniform, dynamic offset), offsets, neighbours, original, weights.
    pub mesh: wgpu::BindGroupLayout,
    /// Group 1 of the umbrella and HC kernels: gathered (read), written (read-write).
    pub pair: wgpu::BindGroupLayout,
    /// Group 1 of `sinc_first`: gathered (the original), previous, estimate, first_current.
    pub sinc_first: wgpu::BindGroupLayout,
    /// Group 1 of `sinc_term` and `sinc_finish`: gathered (T_k), previous, estimate.
    pub sinc_term: wgpu::BindGroupLayout,
    pub surface: SurfaceLayouts,
}

#[derive(Clone)]
pub(crate) struct Pipelines {
    pub umbrella_step: wgpu::ComputePipeline,
    pub hc_differences: wgpu::ComputePipeline,
    pub hc_correct: wgpu::ComputePipeline,
    pub sinc_first: wgpu::ComputePipeline,
    pub sinc_term: wgpu::ComputePipeline,
    pub sinc_finish: wgpu::ComputePipeline,
    pub reference_reset: wgpu::ComputePipeline,
    pub reference_drift: wgpu::ComputePipeline,
    pub vertex_normals: wgpu::ComputePipeline,
    pub measure_vertices: wgpu::ComputePipeline,
}

/// Layouts of the surface kernels.
#[derive(Clone)]
pub(crate) struct SurfaceLayouts {
    /// Group 0 of the drift: constants, original, full ring offsets and entries, stay radii
    /// (read); the reference (written).
    pub drift: wgpu::BindGroupLayout,
    /// Group 0 of the normals: constants, fan offsets and corners (read); normals (written).
    pub normals: wgpu::BindGroupLayout,
    /// Group 0 of the measures: constants, original, fan offsets and corners, boundary flags,
    /// reference (read); per-vertex measures and workgroup partials (written); the part of
    /// the pass (uniform, dynamic offset).
    pub measure: wgpu::BindGroupLayout,
    /// Group 1 of every surface kernel: the positions looked at (read).
    pub looked_at: wgpu::BindGroupLayout,
}

fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A group-1 layout: binding 0 read-only, the next ones read-write.
fn positions_layout(device: &wgpu::Device, label: &str, written: u32) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = std::iter::once(storage(0, true))
        .chain((1..=written).map(|b| storage(b, false)))
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// A surface group-0 layout: the constants (uniform) at 0, then `read` read-only and `written`
/// read-write storage buffers.
fn surface_layout(
    device: &wgpu::Device,
    label: &str,
    read: u32,
    written: u32,
) -> wgpu::BindGroupLayout {
    surface_layout_with(device, label, read, written, &[])
}

/// A uniform buffer binding of records of type `T`, at a dynamic offset or not.
fn uniform<T>(binding: u32, has_dynamic_offset: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset,
            min_binding_size: NonZeroU64::new(std::mem::size_of::<T>() as u64),
        },
        count: None,
    }
}

/// [`surface_layout`] with `extra` entries after the storage buffers.
fn surface_layout_with(
    device: &wgpu::Device,
    label: &str,
    read: u32,
    written: u32,
    extra: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = std::iter::once(uniform::<SurfaceParams>(0, false))
        .chain((1..=read).map(|b| storage(b, true)))
        .chain((read + 1..=read + written).map(|b| storage(b, false)))
        .chain(extra.iter().cloned())
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

impl SurfaceLayouts {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            drift: surface_layout(device, "meshsmooth drift", 4, 1),
            normals: surface_layout(device, "meshsmooth normals", 2, 1),
            // The part of the pass a dispatch covers, at a dynamic offset, after the arrays.
            measure: surface_layout_with(
                device,
                "meshsmooth measures",
                5,
                2,
                &[uniform::<MeasurePart>(8, true)],
            ),
            looked_at: positions_layout(device, "meshsmooth looked-at positions", 0),
        }
    }
}

impl Layouts {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let step = uniform::<StepParams>(0, true);
        let mesh = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("meshsmooth mesh"),
            entries: &[
                step,
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, true),
            ],
        });
        Self {
            mesh,
            pair: positions_layout(device, "meshsmooth gathered/written", 1),
            sinc_first: positions_layout(device, "meshsmooth sinc first term", 3),
            sinc_term: positions_layout(device, "meshsmooth sinc term", 2),
            surface: SurfaceLayouts::new(device),
        }
    }
}

impl Pipelines {
    pub(crate) fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let two_groups = |group0: &wgpu::BindGroupLayout, group1: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: &[Some(group0), Some(group1)],
                immediate_size: 0,
            })
        };
        let layout = |group1: &wgpu::BindGroupLayout| two_groups(&layouts.mesh, group1);
        let pair = layout(&layouts.pair);
        let sinc_first = layout(&layouts.sinc_first);
        let sinc_term = layout(&layouts.sinc_term);
        let surface = &layouts.surface;
        let drift_layout = two_groups(&surface.drift, &surface.looked_at);
        let normals_layout = two_groups(&surface.normals, &surface.looked_at);
        let measure_layout = two_groups(&surface.measure, &surface.looked_at);
        let umbrella = UMBRELLA.create_module(device);
        let hc = HC.create_module(device);
        let sinc = SINC.create_module(device);
        let drift = DRIFT.create_module(device);
        let normals = NORMALS.create_module(device);
        let measure = MEASURE.create_module(device);
        let pipeline = |layout: &wgpu::PipelineLayout,
                        module: &wgpu::ShaderModule,
                        kernel: Kernel,
                        entry: &str| {
            debug_assert!(kernel.entry_points.contains(&entry));
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(layout),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Self {
            umbrella_step: pipeline(&pair, &umbrella, UMBRELLA, "umbrella_step"),
            hc_differences: pipeline(&pair, &hc, HC, "hc_differences"),
            hc_correct: pipeline(&pair, &hc, HC, "hc_correct"),
            sinc_first: pipeline(&sinc_first, &sinc, SINC, "sinc_first"),
            sinc_term: pipeline(&sinc_term, &sinc, SINC, "sinc_term"),
            sinc_finish: pipeline(&sinc_term, &sinc, SINC, "sinc_finish"),
            reference_reset: pipeline(&drift_layout, &drift, DRIFT, "reference_reset"),
            reference_drift: pipeline(&drift_layout, &drift, DRIFT, "reference_drift"),
            vertex_normals: pipeline(&normals_layout, &normals, NORMALS, "vertex_normals"),
            measure_vertices: pipeline(&measure_layout, &measure, MEASURE, "measure_vertices"),
        }
    }
}
