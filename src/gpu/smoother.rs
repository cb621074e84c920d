//! The GPU smoothing engine: pipelines created once per device, runs recorded as one submission
//! (every iteration's dispatches in one compute pass, no readback in between).

use super::layout::{dispatch_size, StepParams, HAS_BOUND, HAS_WEIGHTS, MAX_STEP_SLOTS};
use super::mesh_buffers::{GpuMesh, Slot};
use super::pipelines::{Layouts, Pipelines};
use super::GpuError;
use crate::mesh::{Mesh, Topology};
use crate::smooth::{sinc_coefficients, Filter, Params};

/// Smooths meshes on a device handed in by the caller (the app's, the CLI's, a test's), so
/// every caller shares one engine. Matches [`crate::smooth::smooth`] (the CPU reference) up to
/// float rounding.
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

    /// Smooths `mesh` from its original positions with `params`, honouring the weights set with
    /// [`GpuMesh::set_weights`] and `params.max_displacement`, exactly as the CPU engine
    /// defines them. Submits the whole run and returns without waiting; the result is then
    /// [`GpuMesh::positions_buffer`] (read it back with [`super::read_positions`]).
    pub fn smooth(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &mut GpuMesh,
        params: &Params,
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
            Some((x, y)) if n > 0 => self.record(&mut encoder, mesh, params, (x, y)),
            // Nothing to smooth (grid == None cannot happen: upload checked the limits).
            _ => Slot::Original,
        };
        mesh.result = result;
        Ok(queue.submit([encoder.finish()]))
    }

    /// Records one run; returns where its result lies.
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        params: &Params,
        (x, y): (u32, u32),
    ) -> Slot {
        let p = &self.pipelines;
        let g = &mesh.groups;
        let stride = mesh.step_stride as u32;
        if params.filter != Filter::Sinc {
            // Laplace, Taubin and HC iterate on `a`, starting from the original.
            encoder.copy_buffer_to_buffer(&mesh.original, 0, &mesh.a, 0, mesh.original.size());
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("meshsmooth smoothing"),
            timestamp_writes: None,
        });
        let mut dispatch =
            |pipeline: &wgpu::ComputePipeline, slot: u32, group: &wgpu::BindGroup| {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &mesh.mesh_group, &[slot * stride]);
                pass.set_bind_group(1, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            };
        let iterations = params.iterations;
        match params.filter {
            Filter::Laplace | Filter::Taubin => {
                let factors = if params.filter == Filter::Laplace {
                    1
                } else {
                    2
                };
                let mut in_a = true;
                for _ in 0..iterations {
                    for slot in 0..factors {
                        let group = if in_a { &g.a_to_b } else { &g.b_to_a };
                        dispatch(&p.umbrella_step, slot, group);
                        in_a = !in_a;
                    }
                }
                if in_a {
                    Slot::A
                } else {
                    Slot::B
                }
            }
            Filter::Hc => {
                for _ in 0..iterations {
                    dispatch(&p.hc_differences, 0, &g.a_to_aux);
                    dispatch(&p.hc_correct, 0, &g.aux_to_a);
                }
                Slot::A
            }
            Filter::Sinc => {
                // T_0 in `b`, T_1 in `a`; each term overwrites T_{k-1} with T_{k+1}.
                dispatch(&p.sinc_first, 0, &g.sinc_first);
                let mut current_in_a = true;
                for slot in 1..iterations {
                    let group = if current_in_a {
                        &g.sinc_from_a
                    } else {
                        &g.sinc_from_b
                    };
                    dispatch(&p.sinc_term, slot, group);
                    current_in_a = !current_in_a;
                }
                if mesh.has_weights || bound(params).is_some() {
                    dispatch(&p.sinc_finish, 0, &g.sinc_from_a);
                }
                Slot::Aux
            }
        }
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
