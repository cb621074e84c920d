//! A mesh on the GPU: every buffer and bind group a smoothing run needs, created once at upload.
//!
//! Positions are `vec4<f32>` (w = 0), in buffers a renderer may bind as vertex buffers. Runs
//! ping-pong between `a` and `b`; HC keeps its differences and windowed sinc its running
//! estimate in `aux`. The original positions, the smoothing ring and the weights stay as
//! uploaded, so further kernels can bind them next to a run's result; a mesh uploaded with its
//! measures also holds [`SurfaceBuffers`] (reference vertices, normals, measures).

use wgpu::util::DeviceExt;

use super::layout::{step_stride, StepParams, MAX_STEP_SLOTS};
use super::limits::{check_mesh_fits, POSITION_BYTES};
use super::pipelines::Layouts;
use super::surface::{SlotBuffers, SurfaceBuffers};
use super::GpuError;
use crate::mesh::{bounding_box, Mesh, Topology};
use crate::metrics::Original;

/// Which buffer holds the latest run's positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Slot {
    Original,
    A,
    B,
    Aux,
}

/// Group-1 bind groups, one per role assignment a run uses.
pub(crate) struct PositionGroups {
    /// Umbrella steps `a -> b` and `b -> a`.
    pub a_to_b: wgpu::BindGroup,
    pub b_to_a: wgpu::BindGroup,
    /// HC: differences `a -> aux`, correction `aux -> a`.
    pub a_to_aux: wgpu::BindGroup,
    pub aux_to_a: wgpu::BindGroup,
    /// Windowed sinc: first term (T_0 in `b`, T_1 in `a`), then terms gathering `a` or `b`.
    pub sinc_first: wgpu::BindGroup,
    pub sinc_from_a: wgpu::BindGroup,
    pub sinc_from_b: wgpu::BindGroup,
}

/// A mesh on the GPU: uploaded by [`super::GpuSmoother::upload`] for smoothing, or by
/// [`super::GpuSmoother::upload_with_measures`] for smoothing with the drifting reference,
/// normals and measures.
pub struct GpuMesh {
    pub(crate) vertex_count: u32,
    /// Windowed sinc's centring: the original bounding box's centre, as the CPU computes it.
    pub(crate) centre: [f32; 3],
    pub(crate) has_weights: bool,
    pub(crate) result: Slot,
    pub(crate) step_stride: u64,
    pub(crate) steps: wgpu::Buffer,
    pub(crate) original: wgpu::Buffer,
    pub(crate) weights: wgpu::Buffer,
    pub(crate) a: wgpu::Buffer,
    pub(crate) b: wgpu::Buffer,
    pub(crate) aux: wgpu::Buffer,
    pub(crate) mesh_group: wgpu::BindGroup,
    pub(crate) groups: PositionGroups,
    /// Present when uploaded with its measures.
    pub(crate) surface: Option<SurfaceBuffers>,
}

/// Checks the smoothing ring against the vertex count as the CPU engine does, so no kernel
/// reads past an array.
fn checked_ring(topology: &Topology, vertex_count: usize) -> Result<(&[u32], &[u32]), GpuError> {
    let (offsets, neighbors) = topology.smoothing_ring();
    let mismatch = |what: String| Err(GpuError::TopologyMismatch(what));
    if offsets.len() != vertex_count + 1 {
        return mismatch(format!(
            "{} ring offsets for {vertex_count} vertices",
            offsets.len()
        ));
    }
    let consistent = offsets.first() == Some(&0)
        && offsets.windows(2).all(|w| w[0] <= w[1])
        && offsets.last().map(|&e| e as usize) == Some(neighbors.len());
    if !consistent {
        return mismatch("ring offsets are not a CSR index of the neighbour list".into());
    }
    if let Some(&j) = neighbors.iter().find(|&&j| j as usize >= vertex_count) {
        return mismatch(format!(
            "neighbour {j} of a mesh of {vertex_count} vertices"
        ));
    }
    Ok((offsets, neighbors))
}

/// Bytes of a storage buffer holding `data`; never empty (WebGPU refuses empty bindings).
pub(crate) fn storage_init(device: &wgpu::Device, label: &str, data: &[u8]) -> wgpu::Buffer {
    storage_init_with(device, label, data, wgpu::BufferUsages::empty())
}

/// [`storage_init`] with further usages.
fn storage_init_with(
    device: &wgpu::Device,
    label: &str,
    data: &[u8],
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let padded;
    let contents = if data.is_empty() {
        padded = [0u8; 16];
        &padded[..]
    } else {
        data
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST
            | extra,
    })
}

