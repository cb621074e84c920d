//! `meshsmooth case build INPUTS... -o case.glb`: the fixed pipeline for a whole segmentation
//! (every structure suggested and smoothed, one case glTF), `meshsmooth case info`, and the
//! build `case package` runs first (see `package`).

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use super::case_info::{case_json, image_line, lesson_line, table};
use super::inputs::Inputs;
use super::params::filter as parse_filter;
use super::progress::ProgressLine;
use crate::case::relations::{PairRelation, RelationChanges};
use crate::case::{
    self, Case, SuggestAllOptions, SuggestAllProgress, SuggestAllSearch, WindowPreset,
    DEFAULT_MAX_VOLUME_CHANGE,
};
use crate::export::{self, CaseGltfOptions, Container, SceneFrame, Simplification};
use crate::segmentation::{ExtractOptions, OpenOptions};
use crate::smooth::Filter;
use crate::suggest::{Progress, Suggestion};

#[derive(clap::Subcommand)]
pub(super) enum CaseCommand {
    /// Suggest and smooth every structure, then write one case glTF (.glb, or .gltf with the
    /// buffer embedded).
    Build(Box<BuildArgs>),
    /// Write a package a learning management system imports (SCORM 1.2, SCORM 2004 or cmi5):
    /// the case, the student viewer and the page that reports to the LMS.
    Package(Box<super::package::PackageArgs>),
    /// Print a case glTF's structures, parameters and measures.
    Info {
        file: PathBuf,
        #[arg(long)]
        json: bool,
    },
}

#[derive(clap::Args)]
pub(super) struct BuildArgs {
    /// A label map (.nii, .nii.gz, .nrrd, .seg.nrrd, .mgz, .mgh, DICOM SEG .dcm) or several masks, surface meshes (.ply,
    /// .stl, .obj) and case glTFs (.glb, .gltf), in any mix.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The case glTF to write: .glb, or .gltf (one file, buffer embedded).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    options: BuildOptions,
}

