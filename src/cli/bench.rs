//! `meshsmooth bench FILE [--filter F] [--iterations N] [--json]`: smoothing throughput in
//! vertex-iterations per second and the cost of one measure pass, best of several runs. With
//! `--backend gpu` the smoothing runs on the wgpu engine, and the GPU's own measure pass and
//! drifting reference are timed too (the CPU's columns stay for comparison).
//! Speed is reported, never asserted: machines are shared and noisy.

use super::backend::{Backend, GpuEngine};
use super::params::filter;
use crate::gpu;
use crate::mesh::{Mesh, Topology};
use crate::metrics::{self, DriftingReference, Original};
use crate::smooth::{self, Filter, NoObserver, Params};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

#[derive(Serialize)]
struct BenchResult {
    filter: &'static str,
    vertices: usize,
    iterations: u32,
    /// Best smoothing time, without measures (seconds).
    seconds: f64,
    vertex_iterations_per_second: f64,
    /// Best time of one measure pass (volume, curvature, local error, score).
    measure_seconds: f64,
    /// Extra time the drifting reference adds to a CPU smoothing run (one update per step).
    drift_seconds: f64,
    /// Best time of 10 Laplace iterations on the same mesh, the yardstick for the measures.
    laplace10_seconds: f64,
    backend: &'static str,
    threads: usize,
    /// The GPU adapter, for `--backend gpu`.
    #[serde(skip_serializing_if = "Option::is_none")]
    adapter: Option<String>,
    /// `--backend gpu`: best time of one measure pass on the GPU, its sums read back.
    #[serde(skip_serializing_if = "Option::is_none")]
    gpu_measure_seconds: Option<f64>,
    /// `--backend gpu`: extra time the drifting reference adds to a GPU smoothing run.
    #[serde(skip_serializing_if = "Option::is_none")]
    gpu_drift_seconds: Option<f64>,
}

pub(super) fn run(
    file: &Path,
    filter_name: Option<&str>,
    iterations: Option<u32>,
    repeat: usize,
    backend: Backend,
    json: bool,
) -> Result<(), String> {
    let filters = match filter_name {
        Some(name) => vec![filter(name)?],
        None => Filter::ALL.to_vec(),
    };
    let mesh = super::load_file(file)?;
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);
    let repeat = repeat.max(1);
    let laplace10 = best_of(repeat, || {
        let p = Params {
            iterations: 10,
            ..Params::defaults(Filter::Laplace)
        };
        smooth::smooth(&mesh, &topology, &p, None, &mut NoObserver);
    });
    let mut gpu = match backend {
        Backend::Cpu => None,
        Backend::Gpu => Some(GpuBench::new(&original)?),
    };
    let mut results = Vec::new();
    for f in filters {
        let case = BenchCase {
            mesh: &mesh,
            topology: &topology,
            original: &original,
            repeat,
        };
        results.push(bench_filter(&case, f, iterations, laplace10, gpu.as_mut())?);
    }
    if json {
        let text = if results.len() == 1 {
            super::to_json(&results[0])?
        } else {
            super::to_json(&results)?
        };
        outln!("{text}");
    } else {
        let adapter = gpu.as_ref().map(|g| g.adapter.as_str());
        print_table(file, mesh.vertex_count(), adapter, repeat, &results);
    }
    Ok(())
}

/// The mesh a benchmark runs on, and how often each run is repeated (the best counts).
struct BenchCase<'a> {
    mesh: &'a Mesh,
    topology: &'a Topology,
    original: &'a Original,
    repeat: usize,
}