fn to_vec4(positions: &[[f32; 3]]) -> Vec<[f32; 4]> {
    positions.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect()
}

pub(crate) fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = (0u32..)
        .zip(buffers)
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}

/// Positions of `n` vertices the kernels write and the view draws from.
fn position_buffer(device: &wgpu::Device, label: &str, n: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (n.max(1) as u64) * POSITION_BYTES,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::VERTEX,
        mapped_at_creation: false,
    })
}

/// The mesh's bind group: one step's parameters (a dynamic offset into `steps`), then the
/// ring offsets, the ring, the original positions and the weights.
fn mesh_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    steps: &wgpu::Buffer,
    buffers: [&wgpu::Buffer; 4],
) -> wgpu::BindGroup {
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: steps,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<StepParams>() as u64),
        }),
    }];
    entries.extend(
        (1u32..)
            .zip(buffers)
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }),
    );
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("meshsmooth mesh"),
        layout,
        entries: &entries,
    })
}

impl PositionGroups {
    /// Every pairing of the position buffers the filters read and write.
    fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        original: &wgpu::Buffer,
        [a, b, aux]: [&wgpu::Buffer; 3],
    ) -> Self {
        let pair = |from, to| bind_group(device, &layouts.pair, &[from, to]);
        Self {
            a_to_b: pair(a, b),
            b_to_a: pair(b, a),
            a_to_aux: pair(a, aux),
            aux_to_a: pair(aux, a),
            sinc_first: bind_group(device, &layouts.sinc_first, &[original, b, aux, a]),
            sinc_from_a: bind_group(device, &layouts.sinc_term, &[a, b, aux]),
            sinc_from_b: bind_group(device, &layouts.sinc_term, &[b, a, aux]),
        }
    }
}

impl GpuMesh {
    pub(crate) fn upload(
        device: &wgpu::Device,
        layouts: &Layouts,
        mesh: &Mesh,
        topology: &Topology,
    ) -> Result<Self, GpuError> {
        let n = mesh.positions.len();
        let (offsets, neighbors) = checked_ring(topology, n)?;
        // Before any buffer exists: a mesh over the limits gets an error naming the limit.
        check_mesh_fits(&device.limits(), n, neighbors.len())?;

        let stride = step_stride(device.limits().min_uniform_buffer_offset_alignment);
        let steps = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("meshsmooth step parameters"),
            size: stride * MAX_STEP_SLOTS as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let original_data = to_vec4(&mesh.positions);
        let offsets = storage_init(
            device,
            "meshsmooth ring offsets",
            bytemuck::cast_slice(offsets),
        );
        let neighbors = storage_init(device, "meshsmooth ring", bytemuck::cast_slice(neighbors));
        let original = storage_init_with(
            device,
            "meshsmooth original positions",
            bytemuck::cast_slice(&original_data),
            wgpu::BufferUsages::VERTEX,
        );
        let weights = storage_init(
            device,
            "meshsmooth weights",
            bytemuck::cast_slice(&vec![1.0f32; n]),
        );
        let (a, b, aux) = (
            position_buffer(device, "meshsmooth positions a", n),
            position_buffer(device, "meshsmooth positions b", n),
            position_buffer(device, "meshsmooth positions aux", n),
        );
        // The ring's buffers live as long as the mesh group that binds them.
        let mesh_group = mesh_group(
            device,
            &layouts.mesh,
            &steps,
            [&offsets, &neighbors, &original, &weights],
        );
        let groups = PositionGroups::new(device, layouts, &original, [&a, &b, &aux]);
        let centre = bounding_box(&mesh.positions).map_or([0.0; 3], |(lo, hi)| {
            std::array::from_fn(|k| ((f64::from(lo[k]) + f64::from(hi[k])) * 0.5) as f32)
        });
        Ok(Self {
            vertex_count: n as u32,
            centre,
            has_weights: false,
            result: Slot::Original,
            step_stride: stride,
            steps,
            original,
            weights,
            a,
            b,
            aux,
            mesh_group,
            groups,
            surface: None,
        })
    }

    /// [`Self::upload`] of `original`'s mesh, plus the surface buffers the drift, the normals
    /// and the measures need (checked against the limits first, like the rest).
    pub(crate) fn upload_with_measures(
        device: &wgpu::Device,
        layouts: &Layouts,
        original: &Original,
    ) -> Result<Self, GpuError> {
        let mut mesh = Self::upload(device, layouts, original.mesh(), original.topology())?;
        let slots = SlotBuffers {
            original: &mesh.original,
            a: &mesh.a,
            b: &mesh.b,
            aux: &mesh.aux,
        };
        mesh.surface = Some(SurfaceBuffers::upload(
            device,
            &layouts.surface,
            original,
            slots,
            mesh.centre,
        )?);
        Ok(mesh)
    }

