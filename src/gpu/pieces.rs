//! A smoothing run with its normals and measures, sent to the device in pieces: a few
//! iterations, the normals, some parts of the measure pass, each piece's size counted in
//! vertex-steps ([`super::work`]). A caller that must return between submissions (the web app,
//! one frame at a time) advances it by a budget per call; the device state between calls is
//! the run's alone, so nothing else may run on the mesh until it is finished.

use super::smoother::Segment;
use super::work::{iteration_cost, measure_part_cost};
use super::{GpuError, GpuMesh, GpuSmoother, MeasureReadback, ResultReadback};
use crate::smooth::{Filter, Params};

/// What one submission step sent ([`RunPieces::advance`], the evaluator's segments).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Advance {
    /// Vertex-steps submitted.
    pub spent: u64,
    /// Whether the budget limited it (more was left to send).
    pub full: bool,
}

/// Where a run stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Iterations done (`None`: not started; the first piece starts from the original).
    Smoothing(Option<u32>),
    Normals,
    /// The next part of the measure pass.
    Measuring(usize),
    Done,
}

/// One run of `params` on a mesh uploaded with its measures, in pieces.
#[derive(Clone, Debug)]
pub struct RunPieces {
    params: Params,
    stage: Stage,
}

impl RunPieces {
    pub fn new(params: &Params) -> Self {
        Self {
            params: *params,
            stage: Stage::Smoothing(None),
        }
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Whether the run's positions and normals are in the mesh's buffers.
    pub fn smoothed(&self) -> bool {
        matches!(self.stage, Stage::Measuring(_) | Stage::Done)
    }

    /// Whether every piece has been sent: the measures' sums and per-vertex arrays are then
    /// the run's ([`super::MeasureReadback`] takes them).
    pub fn done(&self) -> bool {
        self.stage == Stage::Done
    }

    /// Once [`Self::done`]: reads back the positions with the reference vertices, and the
    /// measures with their per-vertex arrays.
    pub fn read_back(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
    ) -> Result<(ResultReadback, MeasureReadback), GpuError> {
        if !self.done() {
            return Err(GpuError::Readback("the run is not finished".into()));
        }
        let positions = ResultReadback::start(device, queue, mesh)?;
        let encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("meshsmooth measure readback"),
        });
        let measures = MeasureReadback::start(device, queue, encoder, mesh, true)?;
        Ok((positions, measures))
    }

    /// Vertex-steps of the next piece [`Self::advance`] would send on `mesh` (the smallest
    /// it sends).
    pub fn next_cost(&self, mesh: &GpuMesh) -> Result<u64, GpuError> {
        let vertices = mesh.vertex_count() as u64;
        let iteration = iteration_cost(self.params.filter, vertices);
        Ok(match self.stage {
            Stage::Smoothing(_) if self.params.filter == Filter::Sinc => {
                iteration * u64::from(self.params.iterations)
            }
            Stage::Smoothing(_) => iteration,
            Stage::Normals => vertices.max(1),
            Stage::Measuring(_) => {
                measure_part_cost(vertices, GpuSmoother::measure_part_count(mesh)?)
            }
            Stage::Done => 0,
        })
    }

    /// Submits the next pieces of the run, about `budget` vertex-steps in all and at least one
    /// piece, each its own submission. Windowed sinc's smoothing is one piece.
    pub fn advance(
        &mut self,
        smoother: &GpuSmoother,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &mut GpuMesh,
        budget: u64,
    ) -> Result<Advance, GpuError> {
        let vertices = mesh.vertex_count() as u64;
        let parts = GpuSmoother::measure_part_count(mesh)?;
        let iteration = iteration_cost(self.params.filter, vertices);
        let part = measure_part_cost(vertices, parts);
        let mut spent = 0u64;
        loop {
            let left = budget.saturating_sub(spent);
            let first = spent == 0;
            match self.stage {
                Stage::Smoothing(done) => {
                    let from = done.unwrap_or(0);
                    let total = self.params.iterations;
                    let whole = self.params.filter == Filter::Sinc;
                    let fit = (left / iteration).min(u64::from(total - from)) as u32;
                    let count = if whole {
                        total
                    } else {
                        fit.max(u32::from(first))
                    };
                    if count == 0 && done.is_some() {
                        return Ok(Advance { spent, full: true });
                    }
                    let to = (from + count).min(total);
                    let segment = Segment {
                        from,
                        to,
                        measure_at: &[],
                        into: None,
                    };
                    smoother.smooth_segment(device, queue, mesh, &self.params, &segment)?;
                    spent += u64::from(to - from) * iteration;
                    self.stage = if to == total {
                        Stage::Normals
                    } else {
                        Stage::Smoothing(Some(to))
                    };
                }
                Stage::Normals => {
                    if !first && vertices > left {
                        return Ok(Advance { spent, full: true });
                    }
                    smoother.compute_normals(device, queue, mesh)?;
                    spent += vertices.max(1);
                    self.stage = Stage::Measuring(0);
                }
                Stage::Measuring(next) => {
                    let fit = (left / part) as usize;
                    let count = fit.max(usize::from(first)).min(parts - next);
                    if count == 0 && next < parts {
                        return Ok(Advance { spent, full: true });
                    }
                    let end = next + count;
                    smoother.measure_parts(device, queue, mesh, next..end)?;
                    spent += count as u64 * part;
                    self.stage = if end == parts {
                        Stage::Done
                    } else {
                        Stage::Measuring(end)
                    };
                }
                Stage::Done => return Ok(Advance { spent, full: false }),
            }
        }
    }
}
