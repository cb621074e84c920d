//! `meshsmooth sweep FILE --filter F [--tau T] [--json | --csv] [--plot graphs.png]
//! [--voxel-size MM]`: the model quality graphs as a table, JSON, CSV or a PNG.

mod plot;

use super::backend::{parse_backend, Backend, Engine};
use super::params::FilterArgs;
use super::progress::ProgressLine;
use crate::mesh::Topology;
use crate::metrics::Original;
use crate::smooth::Filter;
use crate::suggest::{quality_graphs_on, QualityGraphs};
use std::path::{Path, PathBuf};

/// The arguments of `meshsmooth sweep`.
#[derive(clap::Args, Debug, Clone)]
pub(super) struct SweepArgs {
    /// Mesh file (.ply, .stl, .obj, .glb).
    pub file: PathBuf,
    /// The filter and the current parameters the graphs vary around.
    #[command(flatten)]
    pub params: FilterArgs,
    /// Weight of smoothness against accuracy in the score S, [0, 1].
    #[arg(long, default_value_t = 0.5)]
    pub tau: f64,
    /// Print JSON.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print CSV, one row per sample.
    #[arg(long)]
    pub csv: bool,
    /// Also draw the graphs into this PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Voxel edge length (mm) of the segmentation: draws half the voxel diagonal on the error axis.
    #[arg(long)]
    pub voxel_size: Option<f64>,
    /// cpu, or gpu (the native wgpu engine smooths and measures every sample).
    #[arg(long, default_value = "cpu", value_parser = parse_backend)]
    pub backend: Backend,
}

pub(super) fn run(args: &SweepArgs) -> Result<(), String> {
    super::check_tau(args.tau)?;
    if let Some(v) = args.voxel_size {
        if !(v > 0.0 && v.is_finite()) {
            return Err(format!("--voxel-size must be a length > 0 mm, got {v}"));
        }
    }
    let current = args.params.params()?;
    if let Some(path) = &args.plot {
        super::check_destination(path)?;
    }
    let mesh = super::load_file(&args.file)?;
    let start = std::time::Instant::now();
    let topology = Topology::build(&mesh);
    let original = Original::new(&mesh, &topology);
    let what = format!("sweeping the {} parameters", current.filter);
    let mut line = ProgressLine::on_terminal(&what, false);
    let graphs = Engine::open(args.backend)?
        .with_evaluator(&original, None, |ev| {
            quality_graphs_on(ev, &current, args.tau, &mut |p| line.update(p))
        })?
        .map_err(|e| e.to_string());
    line.finish();
    let graphs = graphs?;
    let seconds = start.elapsed().as_secs_f64();
    if let Some(path) = &args.plot {
        let title = format!(
            "Model quality graphs: {} on {}",
            filter_title(current.filter),
            file_name(&args.file)
        );
        let figure = plot::Figure {
            title: &title,
            voxel_size: args.voxel_size,
        };
        super::output::write_whole(path, |partial| {
            plot::draw(&graphs, &figure, partial).map_err(|e| format!("{}: {e}", path.display()))
        })?;
    }
    if args.json {
        outln!("{}", super::to_json(&graphs.to_json(seconds))?);
    } else if args.csv {
        out!("{}", csv(&graphs));
    } else {
        out!("{}", text(&graphs, seconds));
    }
    Ok(())
}

fn filter_title(filter: Filter) -> &'static str {
    match filter {
        Filter::Laplace => "uniform Laplace filter",
        Filter::Taubin => "Taubin λ/μ low-pass filter",
        Filter::Hc => "Laplace+HC filter (Vollmer et al.)",
        Filter::Sinc => "windowed sinc filter",
    }
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| format!("{v}"))
}

fn csv(graphs: &QualityGraphs) -> String {
    let mut s = String::from("parameter,value,curvature_ratio,mean_error,volume_change,score\n");
    for c in &graphs.curves {
        for x in &c.samples {
            s += &format!(
                "{},{},{},{},{},{}\n",
                c.param.name(),
                x.value,
                x.terms.curvature_ratio,
                x.terms.mean_error,
                opt(x.terms.volume_change),
                x.score
            );
        }
    }
    s
}

fn text(graphs: &QualityGraphs, seconds: f64) -> String {
    let mut s = format!(
        "quality graphs, {} filter, tau {} ({:.2} s)\n",
        graphs.current.filter, graphs.tau, seconds
    );
    for c in &graphs.curves {
        s += &format!(
            "\n{}: current {}, lowest S at {}\n",
            c.param.name(),
            c.current,
            c.suggestion().map_or("-".into(), |v| v.to_string())
        );
        s += "     value      K/K0    E (mm)  |dV|/V0 %         S\n";
        for (i, x) in c.samples.iter().enumerate() {
            let dv = x
                .terms
                .volume_change
                .map_or("open".to_string(), |v| format!("{:.3}", 100.0 * v));
            s += &format!(
                "{:>10} {:>9.4} {:>9.4} {:>10} {:>9.4}{}\n",
                x.value,
                x.terms.curvature_ratio,
                x.terms.mean_error,
                dv,
                x.score,
                if Some(i) == c.best {
                    "  <- lowest S"
                } else {
                    ""
                }
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(rel: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/data")
            .join(rel)
    }

    #[test]
    fn draws_the_graphs_into_a_png() {
        let dir = std::env::temp_dir().join(format!("meshsmooth-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("graphs.png");
        let args = SweepArgs {
            file: data("synthetic/synthetic_bent_tube_r3.5.ply"),
            params: FilterArgs {
                filter: "sinc".into(),
                ..Default::default()
            },
            tau: 0.5,
            json: false,
            csv: true,
            plot: Some(png.clone()),
            voxel_size: Some(1.0),
            backend: Backend::Cpu,
        };
        run(&args).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert!(bytes.len() > 20_000, "a PNG of {} bytes", bytes.len());
        let bad = SweepArgs {
            voxel_size: Some(-1.0),
            ..args.clone()
        };
        assert!(run(&bad).unwrap_err().contains("--voxel-size"));
        let bad = SweepArgs { tau: 1.5, ..args };
        assert!(run(&bad).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