    pub fn vertex_count(&self) -> usize {
        self.vertex_count as usize
    }

    /// Sets the per-vertex weights in [0, 1] (0 locks a vertex) used by the next runs, or clears
    /// them (`None`: every vertex moves freely). Values are clamped to [0, 1], NaN counts as 0,
    /// as the CPU engine reads them.
    pub fn set_weights(
        &mut self,
        queue: &wgpu::Queue,
        weights: Option<&[f32]>,
    ) -> Result<(), GpuError> {
        let n = self.vertex_count();
        match weights {
            None => self.has_weights = false,
            Some(w) if w.len() != n => {
                return Err(GpuError::WeightCount {
                    given: w.len(),
                    vertices: n,
                })
            }
            Some(w) => {
                let clean: Vec<f32> = w
                    .iter()
                    .map(|&x| if x > 0.0 { x.min(1.0) } else { 0.0 })
                    .collect();
                if n > 0 {
                    queue.write_buffer(&self.weights, 0, bytemuck::cast_slice(&clean));
                }
                self.has_weights = true;
            }
        }
        Ok(())
    }

    /// The buffer holding the latest run's positions (`vec4<f32>` per vertex, w = 0: stride 16),
    /// or the original positions before any run. Usages STORAGE | VERTEX | COPY_SRC | COPY_DST:
    /// a renderer may bind it as a vertex buffer. Which buffer it is changes with the filter and
    /// the iteration count, so take it again after every run.
    pub fn positions_buffer(&self) -> &wgpu::Buffer {
        match self.result {
            Slot::Original => &self.original,
            Slot::A => &self.a,
            Slot::B => &self.b,
            Slot::Aux => &self.aux,
        }
    }

    /// True when uploaded with [`super::GpuSmoother::upload_with_measures`]: runs can drift the
    /// reference, and normals and measures can be computed.
    pub fn has_measures(&self) -> bool {
        self.surface.is_some()
    }

    /// Whether the next runs drift the reference vertices after every step (the default for a
    /// mesh with measures) or leave every vertex its own reference (faster; the local error
    /// then measures against each vertex's own fan). Refused without measures.
    pub fn set_track_reference(&mut self, track: bool) -> Result<(), GpuError> {
        self.surface_mut()?.track_reference = track;
        Ok(())
    }

    /// Whether runs drift the reference vertices (false without measures).
    pub fn tracks_reference(&self) -> bool {
        self.surface.as_ref().is_some_and(|s| s.track_reference)
    }

    /// Each vertex's reference vertex on the original mesh after the latest run (`u32` per
    /// vertex; the identity before any run, after a run of zero steps and when not tracking).
    /// `None` without measures.
    pub fn reference_buffer(&self) -> Option<&wgpu::Buffer> {
        self.surface.as_ref().map(|s| &s.reference)
    }

    /// Unit vertex normals from the latest [`super::GpuSmoother::compute_normals`] (`vec4<f32>`
    /// per vertex, w = 0: stride 16; usages STORAGE | VERTEX | COPY_SRC | COPY_DST). The
    /// buffer stays the same for the mesh's lifetime. `None` without measures.
    pub fn normals_buffer(&self) -> Option<&wgpu::Buffer> {
        self.surface.as_ref().map(|s| &s.normals)
    }

    /// Per-vertex measures from the latest [`super::GpuSmoother::measure`]: `vec2<f32>` per
    /// vertex, (local error in mesh units, K_G), with the zeros the CPU's
    /// [`crate::metrics::VertexMeasures`] has (unreferenced vertices; K_G on the boundary or
    /// without area). For colour-coding on the GPU, or read back with the measures. `None`
    /// without measures.
    pub fn vertex_measures_buffer(&self) -> Option<&wgpu::Buffer> {
        self.surface.as_ref().map(|s| &s.vertex_measures)
    }

    pub(crate) fn surface(&self) -> Result<&SurfaceBuffers, GpuError> {
        self.surface.as_ref().ok_or(GpuError::NoMeasures)
    }

    fn surface_mut(&mut self) -> Result<&mut SurfaceBuffers, GpuError> {
        self.surface.as_mut().ok_or(GpuError::NoMeasures)
    }
}
