//! What the surface kernels (drifting reference, vertex normals, measures) add to an uploaded
//! mesh: the original mesh's full 1-ring and triangle fans, its boundary flags and the drift's
//! stay radii (as [`crate::metrics::Original`] holds them), the reference vertices, the normals,
//! the per-vertex measures and the per-workgroup sums, with their bind groups. Created once, by
//! [`super::GpuSmoother::upload_with_measures`].

use wgpu::util::DeviceExt;

use super::layout::{
    dispatch_size, measure_parts, record_stride, MeasurePart, MeasurePartial, SurfaceParams,
};
use super::limits::{check_surface_fits, POSITION_BYTES, VERTEX_MEASURE_BYTES};
use super::mesh_buffers::{bind_group, storage_init, Slot};
use super::pipelines::SurfaceLayouts;
use super::GpuError;
use crate::metrics::Original;

/// The surface buffers of one mesh.
pub(crate) struct SurfaceBuffers {
    /// Each vertex's reference vertex on the original mesh (u32), the identity at upload.
    pub reference: wgpu::Buffer,
    /// Unit vertex normals of the latest [`super::GpuSmoother::compute_normals`] (`vec4<f32>`).
    pub normals: wgpu::Buffer,
    /// Per vertex (local error, K_G) of the latest measure pass (`vec2<f32>`).
    pub vertex_measures: wgpu::Buffer,
    /// One [`MeasurePartial`] per workgroup of the latest measure pass.
    pub partials: wgpu::Buffer,
    pub partial_count: u32,
    /// The parts of the measure pass (see [`MeasurePart`]), and the distance between their
    /// records: part `k` is bound at dynamic offset `k * measure_part_stride`.
    pub measure_parts: Vec<MeasurePart>,
    pub measure_part_stride: u32,
    pub drift_group: wgpu::BindGroup,
    pub normals_group: wgpu::BindGroup,
    pub measure_group: wgpu::BindGroup,
    /// Group 1 of the surface kernels for each slot: original, a, b, aux.
    looked_at: [wgpu::BindGroup; 4],
    /// Whether smoothing runs drift the reference (else it stays the identity).
    pub track_reference: bool,
}

/// A storage buffer the kernels write and the host may copy out of (and a renderer may bind).
fn written(device: &wgpu::Device, label: &str, bytes: u64, vertex: bool) -> wgpu::Buffer {
    let extra = if vertex {
        wgpu::BufferUsages::VERTEX
    } else {
        wgpu::BufferUsages::empty()
    };
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST
            | extra,
        mapped_at_creation: false,
    })
}

/// The position buffers of a mesh, in [`Slot`] order.
pub(crate) struct SlotBuffers<'a> {
    pub original: &'a wgpu::Buffer,
    pub a: &'a wgpu::Buffer,
    pub b: &'a wgpu::Buffer,
    pub aux: &'a wgpu::Buffer,
}

/// A mesh's neighbourhoods as the kernels read them: the 1-rings (CSR), the triangle fans
/// (CSR), the boundary flags and each vertex's stay radius.
struct Rings {
    ring_offsets: wgpu::Buffer,
    ring: wgpu::Buffer,
    fan_offsets: wgpu::Buffer,
    fan_corners: wgpu::Buffer,
    boundary: wgpu::Buffer,
    stay: wgpu::Buffer,
}

impl Rings {
    fn upload(device: &wgpu::Device, original: &Original, fans: &[[u32; 2]]) -> Self {
        let topology = original.topology();
        let cast = bytemuck::cast_slice::<u32, u8>;
        let boundary: Vec<u32> = topology.is_boundary.iter().map(|&b| b as u32).collect();
        Self {
            ring_offsets: storage_init(
                device,
                "meshsmooth 1-ring offsets",
                cast(&topology.neighbor_offsets),
            ),
            ring: storage_init(device, "meshsmooth 1-ring", cast(&topology.neighbors)),
            fan_offsets: storage_init(
                device,
                "meshsmooth fan offsets",
                cast(&topology.triangle_offsets),
            ),
            fan_corners: storage_init(device, "meshsmooth fan corners", bytemuck::cast_slice(fans)),
            boundary: storage_init(device, "meshsmooth boundary flags", cast(&boundary)),
            stay: storage_init(
                device,
                "meshsmooth stay radii",
                bytemuck::cast_slice(original.stay_radius2()),
            ),
        }
    }
}

/// The measure pass's parts and partial count for `original` on a device with `limits`, after
/// refusing a mesh that exceeds them.
fn measure_plan(
    limits: &wgpu::Limits,
    original: &Original,
) -> Result<(Vec<MeasurePart>, u32), GpuError> {
    let n = original.mesh().vertex_count();
    dispatch_size(n as u32, limits.max_compute_workgroups_per_dimension)
        .ok_or_else(|| GpuError::Device("no workgroup grid covers the mesh".into()))?;
    // The measure pass runs as 1-D parts: one partial per workgroup that holds vertices.
    let parts = measure_parts(n as u32, limits.max_compute_workgroups_per_dimension);
    let partial_count = (n as u32).div_ceil(super::layout::WORKGROUP_SIZE);
    check_surface_fits(
        limits,
        n,
        original.topology().neighbors.len(),
        original.all_fan_corners().len(),
        partial_count as usize,
    )?;
    Ok((parts, partial_count))
}

