//! `meshsmooth bench FILE [--filter F] [--iterations N] [--json]`: smoothing throughput in
//! vertex-iterations per second and the cost of one measure pass, best of several runs.
//! Speed is reported, never asserted: machines are shared and noisy.

use super::params::filter;
use crate::mesh::Topology;
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
    /// Extra time the drifting reference adds to the smoothing run (one update per step).
    drift_seconds: f64,
    /// Best time of 10 Laplace iterations on the same mesh, the yardstick for the measures.
    laplace10_seconds: f64,
    backend: &'static str,
    threads: usize,
}

pub(super) fn run(
    file: &Path,
    filter_name: Option<&str>,
    iterations: Option<u32>,
    repeat: usize,
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
    let mut results = Vec::new();
    for f in filters {
        let mut params = Params::defaults(f);
        if let Some(n) = iterations {
            params.iterations = n;
        }
        params.validate().map_err(|e| e.to_string())?;
        let seconds = best_of(repeat, || {
            smooth::smooth(&mesh, &topology, &params, None, &mut NoObserver);
        });
        let mut positions = Vec::new();
        let mut reference = Vec::new();
        let with_drift = best_of(repeat, || {
            let mut drift = DriftingReference::new(&original);
            positions = smooth::smooth(&mesh, &topology, &params, None, &mut drift);
            reference = drift.into_reference();
        });
        let measure_seconds = best_of(repeat, || {
            metrics::measure(&original, &positions, &reference, 0.5);
        });
        let vertex_iterations = mesh.vertex_count() as f64 * params.iterations as f64;
        results.push(BenchResult {
            filter: f.name(),
            vertices: mesh.vertex_count(),
            iterations: params.iterations,
            seconds,
            vertex_iterations_per_second: vertex_iterations / seconds.max(1e-12),
            measure_seconds,
            drift_seconds: (with_drift - seconds).max(0.0),
            laplace10_seconds: laplace10,
            backend: "cpu",
            threads: rayon::current_num_threads(),
        });
    }
    if json {
        let text = if results.len() == 1 {
            super::to_json(&results[0])?
        } else {
            super::to_json(&results)?
        };
        println!("{text}");
    } else {
        println!(
            "{}: {} vertices, cpu backend, {} threads, best of {repeat}",
            file.display(),
            mesh.vertex_count(),
            rayon::current_num_threads()
        );
        println!("filter   iter   smooth ms   M vertex-it/s   measure ms   drift ms   measure / 10 Laplace it");
        for r in &results {
            println!(
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
    }
    Ok(())
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
