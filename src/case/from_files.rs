//! Opening files as a case, the one way the CLI, the page's workers and the tests do: label
//! maps (each label a structure, or several masks one structure each, named by a colour table
//! given beside them), surface meshes (one structure each, named by the file) and case glTFs
//! (their structures, records and all), in the order given.

use super::{from_gltf_scene, Case, CaseRecordError, CaseStructure};
use crate::io::{self, Format, LoadError};
use crate::mesh::Mesh;
use crate::segmentation::{self, default_color, NamedBytes, OpenOptions};

/// Why files could not be opened as a case; each names the file at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CaseOpenError {
    #[error(transparent)]
    Segmentation(#[from] segmentation::OpenError),
    #[error("{name}: {error}")]
    Load { name: String, error: LoadError },
    #[error("{name}: {error}")]
    Record {
        name: String,
        error: CaseRecordError,
    },
    #[error("{first} and {second}: one colour table names a label map's labels, not two")]
    Tables { first: String, second: String },
    #[error("no file given")]
    NoFiles,
    #[error("{0}: {VIEWER_READS}")]
    NotACase(String),
}

const VIEWER_READS: &str = "the viewer opens case glTF files (.glb, .gltf) only";

impl CaseOpenError {
    /// What is wrong, without the file's name: for a caller that names the one file itself.
    pub fn detail(&self) -> String {
        use segmentation::OpenError;
        match self {
            CaseOpenError::Segmentation(OpenError::Load { error, .. })
            | CaseOpenError::Load { error, .. } => error.to_string(),
            CaseOpenError::Segmentation(OpenError::Extract { error, .. }) => error.to_string(),
            CaseOpenError::Record { error, .. } => error.to_string(),
            CaseOpenError::NotACase(_) => VIEWER_READS.to_string(),
            other => other.to_string(),
        }
    }
}

/// Reading a surface or glTF file, one stage each.
const READING_FILE: &str = "reading the file";

/// Opens `files` as one case. Label maps go together to [`segmentation::open`] (one label map,
/// or several masks) with `table` and `options`; every other file adds its structures after
/// them. Only file names (never folders or headers) are kept as the structures' sources.
pub fn open(
    files: &[NamedBytes],
    table: Option<NamedBytes>,
    options: &OpenOptions,
) -> Result<Case, CaseOpenError> {
    open_staged(files, table, options, &mut |_| {})
}

/// The stages [`open_staged`] announces for `files`, in order.
pub fn reading_stages(files: &[NamedBytes]) -> Vec<&'static str> {
    let maps = files.iter().filter(|f| io::is_label_map(f.name)).count();
    let mut stages = segmentation::reading_stages(maps);
    stages.extend(std::iter::repeat_n(READING_FILE, files.len() - maps));
    stages
}

/// [`open`], telling `on_stage` each of [`reading_stages`] as it begins.
pub fn open_staged(
    files: &[NamedBytes],
    table: Option<NamedBytes>,
    options: &OpenOptions,
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Case, CaseOpenError> {
    if files.is_empty() {
        return Err(CaseOpenError::NoFiles);
    }
    let (maps, others): (Vec<NamedBytes>, Vec<NamedBytes>) =
        files.iter().partition(|f| io::is_label_map(f.name));
    if !crate::AUTHORING {
        return open_case_gltfs(files, on_stage);
    }
    let mut case = Case::default();
    if !maps.is_empty() {
        let structures = segmentation::open_staged(&maps, table, options, on_stage)?;
        let source = match maps.as_slice() {
            [one] => Some(file_name(one.name)),
            _ => None,
        };
        let mut opened = Case::from_label_map(structures, source);
        if maps.len() > 1 {
            for (s, f) in opened.structures.iter_mut().zip(&maps) {
                s.source = Some(file_name(f.name).to_string());
            }
        }
        case.add(opened);
    }
    for f in others {
        on_stage(READING_FILE);
        let load = |error| CaseOpenError::Load {
            name: f.name.to_string(),
            error,
        };
        match Format::from_name(f.name) {
            Some(Format::Glb | Format::Gltf) => case.add(read_case_gltf(&f)?),
            // Surfaces, and whatever else: io::load says what it cannot read.
            _ => {
                let mesh = io::load(f.bytes, f.name).map_err(load)?;
                let ordinal = case.structures.len();
                case.structures
                    .push(surface_structure(f.name, mesh, ordinal));
            }
        }
    }
    Ok(case)
}

/// The student's viewer's reading: case glTF files only (its build has no other reader).
fn open_case_gltfs(
    files: &[NamedBytes],
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Case, CaseOpenError> {
    let mut case = Case::default();
    for f in files {
        on_stage(READING_FILE);
        match Format::from_name(f.name) {
            Some(Format::Glb | Format::Gltf) => case.add(read_case_gltf(f)?),
            _ => return Err(CaseOpenError::NotACase(f.name.to_string())),
        }
    }
    Ok(case)
}

/// A glTF file read as a case (any glTF: one written here keeps its record).
fn read_case_gltf(f: &NamedBytes) -> Result<Case, CaseOpenError> {
    let scene = io::load_gltf_scene(f.bytes, f.name).map_err(|error| CaseOpenError::Load {
        name: f.name.to_string(),
        error,
    })?;
    from_gltf_scene(scene, file_name(f.name)).map_err(|error| CaseOpenError::Record {
        name: f.name.to_string(),
        error,
    })
}

/// The file the case's first structure comes from: label maps open before the other files.
pub fn first_structure_file<'a>(files: &[NamedBytes<'a>]) -> Option<&'a str> {
    (files.iter().find(|f| io::is_label_map(f.name)))
        .or(files.first())
        .map(|f| f.name)
}

/// Files dropped or chosen together, with a colour table among them taken out to name the
/// label maps' labels: a table is one only beside a label map (alone, a `.txt` is no file
/// this opens). Two tables are refused.
pub fn split_color_table<'a>(
    files: &[NamedBytes<'a>],
) -> Result<(Vec<NamedBytes<'a>>, Option<NamedBytes<'a>>), CaseOpenError> {
    if !files.iter().any(|f| io::is_label_map(f.name)) {
        return Ok((files.to_vec(), None));
    }
    let (tables, rest): (Vec<NamedBytes>, Vec<NamedBytes>) =
        files.iter().partition(|f| io::is_color_table(f.name));
    match tables.as_slice() {
        [] => Ok((rest, None)),
        [one] => Ok((rest, Some(*one))),
        [first, second, ..] => Err(CaseOpenError::Tables {
            first: first.name.to_string(),
            second: second.name.to_string(),
        }),
    }
}

/// The structure a surface file (STL, OBJ, PLY) makes: named by its file, coloured by its
/// place in the case.
pub fn surface_structure(path: &str, mesh: Mesh, ordinal: usize) -> CaseStructure {
    let mut s = CaseStructure::from_mesh(&mesh_name(path), mesh, default_color(ordinal));
    s.source = Some(file_name(path).to_string());
    s
}

/// A path's last component: all of a path a case keeps.
pub fn file_name(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

/// A surface's structure name from its file's: `portal_vein.stl` is "portal vein".
fn mesh_name(path: &str) -> String {
    let base = file_name(path);
    let stem = base.rsplit_once('.').map_or(base, |(stem, _)| stem);
    stem.replace('_', " ").trim().to_string()
}
