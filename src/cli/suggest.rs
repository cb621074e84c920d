//! `meshsmooth suggest FILE --filter F [--tau T] [--search grid|local] [--json]`: the suggested
//! parameters for one filter at a target smoothness.

use super::backend::{parse_backend, Backend, Engine};
use super::params::filter as parse_filter;
use super::progress::ProgressLine;
use crate::mesh::Topology;
use crate::metrics::Original;
use crate::smooth::{Filter, Params};
use crate::suggest::{suggest_on, SearchMethod, Suggestion};
use std::io::Stderr;
use std::path::PathBuf;

/// Parses a search method for clap.
pub(super) fn parse_search(name: &str) -> Result<SearchMethod, String> {
    SearchMethod::from_name(name)
        .ok_or_else(|| format!("unknown search '{name}': use grid or local"))
}

/// The arguments of `meshsmooth suggest`.
#[derive(clap::Args, Debug, Clone)]
pub(super) struct SuggestArgs {
    /// Mesh file (.ply, .stl, .obj, .glb).
    pub file: PathBuf,
    /// laplace | taubin | hc | sinc
    #[arg(long, default_value = "hc", value_parser = parse_filter)]
    pub filter: Filter,
    /// Weight of smoothness against accuracy in the score S, [0, 1]: 0 suggests no smoothing.
    #[arg(long, default_value_t = 0.5)]
    pub tau: f64,
    /// grid (every grid point) or local (the paper's faster local search).
    #[arg(long, default_value = "grid", value_parser = parse_search)]
    pub search: SearchMethod,
    /// Bound on each vertex's displacement from its original position (mm), kept in every run.
    #[arg(long = "max-displacement")]
    pub max_displacement: Option<f32>,
    /// cpu, or gpu (the native wgpu engine smooths and measures every parameter set).
    #[arg(long, default_value = "cpu", value_parser = parse_backend)]
    pub backend: Backend,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

pub(super) fn run(args: &SuggestArgs) -> Result<(), String> {
    super::check_tau(args.tau)?;
    let mut base = Params::defaults(args.filter);
    base.max_displacement = args.max_displacement;
    base.validate().map_err(|e| e.to_string())?;
    let mesh = super::load_file(&args.file)?;
    let start = std::time::Instant::now();
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);
    if original.mesh().vertex_count() == 0 {
        return Err(format!("{}: the mesh has no vertices", args.file.display()));
    }
    let mut line = search_progress(args.filter, args.search);
    let s = Engine::open(args.backend)?
        .with_evaluator(&original, Some((args.filter, args.search)), |ev| {
            suggest_on(ev, &base, args.tau, args.search, &mut |p| line.update(p))
        })?
        .map_err(|e| e.to_string());
    line.finish();
    let s = s?;
    let seconds = start.elapsed().as_secs_f64();
    if args.json {
        outln!("{}", super::to_json(&s.to_json(seconds))?);
    } else {
        out!("{}", text(&s, seconds));
    }
    Ok(())
}

/// The terminal's progress line for a search.
pub(super) fn search_progress(filter: Filter, search: SearchMethod) -> ProgressLine<Stderr> {
    let what = format!("suggesting {filter} parameters ({} search)", search.name());
    ProgressLine::on_terminal(&what, search == SearchMethod::Local)
}

fn text(s: &Suggestion, seconds: f64) -> String {
    let mut out = format!(
        "{} filter, tau {}, {} search: {}\n",
        s.filter,
        s.tau,
        s.search.name(),
        s.params.describe()
    );
    if s.leaves_mesh_unchanged() {
        out += "(no smoothing: the mesh is best left as it is at this tau)\n";
    }
    out += &format!(
        "score {:.4}: K/K0 {:.4}, mean local error {:.4} mm, volume change {}\n",
        s.score,
        s.terms.curvature_ratio,
        s.terms.mean_error,
        s.terms
            .volume_change
            .map_or("undefined (open mesh)".into(), |v| format!(
                "{:.3} %",
                100.0 * v
            ))
    );
    out += &format!(
        "{} parameter sets evaluated in {:.2} s\n",
        s.evaluations, seconds
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_on_a_shared_mesh_and_refuses_bad_input() {
        let file = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/data/synthetic/synthetic_bent_tube_r3.5.ply");
        let args = SuggestArgs {
            file,
            filter: Filter::Laplace,
            tau: 0.5,
            search: SearchMethod::Local,
            max_displacement: Some(0.5),
            backend: Backend::Cpu,
            json: true,
        };
        run(&args).unwrap();
        assert_eq!(parse_search("grid"), Ok(SearchMethod::Grid));
        assert!(parse_search("anneal").is_err());
        let bad = SuggestArgs {
            max_displacement: Some(-0.5),
            ..args.clone()
        };
        assert!(run(&bad).unwrap_err().contains("max_displacement"));
        let missing = SuggestArgs {
            file: PathBuf::from("no/such/mesh.ply"),
            ..args
        };
        assert!(run(&missing).unwrap_err().contains("no/such/mesh.ply"));
    }
}
