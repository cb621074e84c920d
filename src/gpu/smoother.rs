//! The GPU smoothing engine: pipelines created once per device, runs recorded as one submission
//! (every iteration's dispatches in one compute pass, no readback in between, the reference
//! vertices drifting along), and the surface passes on a run's result (normals, measures).

use super::layout::{dispatch_size, StepParams, HAS_BOUND, HAS_WEIGHTS, MAX_STEP_SLOTS};
use super::measures::MeasureReadback;
use super::mesh_buffers::{GpuMesh, Slot};
use super::pipelines::{Layouts, Pipelines};
use super::GpuError;
use crate::mesh::{Mesh, Topology};
use crate::metrics::Original;
use crate::smooth::{sinc_coefficients, Filter, Params};

/// Smooths meshes on a device handed in by the caller (the app's, the CLI's, a test's), so
/// every caller shares one engine. Matches [`crate::smooth::smooth`] (the CPU reference) up to
/// float rounding; on a mesh uploaded with its measures, also the CPU's drifting reference,
/// vertex normals and measure pass. Needs WebGPU's default limits (8 storage buffers per
/// shader stage), which eframe requests on WebGPU.
#[derive(Clone)]
pub struct GpuSmoother {
    layouts: Layouts,
    pipelines: Pipelines,
}

impl GpuSmoother {
    /// Compiles the kernels and creates their pipelines on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let layouts = Layouts::new(device);
        let pipelines = Pipelines::new(device, &layouts);
        Self { layouts, pipelines }
    }

    /// Uploads `mesh` (positions, the smoothing ring of `topology`, weights 1) once, for any
    /// number of runs. Refuses, before uploading anything, a mesh over the device's limits
    /// (the error names the limit) and a topology built for another mesh.
    pub fn upload(
        &self,
        device: &wgpu::Device,
        mesh: &Mesh,
        topology: &Topology,
    ) -> Result<GpuMesh, GpuError> {
        GpuMesh::upload(device, &self.layouts, mesh, topology)
    }

    /// [`Self::upload`] of `original`'s mesh and topology, plus what the drifting reference, the
    /// normals and the measures need: the full 1-ring and the triangle fans of the original,
    /// boundary flags, reference vertices, normal and measure buffers (about 100 bytes per
    /// vertex more). Refuses, before uploading anything, a mesh over the device's limits. Runs
    /// on such a mesh drift the reference (see [`GpuMesh::set_track_reference`]).
    pub fn upload_with_measures(
        &self,
        device: &wgpu::Device,
        original: &Original,
    ) -> Result<GpuMesh, GpuError> {
        GpuMesh::upload_with_measures(device, &self.layouts, original)
    }

    /// Smooths `mesh` from its original positions with `params`, honouring the weights set with
    /// [`GpuMesh::set_weights`] and `params.max_displacement`, exactly as the CPU engine
    /// defines them. Submits the whole run and returns without waiting; the result is then
    /// [`GpuMesh::positions_buffer`] (read it back with [`super::read_positions`]).
    ///
    /// On a mesh with measures the reference vertices start as the identity and, while
    /// [`GpuMesh::tracks_reference`], drift after every step exactly when
    /// [`crate::metrics::DriftingReference`] would as the CPU run's observer: Laplace and HC once
    /// per iteration, Taubin twice, windowed sinc `iterations` times towards its result.
    pub fn smooth(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &mut GpuMesh,
        params: &Params,
    ) -> Result<wgpu::SubmissionIndex, GpuError> {
        let segment = Segment {
            from: 0,
            to: params.iterations,
            measure_at: &[],
            into: None,
        };
        self.submit(device, queue, mesh, params, &segment)
    }

    /// Part of a run, measured on the way: iterations `segment.from + 1 ..= segment.to` of
    /// `params` (whose `iterations` field is ignored), continuing from the state the previous
    /// segment left in `mesh` (`from == 0` starts from the original). After each iteration
    /// count in `segment.measure_at` the measure pass runs and its per-workgroup sums are
    /// copied into the next region of `segment.into`. Windowed sinc is one piece: `from` must
    /// be 0 and `to` its degree. Submits and returns without waiting. Needs a mesh with
    /// measures when anything is measured, and nothing run on `mesh` between segments.
    pub(crate) fn smooth_segment(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &mut GpuMesh,
        params: &Params,
        segment: &Segment<'_>,
    ) -> Result<wgpu::SubmissionIndex, GpuError> {
        if !segment.measure_at.is_empty() {
            mesh.surface()?;
        }
        let sinc_in_pieces = params.filter == Filter::Sinc && segment.from != 0;
        if sinc_in_pieces || segment.from > segment.to {
            return Err(GpuError::Device(format!(
                "no run segment from iteration {} to {} of {}",
                segment.from, segment.to, params.filter
            )));
        }
        let mut run = *params;
        run.iterations = segment.to;
        self.submit(device, queue, mesh, &run, segment)
    }

    fn submit(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &mut GpuMesh,
        params: &Params,
        segment: &Segment<'_>,
    ) -> Result<wgpu::SubmissionIndex, GpuError> {
        params.validate()?;
        let steps = step_records(mesh, params);
        if steps.len() > MAX_STEP_SLOTS {
            // Params::validate keeps sinc at 100 iterations or fewer.
            return Err(GpuError::Device(format!(
                "{} step records exceed the {MAX_STEP_SLOTS} reserved",
                steps.len()
            )));
        }
        let stride = mesh.step_stride as usize;
        let mut bytes = vec![0u8; stride * steps.len()];
        for (record, step) in bytes.chunks_mut(stride).zip(&steps) {
            record[..std::mem::size_of::<StepParams>()].copy_from_slice(bytemuck::bytes_of(step));
        }
        if !bytes.is_empty() {
            queue.write_buffer(&mesh.steps, 0, &bytes);
        }

        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth smoothing run"),
        });
        let n = mesh.vertex_count;
        let grid = dispatch_size(n, device.limits().max_compute_workgroups_per_dimension);
        let result = match grid {
            Some(grid) if n > 0 => self.record(&mut encoder, mesh, params, grid, segment),
            // Nothing to smooth (grid == None cannot happen: upload checked the limits).
            _ => Slot::Original,
        };
        mesh.result = result;
        Ok(queue.submit([encoder.finish()]))
    }

    /// Records one run (or a segment of one); returns where its result lies.
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        params: &Params,
        grid: (u32, u32),
        segment: &Segment<'_>,
    ) -> Slot {
        let fresh = segment.from == 0;
        if fresh && params.filter != Filter::Sinc {
            // Laplace, Taubin and HC iterate on `a`, starting from the original.
            encoder.copy_buffer_to_buffer(&mesh.original, 0, &mesh.a, 0, mesh.original.size());
        }
        let mut run = Recorder {
            encoder,
            pass: None,
            mesh,
            pipelines: &self.pipelines,
            grid,
            segment,
            measured: 0,
        };
        if fresh {
            run.reset_reference();
        }
        let result = match params.filter {
            Filter::Laplace | Filter::Taubin => run.umbrella(params, fresh),
            Filter::Hc => run.hc(params.iterations),
            Filter::Sinc => run.sinc(params),
        };
        run.pass = None;
        result
    }
}