/// How `case build` (and `case package`, which builds first) makes the case.
#[derive(clap::Args)]
pub(super) struct BuildOptions {
    /// Target smoothness: the weight of smoothness against accuracy in the score, [0, 1].
    #[arg(long, default_value_t = 0.5)]
    tau: f64,
    /// One filter for every structure (laplace | taubin | hc | sinc); else each keeps its own
    /// (hc for new structures).
    #[arg(long, value_parser = parse_filter)]
    filter: Option<Filter>,
    /// grid (every grid point), local (the paper's, from the corners) or learned (the local
    /// search from where the searches of smaller structures ended).
    #[arg(long, default_value_t = SuggestAllSearch::default(), value_parser = parse_case_search)]
    search: SuggestAllSearch,
    /// The most volume a structure's suggestion may take off or add, in percent of its
    /// original volume, or `none`: thin structures (vessels) lose volume faster than the
    /// score weighs it.
    #[arg(long, default_value_t = Percent(Some(100.0 * DEFAULT_MAX_VOLUME_CHANGE)), value_parser = parse_percent)]
    max_volume_change: Percent,
    /// Lift the displacement bound label-map structures get (half their voxel diagonal).
    #[arg(long)]
    no_bound: bool,
    #[arg(long)]
    title: Option<String>,
    #[arg(long)]
    description: Option<String>,
    /// A colour table naming the label map's labels.
    #[arg(long)]
    colors: Option<PathBuf>,
    /// Only these label values of the label map, comma-separated.
    #[arg(long, value_delimiter = ',')]
    labels: Vec<i64>,
    /// Drop voxel components smaller than this (specks).
    #[arg(long, default_value_t = 0)]
    min_voxels: usize,
    /// The level at which a float image becomes a mask.
    #[arg(long)]
    level: Option<f64>,
    /// The image the segmentation was drawn on (CT or MRI: NIfTI, NRRD as 3D Slicer saves a
    /// volume, FreeSurfer's MGH/MGZ, or a folder of a DICOM series, one slice a file), carried
    /// in the case for the viewer to show under the surfaces; it must lie on the
    /// segmentation's voxel grid.
    #[arg(long, value_name = "IMAGE")]
    image: Option<PathBuf>,
    /// The window the image's grey levels are made with: ct-soft-tissue, ct-bone, ct-lung,
    /// ct-brain or mri-auto.
    #[arg(long, default_value = "ct-soft-tissue", value_parser = parse_window, requires = "image")]
    window: WindowPreset,
    /// The most voxels the image keeps (one byte each in the case): a larger one is reduced
    /// by the smallest whole factor that fits.
    #[arg(long, default_value_t = case::DEFAULT_IMAGE_VOXELS, requires = "image")]
    image_voxels: usize,
    /// The lesson the case carries (JSON: tour steps, labels on the structures, a quiz), its
    /// structures named as the case names them.
    #[arg(long, value_name = "LESSON")]
    lesson: Option<PathBuf>,
    /// The structures' names in other languages (JSON: each structure's name, as the case names
    /// it, to its names by language tag: {"Liver": {"de": "Leber", "fr": "Foie"}}); the viewer
    /// shows the student's language.
    #[arg(long, value_name = "NAMES")]
    names: Option<PathBuf>,
    /// Leave out the original surface (the morph target a viewer slides to, and what a
    /// reopened case smooths again from).
    #[arg(long)]
    no_original: bool,
    /// Add each vertex's local error (mm) as the attribute _LOCAL_ERROR.
    #[arg(long)]
    local_error: bool,
    /// Unlit materials (KHR_materials_unlit): colours show exactly as chosen.
    #[arg(long)]
    unlit: bool,
    /// Keep the data's RAS millimetres instead of glTF's metres with +Y up.
    #[arg(long)]
    millimetres: bool,
    /// Write float arrays as they are, for tools that cannot decode KHR_mesh_quantization and
    /// EXT_meshopt_compression (by default the arrays are quantized and compressed).
    #[arg(long)]
    uncompressed: bool,
    /// Simplify each structure's surface within this many of its voxel diagonals of the
    /// smoothed one (the record states the deviation measured), for a smaller download.
    #[arg(
        long,
        value_name = "VOXEL_DIAGONALS",
        conflicts_with = "triangle_budget"
    )]
    simplify: Option<f64>,
    /// Simplify the surfaces to about this many triangles in the whole case, shared in
    /// proportion to each structure's (the record states each deviation measured).
    #[arg(long, value_name = "TRIANGLES")]
    triangle_budget: Option<usize>,
    #[arg(long)]
    pub(super) json: bool,
}

pub(super) fn run(command: &CaseCommand) -> Result<(), String> {
    match command {
        CaseCommand::Build(args) => build(args),
        CaseCommand::Package(args) => super::package::run(args),
        CaseCommand::Info { file, json } => super::case_info::info(file, *json),
    }
}

fn build(args: &BuildArgs) -> Result<(), String> {
    let container = container(&args.output)?;
    super::check_destination(&args.output)?;
    let built = build_case(&args.inputs, &args.options, container)?;
    super::write_file(&args.output, &built.bytes)?;
    let case = &built.case;
    if args.options.json {
        let mut out = case_json(case);
        out["checks"] = case::checks_json(case, &built.after, &built.changes);
        out["evaluations"] = serde_json::json!(built.evaluations);
        out["open_seconds"] = serde_json::json!(built.seconds.open);
        out["suggest_seconds"] = serde_json::json!(built.seconds.suggest);
        out["checks_seconds"] = serde_json::json!(built.seconds.checks);
        out["export_seconds"] = serde_json::json!(built.seconds.export);
        out["seconds"] = serde_json::json!(built.seconds.all);
        out["bytes"] = serde_json::json!(built.bytes.len());
        outln!("{}", super::to_json(&out)?);
    } else {
        out!("{}", table(case));
        out!("{}", image_line(case));
        out!("{}", lesson_line(case));
        out!(
            "{}",
            case::checks_text(case, &built.before, &built.after, &built.changes)
        );
        outln!(
            "{} structures, {} parameter sets, suggested and smoothed in {:.2} s; \
             {} written ({} bytes)",
            case.structures.len(),
            built.evaluations,
            built.seconds.suggest,
            args.output.display(),
            built.bytes.len()
        );
    }
    Ok(())
}

