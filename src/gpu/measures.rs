//! The measure pass's results: each workgroup's partial sums (f32, pairwise within the
//! workgroup) come back in one small readback and are added on the host in f64, in workgroup
//! order, then reported exactly as the CPU reports its own sums
//! ([`crate::metrics::measure_vertices`]). The per-vertex arrays come back too when asked for.

use super::layout::MeasurePartial;
use super::limits::VERTEX_MEASURE_BYTES;
use super::mesh_buffers::GpuMesh;
use super::readback::Staging;
use super::GpuError;
use crate::metrics::{metrics_from_sums, Metrics, Original, Sums, VertexMeasures};

/// What a GPU measure pass reports.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuMeasures {
    /// The numbers [`crate::metrics::measure`] gives for the same positions and references (V0
    /// and K0 come from the [`Original`]), up to f32 rounding.
    pub metrics: Metrics,
    /// Per-vertex local error and `K_G`, when the readback asked for them.
    pub vertex: Option<VertexMeasures>,
    /// R/R0 ([`Original::roughness_ratio`]), up to f32 rounding.
    pub roughness_ratio: f64,
}

/// A measure pass's readback in flight (from [`super::GpuSmoother::measure`]).
pub struct MeasureReadback {
    staging: Staging,
    vertex_count: usize,
    with_vertices: bool,
}

impl MeasureReadback {
    /// Records the copies of `mesh`'s partial sums (and per-vertex measures when
    /// `with_vertices`) after the work in `encoder`, submits it and requests the mapping.
    pub(crate) fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: wgpu::CommandEncoder,
        mesh: &GpuMesh,
        with_vertices: bool,
    ) -> Result<Self, GpuError> {
        let surface = mesh.surface()?;
        let n = mesh.vertex_count();
        let partial_bytes = surface.partial_bytes();
        let vertex_bytes = if with_vertices {
            n as u64 * VERTEX_MEASURE_BYTES
        } else {
            0
        };
        let sources = [
            (&surface.partials, partial_bytes),
            (&surface.vertex_measures, vertex_bytes),
        ];
        Ok(Self {
            staging: Staging::start(
                device,
                queue,
                encoder,
                "meshsmooth measure readback",
                &sources,
            ),
            vertex_count: n,
            with_vertices,
        })
    }

    /// The measures once the mapping has completed (`None` while it is pending), reported
    /// against `original` (the mesh this one was uploaded from) with the score at `tau`.
    pub fn try_take(&self, original: &Original, tau: f64) -> Option<Result<GpuMeasures, GpuError>> {
        self.staging.try_read(|parts| {
            if original.mesh().vertex_count() != self.vertex_count {
                return Err(GpuError::TopologyMismatch(format!(
                    "measures of {} vertices reported against an original of {}",
                    self.vertex_count,
                    original.mesh().vertex_count()
                )));
            }
            let partials: Vec<MeasurePartial> = bytemuck::pod_collect_to_vec(parts[0]);
            let metrics = metrics_from_sums(original, &totals(&partials), tau);
            let roughness_ratio = roughness_ratio(original, &partials);
            let vertex = self.with_vertices.then(|| {
                let pairs: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(parts[1]);
                VertexMeasures {
                    local_error: pairs.iter().map(|p| p[0]).collect(),
                    gaussian_curvature: pairs.iter().map(|p| p[1]).collect(),
                }
            });
            Ok(GpuMeasures {
                metrics,
                vertex,
                roughness_ratio,
            })
        })
    }

    /// Blocks until the measures are back (native only: the browser cannot block).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn wait(
        self,
        device: &wgpu::Device,
        original: &Original,
        tau: f64,
    ) -> Result<GpuMeasures, GpuError> {
        super::readback::wait_for(device, || self.try_take(original, tau))
    }
}

/// R/R0 of the pass's positions: the workgroups' roughness added in f64.
pub(super) fn roughness_ratio(original: &Original, partials: &[MeasurePartial]) -> f64 {
    let r = partials.iter().map(|p| f64::from(p.roughness)).sum();
    crate::metrics::roughness_ratio(r, original.roughness())
}

/// The workgroups' partial sums added in f64.
pub(super) fn totals(partials: &[MeasurePartial]) -> Sums {
    let (mut volume6, mut curvature_sum, mut error_sum, mut error_max) = (0.0, 0.0, 0.0, 0.0f64);
    let (mut curvature_count, mut error_count) = (0usize, 0usize);
    for p in partials {
        volume6 += f64::from(p.volume6);
        curvature_sum += f64::from(p.curvature_sum);
        curvature_count += p.curvature_count as usize;
        error_sum += f64::from(p.error_sum);
        error_max = error_max.max(f64::from(p.error_max));
        error_count += p.error_count as usize;
    }
    Sums::from_totals(
        volume6,
        (curvature_sum, curvature_count),
        (error_sum, error_max, error_count),
    )
}
