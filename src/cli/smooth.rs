//! `meshsmooth smooth FILE -o OUT [filter flags] [--json]`: smooth, write, print the measures.

use super::params::{params_json, FilterArgs};
use crate::export::{self, ExportFormat, ExportOptions};
use crate::mesh::{vertex_normals, Mesh, Topology};
use crate::metrics::{self, DriftingReference, Metrics, Original};
use crate::smooth::{self, Params};
use std::path::Path;
use std::time::Instant;

pub(super) fn run(
    file: &Path,
    output: &Path,
    args: &FilterArgs,
    tau: f64,
    json: bool,
) -> Result<(), String> {
    super::check_tau(tau)?;
    let format = super::convert::output_format(output)?;
    let params = args.params()?;
    let mesh = super::load_file(file)?;
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);

    let start = Instant::now();
    let (positions, metrics) = smooth_and_measure(&original, &params, tau);
    let seconds = start.elapsed().as_secs_f64();

    let smoothed = Mesh::new(positions, mesh.triangles.clone());
    let normals = (format == ExportFormat::Glb)
        .then(|| vertex_normals(&smoothed.positions, &smoothed.triangles));
    let options = ExportOptions {
        normals: normals.as_deref(),
        colors: None,
        extras: Some(report_json(&params, &metrics, seconds)),
    };
    let bytes = export::write(&smoothed, format, &options)
        .map_err(|e| format!("{}: {e}", output.display()))?;
    super::write_file(output, &bytes)?;

    if json {
        println!(
            "{}",
            super::to_json(&report_json(&params, &metrics, seconds))?
        );
    } else {
        println!(
            "{} -> {} ({} {} iterations, {:.1} ms)",
            file.display(),
            output.display(),
            params.filter,
            params.iterations,
            seconds * 1e3
        );
        print!("{}", super::measure::text(&metrics));
    }
    Ok(())
}

/// Smooths from the original with the drifting reference watching, then measures.
pub(crate) fn smooth_and_measure(
    original: &Original,
    params: &Params,
    tau: f64,
) -> (Vec<[f32; 3]>, Metrics) {
    let mut drift = DriftingReference::new(original);
    let positions = smooth::smooth(
        original.mesh(),
        original.topology(),
        params,
        None,
        &mut drift,
    );
    let metrics = metrics::measure(original, &positions, drift.reference(), tau);
    (positions, metrics)
}

fn report_json(params: &Params, metrics: &Metrics, seconds: f64) -> serde_json::Value {
    serde_json::json!({
        "filter": params.filter.name(),
        "params": params_json(params),
        "seconds": seconds,
        "metrics": metrics,
    })
}