/// A case built from files: the structures opened, authored, suggested, smoothed and checked,
/// and its glTF.
pub(super) struct Built {
    pub case: Case,
    pub bytes: Vec<u8>,
    pub evaluations: usize,
    before: Vec<PairRelation>,
    after: Vec<PairRelation>,
    changes: RelationChanges,
    seconds: Seconds,
}

/// Where a build's time went.
struct Seconds {
    open: f64,
    suggest: f64,
    checks: f64,
    export: f64,
    all: f64,
}

/// Opens `inputs` as a case, adds what the options author, suggests and smooths every
/// structure, checks them, and writes the case glTF in `container`.
pub(super) fn build_case(
    inputs: &[PathBuf],
    options: &BuildOptions,
    container: Container,
) -> Result<Built, String> {
    super::check_tau(options.tau)?;
    if options
        .simplify
        .is_some_and(|v| !(v.is_finite() && v > 0.0))
    {
        return Err("--simplify takes a distance in voxel diagonals above 0".into());
    }
    if options.triangle_budget == Some(0) {
        return Err("--triangle-budget takes a count of triangles above 0".into());
    }
    let started = Instant::now();
    let mut case = open(inputs, options)?;
    author(&mut case, options)?;
    let opened = started.elapsed().as_secs_f64();
    let checks_started = Instant::now();
    // The trees of the checks as opened, refitted by the checks as shown.
    let mut trees = case::relations::TreeShapes::default();
    let before = case::check_refitting(&case, false, &mut trees);
    let mut checks_seconds = checks_started.elapsed().as_secs_f64();

    let suggest_options = SuggestAllOptions {
        tau: options.tau,
        filter: options.filter,
        search: options.search,
        max_volume_change: options.max_volume_change.0.map(|p| p / 100.0),
    };
    let suggest_started = Instant::now();
    let suggestions = suggest_all_shown(&mut case, &suggest_options)?;
    let suggest_seconds = suggest_started.elapsed().as_secs_f64();
    let checks_started = Instant::now();
    let after = case::check_refitting(&case, true, &mut trees);
    drop(trees);
    checks_seconds += checks_started.elapsed().as_secs_f64();
    let changes = case::relations::changes(&before, &after);

    let export_started = Instant::now();
    let bytes =
        export::write_case(&case, &gltf_options(options, container)).map_err(|e| e.to_string())?;
    Ok(Built {
        evaluations: suggestions.iter().flatten().map(|s| s.evaluations).sum(),
        case,
        bytes,
        before,
        after,
        changes,
        seconds: Seconds {
            open: opened,
            suggest: suggest_seconds,
            checks: checks_seconds,
            export: export_started.elapsed().as_secs_f64(),
            all: started.elapsed().as_secs_f64(),
        },
    })
}

/// Adds the image at `path`: one file, or a folder of a DICOM series' slices (in subfolders,
/// as a DICOM export keeps them).
fn add_image(case: &mut Case, path: &Path, args: &BuildOptions) -> Result<(), String> {
    let name = path.display().to_string();
    let added = if path.is_dir() {
        let files = super::inputs::read_folder(path)?;
        // Each slice by its path in the folder: the error's prefix names the folder.
        let names: Vec<String> = (files.iter())
            .map(|(n, _)| Path::new(n).strip_prefix(path).map_or(n.clone(), path_text))
            .collect();
        let slices: Vec<(&str, &[u8])> = (names.iter().zip(&files))
            .map(|(n, (_, b))| (n.as_str(), b.as_slice()))
            .collect();
        let folder = name.trim_end_matches(['/', '\\']);
        case.add_image(&slices, folder, args.window, args.image_voxels)
    } else {
        let bytes = std::fs::read(path).map_err(|e| format!("{name}: {e}"))?;
        case.add_image(&[(&name, &bytes)], &name, args.window, args.image_voxels)
    };
    added.map_err(|e| format!("{name}: {e}"))
}

fn path_text(path: &Path) -> String {
    path.display().to_string()
}