/// One filter's figures: smoothing (on the GPU too, when given), the drift and the measures.
fn bench_filter(
    case: &BenchCase<'_>,
    f: Filter,
    iterations: Option<u32>,
    laplace10: f64,
    gpu: Option<&mut GpuBench>,
) -> Result<BenchResult, String> {
    let BenchCase {
        mesh,
        topology,
        original,
        repeat,
    } = *case;
    let adapter = gpu.as_ref().map(|g| g.adapter.clone());
    let mut params = Params::defaults(f);
    if let Some(n) = iterations {
        params.iterations = n;
    }
    params.validate().map_err(|e| e.to_string())?;
    let cpu_seconds = best_of(repeat, || {
        smooth::smooth(mesh, topology, &params, None, &mut NoObserver);
    });
    let (seconds, gpu_figures) = match gpu {
        None => (cpu_seconds, None),
        Some(g) => {
            let seconds = g.best_of(repeat, &params, false)?;
            let with_drift = g.best_of(repeat, &params, true)?;
            let measure = g.measure_best_of(repeat, original)?;
            (seconds, Some((measure, (with_drift - seconds).max(0.0))))
        }
    };
    let mut positions = Vec::new();
    let mut reference = Vec::new();
    let with_drift = best_of(repeat, || {
        let mut drift = DriftingReference::new(original);
        positions = smooth::smooth(mesh, topology, &params, None, &mut drift);
        reference = drift.into_reference();
    });
    let measure_seconds = best_of(repeat, || {
        metrics::measure(original, &positions, &reference, 0.5);
    });
    let vertex_iterations = mesh.vertex_count() as f64 * params.iterations as f64;
    Ok(BenchResult {
        filter: f.name(),
        vertices: mesh.vertex_count(),
        iterations: params.iterations,
        seconds,
        vertex_iterations_per_second: vertex_iterations / seconds.max(1e-12),
        measure_seconds,
        drift_seconds: (with_drift - cpu_seconds).max(0.0),
        laplace10_seconds: laplace10,
        backend: if adapter.is_some() { "gpu" } else { "cpu" },
        threads: rayon::current_num_threads(),
        adapter,
        gpu_measure_seconds: gpu_figures.map(|(m, _)| m),
        gpu_drift_seconds: gpu_figures.map(|(_, d)| d),
    })
}

/// The results as a table, the GPU's own columns after it.
fn print_table(
    file: &Path,
    vertices: usize,
    adapter: Option<&str>,
    repeat: usize,
    results: &[BenchResult],
) {
    let engine = match adapter {
        Some(adapter) => format!(
            "gpu backend on {} (measure and drift columns: the cpu's; gpu's below)",
            adapter
        ),
        None => "cpu backend".to_string(),
    };
    outln!(
        "{}: {} vertices, {engine}, {} threads, best of {repeat}",
        file.display(),
        vertices,
        rayon::current_num_threads()
    );
    outln!("filter   iter   smooth ms   M vertex-it/s   measure ms   drift ms   measure / 10 Laplace it");
    for r in results {
        outln!(
            "{:<8} {:>4} {:>11.2} {:>15.1} {:>12.2} {:>10.2} {:>25.2}",
            r.filter,
            r.iterations,
            r.seconds * 1e3,
            r.vertex_iterations_per_second / 1e6,
            r.measure_seconds * 1e3,
            r.drift_seconds * 1e3,
            r.measure_seconds / r.laplace10_seconds.max(1e-12)
        );
    }
    if adapter.is_some() {
        outln!("filter   gpu measure ms   gpu drift ms");
        for r in results {
            outln!(
                "{:<8} {:>15.2} {:>14.2}",
                r.filter,
                r.gpu_measure_seconds.unwrap_or(0.0) * 1e3,
                r.gpu_drift_seconds.unwrap_or(0.0) * 1e3
            );
        }
    }
}

fn best_of(repeat: usize, mut f: impl FnMut()) -> f64 {
    (0..repeat)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The GPU engine with the mesh (and its measures) uploaded once; each timing is submission to
/// completion.
struct GpuBench {
    engine: GpuEngine,
    mesh: gpu::GpuMesh,
    adapter: String,
}

impl GpuBench {
    fn new(original: &Original) -> Result<Self, String> {
        let engine = GpuEngine::open()?;
        let mesh = engine
            .smoother
            .upload_with_measures(&engine.context.device, original)
            .map_err(|e| e.to_string())?;
        let adapter = engine.adapter();
        Ok(Self {
            engine,
            mesh,
            adapter,
        })
    }

    /// Best smoothing time, with or without the drifting reference.
    fn best_of(&mut self, repeat: usize, params: &Params, drift: bool) -> Result<f64, String> {
        self.mesh
            .set_track_reference(drift)
            .map_err(|e| e.to_string())?;
        let mut best = f64::INFINITY;
        for _ in 0..repeat {
            let t = gpu::time_smoothing(
                &self.engine.smoother,
                &self.engine.context.device,
                &self.engine.context.queue,
                &mut self.mesh,
                params,
            )
            .map_err(|e| e.to_string())?;
            best = best.min(t);
        }
        Ok(best)
    }

    /// Best time of a measure pass over the latest run's result.
    fn measure_best_of(&self, repeat: usize, original: &Original) -> Result<f64, String> {
        let mut best = f64::INFINITY;
        for _ in 0..repeat {
            let t = gpu::time_measures(
                &self.engine.smoother,
                &self.engine.context.device,
                &self.engine.context.queue,
                &self.mesh,
                original,
            )
            .map_err(|e| e.to_string())?;
            best = best.min(t);
        }
        Ok(best)
    }
}
