//! `meshsmooth smooth FILE -o OUT [filter flags] [--json]`: smooth, write, print the measures.

use super::backend::{Backend, Engine};
use super::params::FilterArgs;
use crate::export::{self, ExportFormat, ExportOptions};
use crate::mesh::{vertex_normals, Mesh, Topology};
use crate::metrics::{Metrics, Original};
use crate::smooth::Params;
use crate::suggest::{suggest_on, SearchMethod};
use std::path::Path;
use std::time::Instant;

/// How `smooth` goes about it.
pub(super) struct How {
    /// The score's weight of smoothness, for the report and `--auto`.
    pub tau: f64,
    /// `--auto`: suggest the parameters first, by this search.
    pub auto: Option<SearchMethod>,
    pub backend: Backend,
    pub json: bool,
    /// GLB: keep the data's millimetres (no conversion to metres with +Y up).
    pub millimetres: bool,
}

pub(super) fn run(file: &Path, output: &Path, args: &FilterArgs, how: &How) -> Result<(), String> {
    let (tau, json) = (how.tau, how.json);
    super::check_tau(tau)?;
    let format = super::convert::output_format(output)?;
    super::check_destination(output)?;
    let mut params = args.params()?;
    let mesh = super::load_file(file)?;
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);
    // The fixed-pipeline mode: the suggestion's parameters replace the given ones (the given
    // displacement bound is kept in every trial run and in the final one).
    let engine = Engine::open(how.backend)?;
    let suggestion = match how.auto {
        Some(method) => {
            let mut line = super::suggest::search_progress(params.filter, method);
            let s = engine
                .with_evaluator(&original, Some((params.filter, method)), |ev| {
                    suggest_on(ev, &params, tau, method, &mut |p| line.update(p))
                })?
                .map_err(|e| e.to_string());
            line.finish();
            let s = s?;
            params = s.params;
            Some(s)
        }
        None => None,
    };

    let start = Instant::now();
    let (positions, metrics) = engine.smooth_and_measure(&original, &params, tau)?;
    let seconds = start.elapsed().as_secs_f64();

    let smoothed = Mesh::new(positions, mesh.triangles.clone());
    let normals = (format == ExportFormat::Glb)
        .then(|| vertex_normals(&smoothed.positions, &smoothed.triangles));
    let options = ExportOptions {
        normals: normals.as_deref(),
        colors: None,
        extras: Some(report_json(&params, &metrics, seconds)),
        millimetres: how.millimetres,
    };
    let bytes = export::write(&smoothed, format, &options)
        .map_err(|e| format!("{}: {e}", output.display()))?;
    super::write_file(output, &bytes)?;

    if json {
        let mut report = report_json(&params, &metrics, seconds);
        report["backend"] = serde_json::json!(engine.backend().name());
        if let Some(s) = &suggestion {
            report["suggestion"] = serde_json::json!({
                "search": s.search.name(),
                "tau": tau,
                "evaluations": s.evaluations,
            });
        }
        outln!("{}", super::to_json(&report)?);
    } else {
        if let Some(s) = &suggestion {
            outln!(
                "suggested for tau {tau} by {} search ({} parameter sets): {}",
                s.search.name(),
                s.evaluations,
                params.to_json()
            );
        }
        outln!(
            "{} -> {} ({} {} iterations, {:.1} ms)",
            file.display(),
            output.display(),
            params.filter,
            params.iterations,
            seconds * 1e3
        );
        out!("{}", super::measure::text(&metrics));
    }
    Ok(())
}

fn report_json(params: &Params, metrics: &Metrics, seconds: f64) -> serde_json::Value {
    let mut report = export::smoothing_extras(params, metrics);
    report["seconds"] = serde_json::json!(seconds);
    report
}