/// What the author adds to the structures opened: the image, title, description, lesson,
/// names in other languages, and no bound where asked.
fn author(case: &mut Case, args: &BuildOptions) -> Result<(), String> {
    let read = |path: &Path| {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| format!("{name}: {e}"))?;
        Ok::<_, String>((bytes, name))
    };
    if let Some(path) = &args.image {
        add_image(case, path, args)?;
    }
    if let Some(t) = &args.title {
        case.title = t.clone();
    }
    if let Some(d) = &args.description {
        case.description = d.clone();
    }
    if let Some((bytes, name)) = args.lesson.as_deref().map(read).transpose()? {
        // Checked here, before the searches, though the export checks it again.
        let lesson = case::Lesson::from_json(&bytes).map_err(|e| format!("{name}: {e}"))?;
        lesson.check(case).map_err(|e| format!("{name}: {e}"))?;
        case.lesson = lesson;
    }
    if let Some((bytes, name)) = args.names.as_deref().map(read).transpose()? {
        case::names::apply_table(case, &bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    if args.no_bound {
        for s in &mut case.structures {
            s.params.max_displacement = None;
        }
    }
    Ok(())
}

/// [`case::suggest_all`] with a progress line on the terminal.
fn suggest_all_shown(
    case: &mut Case,
    options: &SuggestAllOptions,
) -> Result<Vec<Option<Suggestion>>, String> {
    let what = format!(
        "suggesting and smoothing {} structures",
        case.structures.len()
    );
    let line = Mutex::new(ProgressLine::on_terminal(&what, false));
    let report = |p: SuggestAllProgress| {
        if let Ok(mut line) = line.lock() {
            line.update(Progress {
                done: p.structures_done,
                total: p.structures,
            });
        }
        true
    };
    let suggestions = case::suggest_all(case, options, &report);
    if let Ok(line) = line.into_inner() {
        line.finish();
    }
    suggestions.map_err(|e| e.to_string())
}

/// How `case build` writes the glTF.
fn gltf_options(args: &BuildOptions, container: Container) -> CaseGltfOptions {
    CaseGltfOptions {
        frame: if args.millimetres {
            SceneFrame::Millimetres
        } else {
            SceneFrame::Gltf
        },
        container,
        original_as_morph_target: !args.no_original,
        local_error: args.local_error,
        unlit: args.unlit,
        compressed: !args.uncompressed,
        simplify: match (args.simplify, args.triangle_budget) {
            (Some(v), _) => Some(Simplification::VoxelDiagonals(v)),
            (None, Some(n)) => Some(Simplification::TriangleBudget(n)),
            (None, None) => None,
        },
    }
}

fn parse_window(name: &str) -> Result<WindowPreset, String> {
    WindowPreset::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = WindowPreset::ALL.iter().map(|p| p.name()).collect();
        format!("'{name}' is not a window: {}", names.join(", "))
    })
}

/// A percentage, or none.
#[derive(Clone, Copy, Debug)]
struct Percent(Option<f64>);

impl std::fmt::Display for Percent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(p) => write!(f, "{p}"),
            None => f.write_str("none"),
        }
    }
}

fn parse_case_search(name: &str) -> Result<SuggestAllSearch, String> {
    SuggestAllSearch::from_name(name)
        .ok_or_else(|| format!("unknown search '{name}': use learned, local or grid"))
}

fn parse_percent(text: &str) -> Result<Percent, String> {
    if text == "none" {
        return Ok(Percent(None));
    }
    match text.parse::<f64>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(Percent(Some(v))),
        _ => Err(format!("'{text}' is not a percentage >= 0 or 'none'")),
    }
}

fn container(output: &Path) -> Result<Container, String> {
    let name = output.to_string_lossy().to_ascii_lowercase();
    if name.ends_with(".glb") {
        Ok(Container::Glb)
    } else if name.ends_with(".gltf") {
        Ok(Container::Gltf)
    } else {
        Err(format!(
            "{}: a case is written as .glb or .gltf",
            output.display()
        ))
    }
}

pub(super) fn open(inputs: &[PathBuf], args: &BuildOptions) -> Result<Case, String> {
    let inputs = Inputs::read(inputs, args.colors.as_deref())?;
    let options = OpenOptions {
        extract: ExtractOptions {
            labels: args.labels.clone(),
            min_voxels: args.min_voxels,
        },
        level: args.level,
    };
    let (files, table) = inputs.named()?;
    case::open(&files, table, &options).map_err(|e| e.to_string())
}
