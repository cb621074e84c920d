//! The native command-line tool: fixed pipelines (e.g. CFD preparation) on the same engine as
//! the web app. Every error goes to stderr with a non-zero exit code.

#[macro_use]
mod stdout;

mod backend;
mod bench;
mod bench_load;
mod case;
mod case_info;
mod convert;
mod extract;
mod info;
mod inputs;
mod measure;
mod output;
mod package;
mod params;
mod progress;
mod smooth;
mod suggest;
mod sweep;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub(crate) use output::{check_destination, write_file};

#[derive(Parser)]
#[command(
    name = "meshsmooth",
    version,
    about = "Smooth anatomical surface meshes guided by quality measures"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the mesh report (counts, topology, oddities, volume), or a label map's structures.
    Info {
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// One closed surface per structure of a segmentation (NIfTI, NRRD, 3D Slicer .seg.nrrd, FreeSurfer .mgz, DICOM SEG).
    Extract(extract::ExtractArgs),
    /// Cases: every structure of a segmentation smoothed and written as one glTF.
    #[command(subcommand)]
    Case(case::CaseCommand),
    /// Convert any supported input to .ply (binary), .stl (binary), .obj or .glb, keeping vertex order.
    Convert {
        input: PathBuf,
        output: PathBuf,
        /// A .glb keeps the data's millimetres instead of glTF's metres with +Y up.
        #[arg(long)]
        millimetres: bool,
    },
    /// Smooth from the original and write the result; prints the quality measures.
    Smooth {
        file: PathBuf,
        /// Output file; the format follows the extension (.ply .stl .obj .glb).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        params: params::FilterArgs,
        /// Weight of smoothness against accuracy in the score S, [0, 1].
        #[arg(long, default_value_t = 0.5)]
        tau: f64,
        /// Suggest the filter's parameters for --tau first, then smooth with them.
        #[arg(long)]
        auto: bool,
        /// With --auto: grid or local search.
        #[arg(long, default_value = "grid", value_parser = suggest::parse_search)]
        search: crate::suggest::SearchMethod,
        /// cpu, or gpu (the native wgpu engine smooths, measures and searches).
        #[arg(long, default_value = "cpu", value_parser = backend::parse_backend)]
        backend: backend::Backend,
        /// A .glb keeps the data's millimetres instead of glTF's metres with +Y up.
        #[arg(long)]
        millimetres: bool,
        #[arg(long)]
        json: bool,
    },
    /// Compare a smoothed mesh with its original (same vertices in the same order).
    Measure {
        original: PathBuf,
        smoothed: PathBuf,
        #[arg(long, default_value_t = 0.5)]
        tau: f64,
        /// Also compute the exact point-to-mesh distance (slower) to check the local error.
        #[arg(long)]
        exact: bool,
        #[arg(long)]
        json: bool,
    },
    /// Smoothing throughput and measure cost, best of several runs (all filters by default).
    Bench {
        file: PathBuf,
        #[arg(long)]
        filter: Option<String>,
        #[arg(long)]
        iterations: Option<u32>,
        #[arg(long, default_value_t = 5)]
        repeat: usize,
        /// cpu, or gpu (the native wgpu engine; the cpu's measure columns stay for comparison).
        #[arg(long, default_value = "cpu", value_parser = backend::parse_backend)]
        backend: backend::Backend,
        #[arg(long)]
        json: bool,
    },
    /// Model quality graphs: each parameter swept, curves of K/K0, error, volume change and S.
    Sweep(sweep::SweepArgs),
    /// Suggest the parameters that minimise the score S(tau) (grid or local search).
    Suggest(suggest::SuggestArgs),
    /// Time loading a file into an indexed mesh and its topology.
    BenchLoad {
        file: PathBuf,
        /// How many times to load; the best time is reported.
        #[arg(long, default_value_t = 5)]
        repeat: usize,
        #[arg(long)]
        json: bool,
    },
}

/// Parses the command line, runs the command, and turns an error into a message and exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info { file, json } => info::run(&file, json),
        Command::Convert {
            input,
            output,
            millimetres,
        } => convert::run(&input, &output, millimetres),
        Command::Extract(args) => extract::run(&args),
        Command::Case(command) => case::run(&command),
        Command::Smooth {
            file,
            output,
            params,
            tau,
            auto,
            search,
            backend,
            millimetres,
            json,
        } => {
            let how = smooth::How {
                tau,
                auto: auto.then_some(search),
                backend,
                json,
                millimetres,
            };
            smooth::run(&file, &output, &params, &how)
        }
        Command::Measure {
            original,
            smoothed,
            tau,
            exact,
            json,
        } => measure::run(&original, &smoothed, tau, exact, json),
        Command::Bench {
            file,
            filter,
            iterations,
            repeat,
            backend,
            json,
        } => bench::run(&file, filter.as_deref(), iterations, repeat, backend, json),
        Command::Sweep(args) => sweep::run(&args),
        Command::Suggest(args) => suggest::run(&args),
        Command::BenchLoad { file, repeat, json } => bench_load::run(&file, repeat.max(1), json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("meshsmooth: error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Reads and parses a mesh file; errors name the file.
pub(crate) fn load_file(path: &Path) -> Result<crate::mesh::Mesh, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.to_string_lossy();
    crate::io::load(&bytes, &name).map_err(|e| format!("{}: {e}", path.display()))
}

/// Refuses a score weight outside [0, 1].
pub(crate) fn check_tau(tau: f64) -> Result<(), String> {
    if (0.0..=1.0).contains(&tau) {
        Ok(())
    } else {
        Err(format!("tau = {tau} is out of range: [0, 1]"))
    }
}

pub(crate) fn to_json<T: serde::Serialize>(value: &T) -> Result<String, String> {
    serde_json::to_string_pretty(value).map_err(|e| format!("cannot encode JSON: {e}"))
}