/// Which iterations of a run one submission records, and where the measures taken on the way
/// go (see [`GpuSmoother::smooth_segment`]).
pub(crate) struct Segment<'a> {
    /// Iterations already run (0: start from the original).
    pub from: u32,
    /// Iterations run once this segment is done.
    pub to: u32,
    /// Iteration counts in `from + 1 ..= to` to measure after, ascending.
    pub measure_at: &'a [u32],
    /// Where the k-th measure's per-workgroup sums go: region `first + k` of the staging.
    pub into: Option<(&'a super::readback::Staging, usize)>,
}

/// Records the dispatches of one run: compute passes, broken where a measure's sums are
/// copied out.
struct Recorder<'e, 'm> {
    encoder: &'e mut wgpu::CommandEncoder,
    pass: Option<wgpu::ComputePass<'static>>,
    mesh: &'m GpuMesh,
    pipelines: &'m Pipelines,
    grid: (u32, u32),
    segment: &'m Segment<'m>,
    /// Measures taken so far in this segment.
    measured: usize,
}

impl Recorder<'_, '_> {
    /// Laplace (one umbrella step an iteration) or Taubin (two), ping-ponging between `a` and
    /// `b`; a later segment goes on from where the previous one left the positions.
    fn umbrella(&mut self, params: &Params, fresh: bool) -> Slot {
        let (p, g) = (self.pipelines, &self.mesh.groups);
        let factors = if params.filter == Filter::Laplace {
            1
        } else {
            2
        };
        let mut in_a = fresh || self.mesh.result != Slot::B;
        for iteration in self.segment.from + 1..=params.iterations {
            for slot in 0..factors {
                let group = if in_a { &g.a_to_b } else { &g.b_to_a };
                self.step(&p.umbrella_step, slot, group);
                in_a = !in_a;
                self.drift(if in_a { Slot::A } else { Slot::B });
            }
            self.after_iteration(iteration, if in_a { Slot::A } else { Slot::B });
        }
        if in_a {
            Slot::A
        } else {
            Slot::B
        }
    }

