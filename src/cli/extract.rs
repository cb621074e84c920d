//! `meshsmooth extract LABELMAP... -o OUT`: one surface per structure of a segmentation, as PLY
//! files in a folder or one GLB with a named node per structure.

use super::inputs::Inputs;
use crate::case::Case;
use crate::export::{self, CaseGltfOptions, ExportFormat, ExportOptions, SceneFrame};
use crate::mesh::vertex_normals;
use crate::segmentation::{self, ExtractOptions, OpenOptions, Structure};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub(super) struct ExtractArgs {
    /// One label map (.nii, .nii.gz, .nrrd, .seg.nrrd, .mgz, .mgh, DICOM SEG .dcm), or several mask files (one structure each).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// A folder (OUT/, one PLY per structure) or a .glb (one node per structure).
    #[arg(short, long)]
    output: PathBuf,
    /// Only these label values, comma-separated (e.g. 1,3,7).
    #[arg(long, value_delimiter = ',')]
    labels: Vec<i64>,
    /// A colour table naming the labels (Slicer/FreeSurfer, FSL .txt or ITK-SNAP).
    #[arg(long)]
    colors: Option<PathBuf>,
    /// Drop voxel components smaller than this (specks); 0 keeps everything.
    #[arg(long, default_value_t = 0)]
    min_voxels: usize,
    /// The level at which a float image (probabilities) becomes a mask.
    #[arg(long)]
    level: Option<f64>,
    /// Keep the GLB in the data's RAS millimetres instead of glTF's metres with +Y up.
    #[arg(long)]
    millimetres: bool,
    /// Write the GLB's float arrays as they are, for tools that cannot decode
    /// KHR_mesh_quantization and EXT_meshopt_compression (as `case build --uncompressed`).
    #[arg(long)]
    uncompressed: bool,
    #[arg(long)]
    json: bool,
}

/// Where the surfaces go.
enum Destination {
    Folder(PathBuf),
    Glb(PathBuf),
}

pub(super) fn run(args: &ExtractArgs) -> Result<(), String> {
    let destination = destination(&args.output)?;
    let inputs = Inputs::read(&args.inputs, args.colors.as_deref())?;
    let options = OpenOptions {
        extract: ExtractOptions {
            labels: args.labels.clone(),
            min_voxels: args.min_voxels,
        },
        level: args.level,
    };
    // Only a file's name goes into the record, never its folder or header.
    let source = match args.inputs.as_slice() {
        [one] => one.file_name().map(|n| n.to_string_lossy().into_owned()),
        _ => None,
    };
    let started = Instant::now();
    let (files, table) = inputs.named()?;
    let structures = segmentation::open(&files, table, &options).map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    let written = match &destination {
        Destination::Folder(dir) => write_folder(dir, &structures)?,
        Destination::Glb(path) => {
            let options = CaseGltfOptions {
                frame: match args.millimetres {
                    true => SceneFrame::Millimetres,
                    false => SceneFrame::Gltf,
                },
                compressed: !args.uncompressed,
                ..Default::default()
            };
            write_glb(path, &structures, source.as_deref(), &options)?;
            vec![path.display().to_string(); structures.len()]
        }
    };
    if args.json {
        let list: Vec<_> = structures
            .iter()
            .zip(&written)
            .map(|(s, file)| structure_json(s, file))
            .collect();
        let out = serde_json::json!({
            "structures": list,
            "seconds": seconds,
            "peak_memory_bytes": peak_memory_bytes(),
        });
        outln!("{}", super::to_json(&out)?);
    } else {
        out!("{}", table_text(&structures));
        outln!("{} structures in {seconds:.3} s", structures.len());
    }
    Ok(())
}

/// The process's peak resident memory (Linux's VmHWM), where the system tells it.
fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn destination(output: &Path) -> Result<Destination, String> {
    let text = output.to_string_lossy();
    if text.ends_with('/') || text.ends_with('\\') || output.is_dir() {
        return Ok(Destination::Folder(output.to_path_buf()));
    }
    if ExportFormat::from_name(&text) == Some(ExportFormat::Glb) {
        super::check_destination(output)?;
        return Ok(Destination::Glb(output.to_path_buf()));
    }
    Err(format!(
        "{}: give a folder (ending in /) for one PLY per structure, or a .glb",
        output.display()
    ))
}

/// One binary PLY per structure, named after it; returns the paths written.
fn write_folder(dir: &Path, structures: &[Structure]) -> Result<Vec<String>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut taken = std::collections::HashSet::new();
    let mut written = Vec::new();
    for s in structures {
        let stem = file_stem(&s.name);
        let mut name = format!("{stem}.ply");
        let mut n = 2;
        while !taken.insert(name.clone()) {
            name = format!("{stem}_{n}.ply");
            n += 1;
        }
        let path = dir.join(&name);
        let normals = vertex_normals(&s.mesh.positions, &s.mesh.triangles);
        let options = ExportOptions {
            normals: Some(&normals),
            ..Default::default()
        };
        let bytes = export::write(&s.mesh, ExportFormat::Ply, &options)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        super::write_file(&path, &bytes)?;
        written.push(path.display().to_string());
    }
    Ok(written)
}

/// A file name from a structure's name: letters, digits, `-` and `.` kept, the rest `_`.
fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim_matches(['_', '.']).to_string();
    if stem.is_empty() {
        "structure".to_string()
    } else {
        stem
    }
}

/// The structures as an unsmoothed case: the same glTF `case build` writes.
fn write_glb(
    path: &Path,
    structures: &[Structure],
    source: Option<&str>,
    options: &CaseGltfOptions,
) -> Result<(), String> {
    let case = Case::from_label_map(structures.to_vec(), source);
    let bytes =
        export::write_case(&case, options).map_err(|e| format!("{}: {e}", path.display()))?;
    super::write_file(path, &bytes)
}

fn structure_json(s: &Structure, file: &str) -> serde_json::Value {
    serde_json::json!({
        "label": s.label,
        "layer": s.layer,
        "name": s.name,
        "color": s.color,
        "voxels": s.voxels,
        "vertices": s.mesh.vertex_count(),
        "triangles": s.mesh.triangle_count(),
        "volume": s.mesh.signed_volume(),
        "voxel_volume": s.voxel_volume(),
        "voxel_size": s.voxel_size,
        "codes": s.codes,
        "file": file,
    })
}

fn table_text(structures: &[Structure]) -> String {
    let mut s = format!(
        "{:>6}  {:<32} {:>9} {:>9} {:>9} {:>12}\n",
        "label", "name", "voxels", "vertices", "triangles", "volume mm3"
    );
    for st in structures {
        s += &format!(
            "{:>6}  {:<32} {:>9} {:>9} {:>9} {:>12.1}\n",
            st.label,
            st.name,
            st.voxels,
            st.mesh.vertex_count(),
            st.mesh.triangle_count(),
            st.mesh.signed_volume()
        );
    }
    s
}
