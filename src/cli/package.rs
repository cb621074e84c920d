//! `meshsmooth case package INPUTS... --format scorm12|scorm2004|cmi5 -o course.zip`: a case
//! as a package a learning management system imports, with the student viewer's build.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::case::{build_case, open, BuildOptions};
use crate::case::Case;
use crate::export::lms::{self, LmsFormat, LmsPackage};
use crate::export::Container;

/// The most files and bytes a viewer's build folder may hold: a build is a page, a script, a
/// wasm module and a worker; anything far beyond is the wrong folder.
const VIEWER_FILES: usize = 64;
const VIEWER_BYTES: u64 = 256 << 20;

#[derive(clap::Args)]
pub(super) struct PackageArgs {
    /// A case glTF (.glb, .gltf), packaged as it is; or what `case build` takes (a label map,
    /// masks, surfaces), built first with the options below.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The package to write (.zip).
    #[arg(short, long)]
    output: PathBuf,
    /// scorm12 (SCORM 1.2), scorm2004 (SCORM 2004 4th edition) or cmi5.
    #[arg(long, value_parser = parse_format)]
    format: LmsFormat,
    /// The student viewer's build folder (what `trunk build` wrote beside the app).
    #[arg(long, default_value = "dist/viewer")]
    viewer: PathBuf,
    #[command(flatten)]
    build: BuildOptions,
}

pub(super) fn run(args: &PackageArgs) -> Result<(), String> {
    if !args
        .output
        .to_string_lossy()
        .to_ascii_lowercase()
        .ends_with(".zip")
    {
        return Err(format!(
            "{}: a package is written as .zip",
            args.output.display()
        ));
    }
    super::check_destination(&args.output)?;
    let viewer = read_viewer(&args.viewer)?;
    let (case, case_file, bytes) = case_of(args)?;
    let package = LmsPackage {
        format: args.format,
        case: &case,
        case_file: (case_file, &bytes),
        viewer: &viewer,
    };
    let zip =
        lms::write_package(&package).map_err(|e| format!("{}: {e}", args.output.display()))?;
    super::write_file(&args.output, &zip)?;
    if args.build.json {
        let out = serde_json::json!({
            "format": args.format.name(),
            "title": case.title,
            "structures": case.structures.len(),
            "case_bytes": bytes.len(),
            "viewer_bytes": viewer.values().map(Vec::len).sum::<usize>(),
            "bytes": zip.len(),
        });
        outln!("{}", super::to_json(&out)?);
    } else {
        outln!(
            "{} package of {} structures written to {} ({} bytes; case {} bytes)",
            args.format.name(),
            case.structures.len(),
            args.output.display(),
            zip.len(),
            bytes.len()
        );
    }
    Ok(())
}

/// The case and its glTF's name and bytes in the package: a case glTF given alone as it is,
/// anything else built as `case build` does.
fn case_of(args: &PackageArgs) -> Result<(Case, &'static str, Vec<u8>), String> {
    if let [single] = args.inputs.as_slice() {
        let name = single.to_string_lossy().to_ascii_lowercase();
        let file = if name.ends_with(".glb") {
            Some("case.glb")
        } else if name.ends_with(".gltf") {
            Some("case.gltf")
        } else {
            None
        };
        if let Some(file) = file {
            let bytes = std::fs::read(single).map_err(|e| format!("{}: {e}", single.display()))?;
            return Ok((open(&args.inputs, &args.build)?, file, bytes));
        }
    }
    let built = build_case(&args.inputs, &args.build, Container::Glb)?;
    Ok((built.case, "case.glb", built.bytes))
}

/// The viewer's build: every file under `folder`, by its path there.
fn read_viewer(folder: &Path) -> Result<BTreeMap<String, Vec<u8>>, String> {
    let shown = folder.display();
    if !folder.join("index.html").is_file() {
        return Err(format!(
            "{shown}: no viewer build here (no index.html): build it with `trunk build` (see \
             the README) or name its folder with --viewer"
        ));
    }
    if folder.join("viewer").join("index.html").is_file() {
        return Err(format!(
            "{shown}: the web app's build; the student's viewer is its viewer/ folder: name \
             that with --viewer"
        ));
    }
    let mut files = BTreeMap::new();
    let mut total = 0;
    let mut folders = vec![folder.to_path_buf()];
    while let Some(dir) = folders.pop() {
        let entries = std::fs::read_dir(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for entry in entries {
            let path = entry.map_err(|e| format!("{}: {e}", dir.display()))?.path();
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            let size = path.metadata().map(|m| m.len()).unwrap_or(0);
            total += size;
            if files.len() >= VIEWER_FILES || total > VIEWER_BYTES {
                return Err(format!(
                    "{shown}: more than a viewer's build ({VIEWER_FILES} files, {} MB): name \
                     the viewer's build folder with --viewer",
                    VIEWER_BYTES >> 20
                ));
            }
            let relative = path.strip_prefix(folder).unwrap_or(&path);
            let name = (relative.components())
                .map(|c| c.as_os_str().to_string_lossy())
                .collect::<Vec<_>>()
                .join("/");
            let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            files.insert(name, bytes);
        }
    }
    Ok(files)
}

fn parse_format(name: &str) -> Result<LmsFormat, String> {
    LmsFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = LmsFormat::ALL.iter().map(|f| f.name()).collect();
        format!("'{name}' is not a package format: {}", names.join(", "))
    })
}