    /// Laplace+HC: the differences into `aux`, the corrected positions back into `a`.
    fn hc(&mut self, iterations: u32) -> Slot {
        let (p, g) = (self.pipelines, &self.mesh.groups);
        for iteration in self.segment.from + 1..=iterations {
            self.step(&p.hc_differences, 0, &g.a_to_aux);
            self.step(&p.hc_correct, 0, &g.aux_to_a);
            self.drift(Slot::A);
            self.after_iteration(iteration, Slot::A);
        }
        Slot::A
    }

    /// Windowed sinc: the Chebyshev terms, the result accumulated in `aux`.
    fn sinc(&mut self, params: &Params) -> Slot {
        let (p, g) = (self.pipelines, &self.mesh.groups);
        let iterations = params.iterations;
        // T_0 in `b`, T_1 in `a`; each term overwrites T_{k-1} with T_{k+1}.
        self.step(&p.sinc_first, 0, &g.sinc_first);
        let mut current_in_a = true;
        for slot in 1..iterations {
            let group = if current_in_a {
                &g.sinc_from_a
            } else {
                &g.sinc_from_b
            };
            self.step(&p.sinc_term, slot, group);
            current_in_a = !current_in_a;
        }
        if self.mesh.has_weights || bound(params).is_some() {
            self.step(&p.sinc_finish, 0, &g.sinc_from_a);
        }
        // As the CPU's observers see it: the result once per degree.
        for _ in 0..iterations {
            self.drift(Slot::Aux);
        }
        self.after_iteration(iterations, Slot::Aux);
        Slot::Aux
    }

    /// The open compute pass (a new one after a copy).
    fn pass(&mut self) -> &mut wgpu::ComputePass<'static> {
        let encoder = &mut *self.encoder;
        self.pass.get_or_insert_with(|| {
            encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("meshsmooth smoothing"),
                    timestamp_writes: None,
                })
                .forget_lifetime()
        })
    }

    fn dispatch(&mut self) {
        let (x, y) = self.grid;
        self.pass().dispatch_workgroups(x, y, 1);
    }

    /// One smoothing kernel with the step record in `slot` and the position group `group`.
    fn step(&mut self, pipeline: &wgpu::ComputePipeline, slot: u32, group: &wgpu::BindGroup) {
        let stride = self.mesh.step_stride as u32;
        let mesh_group = &self.mesh.mesh_group;
        let pass = self.pass();
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, mesh_group, &[slot * stride]);
        pass.set_bind_group(1, group, &[]);
        self.dispatch();
    }

    /// Every vertex its own reference, when the mesh has one.
    fn reset_reference(&mut self) {
        if let Some(surface) = &self.mesh.surface {
            let pipelines = self.pipelines;
            let pass = self.pass();
            pass.set_pipeline(&pipelines.reference_reset);
            pass.set_bind_group(0, &surface.drift_group, &[]);
            pass.set_bind_group(1, surface.looked_at(Slot::Original), &[]);
            self.dispatch();
        }
    }

    /// One drift step towards the positions in `towards`, when the mesh tracks its reference.
    fn drift(&mut self, towards: Slot) {
        let Some(surface) = self.mesh.surface.as_ref().filter(|s| s.track_reference) else {
            return;
        };
        let pipelines = self.pipelines;
        let pass = self.pass();
        pass.set_pipeline(&pipelines.reference_drift);
        pass.set_bind_group(0, &surface.drift_group, &[]);
        pass.set_bind_group(1, surface.looked_at(towards), &[]);
        self.dispatch();
    }

    /// After `iteration`, with the positions in `slot`: the measure pass, its sums copied out,
    /// when the segment measures there.
    fn after_iteration(&mut self, iteration: u32, slot: Slot) {
        let segment = self.segment;
        if segment.measure_at.get(self.measured) != Some(&iteration) {
            return;
        }
        let (Some(surface), Some((staging, first))) = (&self.mesh.surface, segment.into) else {
            return;
        };
        let pipelines = self.pipelines;
        let pass = self.pass();
        surface.record_measure(
            pass,
            &pipelines.measure_vertices,
            slot,
            0..surface.measure_parts.len(),
        );
        self.pass = None;
        let (buffer, offset) = staging.region(first + self.measured);
        self.encoder.copy_buffer_to_buffer(
            &surface.partials,
            0,
            buffer,
            offset,
            surface.partial_bytes(),
        );
        self.measured += 1;
    }
}

