//! The native command-line tool: fixed pipelines (e.g. CFD preparation) on the same engine as
//! the web app. Every error goes to stderr with a non-zero exit code.

mod bench_load;
mod convert;
mod info;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
    /// Print the mesh report: counts, topology, oddities, volume.
    Info {
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Convert any supported input to .ply (binary), .stl (binary), .obj or .glb, keeping vertex order.
    Convert { input: PathBuf, output: PathBuf },
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
        Command::Convert { input, output } => convert::run(&input, &output),
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

/// Writes bytes to a file; errors name the file.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), String> {
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

pub(crate) fn to_json<T: serde::Serialize>(value: &T) -> Result<String, String> {
    serde_json::to_string_pretty(value).map_err(|e| format!("cannot encode JSON: {e}"))
}