/// The buffers the kernels write for `n` vertices: the drifting reference (the identity until
/// a run drifts it), the normals, the per-vertex measures and the measure pass's partials.
fn working_buffers(device: &wgpu::Device, n: usize, partial_count: u32) -> [wgpu::Buffer; 4] {
    let n64 = n as u64;
    [
        storage_init(
            device,
            "meshsmooth reference vertices",
            bytemuck::cast_slice::<u32, u8>(&crate::metrics::identity(n)),
        ),
        written(device, "meshsmooth normals", n64 * POSITION_BYTES, true),
        written(
            device,
            "meshsmooth vertex measures",
            n64 * VERTEX_MEASURE_BYTES,
            false,
        ),
        written(
            device,
            "meshsmooth measure partials",
            u64::from(partial_count) * std::mem::size_of::<MeasurePartial>() as u64,
            false,
        ),
    ]
}

/// The measure pass's part records, one per `stride` bytes (a dynamic uniform offset each).
fn measure_part_records(device: &wgpu::Device, parts: &[MeasurePart], stride: u64) -> wgpu::Buffer {
    let mut records = vec![0u8; (stride as usize * parts.len()).max(stride as usize)];
    for (record, part) in records.chunks_mut(stride as usize).zip(parts) {
        record[..std::mem::size_of::<MeasurePart>()].copy_from_slice(bytemuck::bytes_of(part));
    }
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("meshsmooth measure parts"),
        contents: &records,
        usage: wgpu::BufferUsages::UNIFORM,
    })
}

/// The measure pass's bind group: `buffers` at bindings 0 to 7, one part record at 8.
fn measure_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: [&wgpu::Buffer; 8],
    part_records: &wgpu::Buffer,
) -> wgpu::BindGroup {
    let mut entries: Vec<_> = (0u32..)
        .zip(buffers)
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    entries.push(wgpu::BindGroupEntry {
        binding: 8,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: part_records,
            offset: 0,
            size: std::num::NonZeroU64::new(std::mem::size_of::<MeasurePart>() as u64),
        }),
    });
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("meshsmooth measures"),
        layout,
        entries: &entries,
    })
}

impl SurfaceBuffers {
    /// Uploads `original`'s surface data for a mesh whose position buffers are `slots`, with
    /// `centre` as the volume's centre. Refuses, before uploading anything, what exceeds the
    /// device's limits.
    pub(crate) fn upload(
        device: &wgpu::Device,
        layouts: &SurfaceLayouts,
        original: &Original,
        slots: SlotBuffers<'_>,
        centre: [f32; 3],
    ) -> Result<Self, GpuError> {
        let n = original.mesh().vertex_count();
        let limits = device.limits();
        let (parts, partial_count) = measure_plan(&limits, original)?;

        let params = SurfaceParams {
            vertex_count: n as u32,
            centre: [centre[0], centre[1], centre[2], 0.0],
            ..SurfaceParams::default()
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("meshsmooth surface constants"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let rings = Rings::upload(device, original, original.all_fan_corners());
        let [reference, normals, vertex_measures, partials] =
            working_buffers(device, n, partial_count);

        let stride = record_stride::<MeasurePart>(limits.min_uniform_buffer_offset_alignment);
        let part_records = measure_part_records(device, &parts, stride);

        let group = |layout, buffers: &[&wgpu::Buffer]| {
            let mut all = vec![&params];
            all.extend_from_slice(buffers);
            bind_group(device, layout, &all)
        };
        let Rings {
            ring_offsets,
            ring,
            fan_offsets,
            fan_corners,
            boundary,
            stay,
        } = &rings;
        let drift_group = group(
            &layouts.drift,
            &[slots.original, ring_offsets, ring, stay, &reference],
        );
        let normals_group = group(&layouts.normals, &[fan_offsets, fan_corners, &normals]);
        let measure_buffers = [
            &params,
            slots.original,
            fan_offsets,
            fan_corners,
            boundary,
            &reference,
            &vertex_measures,
            &partials,
        ];
        let measure_group = measure_group(device, &layouts.measure, measure_buffers, &part_records);
        let looked_at = [slots.original, slots.a, slots.b, slots.aux]
            .map(|b| bind_group(device, &layouts.looked_at, &[b]));
        Ok(Self {
            reference,
            normals,
            vertex_measures,
            partials,
            partial_count,
            measure_parts: parts,
            measure_part_stride: stride as u32,
            drift_group,
            normals_group,
            measure_group,
            looked_at,
            track_reference: true,
        })
    }

    /// Records parts `parts` of the measure pass over the positions in `slot` into `pass`.
    pub(crate) fn record_measure(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        slot: Slot,
        parts: std::ops::Range<usize>,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, self.looked_at(slot), &[]);
        for (k, part) in self
            .measure_parts
            .iter()
            .enumerate()
            .take(parts.end)
            .skip(parts.start)
        {
            pass.set_bind_group(
                0,
                &self.measure_group,
                &[k as u32 * self.measure_part_stride],
            );
            pass.dispatch_workgroups(part.group_count, 1, 1);
        }
    }

    /// Bytes of the measure pass's sums (one [`MeasurePartial`] per workgroup).
    pub(crate) fn partial_bytes(&self) -> u64 {
        u64::from(self.partial_count) * std::mem::size_of::<MeasurePartial>() as u64
    }

    /// Group 1 of a surface kernel looking at the positions in `slot`.
    pub(crate) fn looked_at(&self, slot: Slot) -> &wgpu::BindGroup {
        let k = match slot {
            Slot::Original => 0,
            Slot::A => 1,
            Slot::B => 2,
            Slot::Aux => 3,
        };
        &self.looked_at[k]
    }
}