impl GpuSmoother {
    /// Computes the unit vertex normals of `mesh`'s latest result (or of the original before
    /// any run) into [`GpuMesh::normals_buffer`], as [`crate::mesh::vertex_normals`] defines
    /// them. Submits and returns without waiting. Needs a mesh with measures.
    pub fn compute_normals(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
    ) -> Result<wgpu::SubmissionIndex, GpuError> {
        let surface = mesh.surface()?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth normals"),
        });
        self.surface_pass(
            device,
            &mut encoder,
            mesh,
            &self.pipelines.vertex_normals,
            &surface.normals_group,
        );
        Ok(queue.submit([encoder.finish()]))
    }

    /// The measure pass on `mesh`'s latest result against its original, with the reference
    /// vertices of the run: per-vertex local error and `K_G` into
    /// [`GpuMesh::vertex_measures_buffer`], the volume, and per-workgroup sums that come back
    /// in the returned readback (with the per-vertex arrays too when `with_vertices`).
    /// Submits and returns without waiting; poll [`MeasureReadback::try_take`]. Equals
    /// [`crate::metrics::measure_vertices`] of the same positions and references up to f32
    /// rounding. Needs a mesh with measures.
    pub fn measure(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
        with_vertices: bool,
    ) -> Result<MeasureReadback, GpuError> {
        let surface = mesh.surface()?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth measures"),
        });
        self.record_measure_parts(&mut encoder, mesh, 0..surface.measure_parts.len())?;
        MeasureReadback::start(device, queue, encoder, mesh, with_vertices)
    }

    /// How many parts `mesh`'s measure pass has (see [`Self::measure_parts`]).
    pub(crate) fn measure_part_count(mesh: &GpuMesh) -> Result<usize, GpuError> {
        Ok(mesh.surface()?.measure_parts.len())
    }

    /// Parts `parts` of the measure pass on `mesh`'s latest result, in one submission: a
    /// measure spread over several submissions (a frame each), with nothing run on `mesh`
    /// between them. Once every part has run, [`MeasureReadback::start`] (or a copy of the
    /// sums) takes the result; [`Self::measure`] is all parts and that readback at once.
    pub(crate) fn measure_parts(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
        parts: std::ops::Range<usize>,
    ) -> Result<wgpu::SubmissionIndex, GpuError> {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth measure parts"),
        });
        self.record_measure_parts(&mut encoder, mesh, parts)?;
        Ok(queue.submit([encoder.finish()]))
    }

    fn record_measure_parts(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        parts: std::ops::Range<usize>,
    ) -> Result<(), GpuError> {
        let surface = mesh.surface()?;
        if mesh.vertex_count == 0 || parts.is_empty() {
            return Ok(());
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("meshsmooth measures"),
            timestamp_writes: None,
        });
        surface.record_measure(
            &mut pass,
            &self.pipelines.measure_vertices,
            mesh.result,
            parts,
        );
        Ok(())
    }

    /// One surface kernel over every vertex, looking at the latest result.
    fn surface_pass(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
    ) {
        let n = mesh.vertex_count;
        let max = device.limits().max_compute_workgroups_per_dimension;
        let (Some((x, y)), Some(surface)) = (dispatch_size(n, max), &mesh.surface) else {
            return;
        };
        if n == 0 {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("meshsmooth surface"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.set_bind_group(1, surface.looked_at(mesh.result), &[]);
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// The displacement bound as the CPU applies it: negative or NaN locks (0), infinite is none.
fn bound(params: &Params) -> Option<f32> {
    params
        .max_displacement
        .map(|d| d.max(0.0))
        .filter(|d| d.is_finite())
}

/// The step records of a run, in slot order: Laplace `[lambda]`, Taubin `[lambda, mu]`, HC
/// `[alpha/beta]`, windowed sinc `[c0/c1, c2, .., cN]`.
fn step_records(mesh: &GpuMesh, params: &Params) -> Vec<StepParams> {
    let d_max = bound(params);
    let flags = if mesh.has_weights { HAS_WEIGHTS } else { 0 }
        | if d_max.is_some() { HAS_BOUND } else { 0 };
    let base = StepParams {
        vertex_count: mesh.vertex_count,
        flags,
        bound: d_max.unwrap_or(0.0),
        alpha: params.alpha,
        beta: params.beta,
        centre: [mesh.centre[0], mesh.centre[1], mesh.centre[2], 0.0],
        ..StepParams::default()
    };
    let with_factor = |factor| StepParams { factor, ..base };
    match params.filter {
        Filter::Laplace => vec![with_factor(params.lambda)],
        Filter::Taubin => vec![with_factor(params.lambda), with_factor(params.mu)],
        Filter::Hc => vec![base],
        Filter::Sinc => {
            let c: Vec<f32> = sinc_coefficients(params.iterations, params.passband)
                .into_iter()
                .map(|x| x as f32)
                .collect();
            let first = StepParams {
                c0: c.first().copied().unwrap_or(1.0),
                c1: c.get(1).copied().unwrap_or(0.0),
                ..base
            };
            std::iter::once(first)
                .chain(c.iter().skip(2).map(|&ck| with_factor(ck)))
                .collect()
        }
    }
}
