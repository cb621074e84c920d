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
}

impl CaseOpenError {
    /// What is wrong, without the file's name: for a caller that names the one file itself.
    pub fn detail(&self) -> String {
        use segmentation::OpenError;
        match self {
            CaseOpenError::Segmentation(OpenError::Load { error, .. })
            | CaseOpenError::Load { error, .. } => error.to_string(),
            CaseOpenError::Segmentation(OpenError::Extract { error, .. }) => error.to_string(),
            CaseOpenError::Record { error, .. } => error.to_string(),
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
            Some(Format::Glb | Format::Gltf) => {
                let scene = io::load_gltf_scene(f.bytes, f.name).map_err(load)?;
                let opened = from_gltf_scene(scene, file_name(f.name)).map_err(|error| {
                    CaseOpenError::Record {
                        name: f.name.to_string(),
                        error,
                    }
                })?;
                case.add(opened);
            }
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

/// Whether a file or subfolder found in a folder opens with the folder's others: every one but
/// hidden ones (a file manager's `.DS_Store`) and a DICOMDIR index, which holds no slice or
/// segment. The CLI's folders and the page's dropped folders are read alike.
pub fn read_in_folder(name: &str) -> bool {
    let name = file_name(name);
    !name.starts_with('.') && !name.eq_ignore_ascii_case("DICOMDIR")
}

/// A folder is read with its subfolders (a DICOM export keeps each series some levels below
/// the folder a user picks) down to this many levels below it...
pub const FOLDER_DEPTH: usize = 8;
/// ...and up to this many entries in all: the listing stays bounded.
pub const FOLDER_ENTRIES: usize = 20_000;

/// Why a folder is not read: its subfolders go deeper than [`FOLDER_DEPTH`].
pub fn folder_too_deep() -> String {
    format!(
        "its subfolders go more than {FOLDER_DEPTH} levels down: open the folder that holds \
         the files"
    )
}

/// Why a folder is not read: it holds more than [`FOLDER_ENTRIES`] entries.
pub fn folder_too_large() -> String {
    format!(
        "the folder and its subfolders hold more than {FOLDER_ENTRIES} entries: open the \
         folder of one series or one set of masks"
    )
}

/// Why a folder whose subfolders (`subfolders` of them, all levels) hold no file that
/// [`read_in_folder`] keeps opens nothing.
pub fn no_file_in_folder(subfolders: usize) -> String {
    match subfolders {
        0 => "the folder holds no file".to_string(),
        n => format!("neither the folder nor its {n} subfolder(s) hold a file"),
    }
}

/// The order a folder's files open in: by their paths, folder by folder (`a/b` before `a-c`),
/// on the page and in the CLI alike.
pub fn folder_order(a: &str, b: &str) -> std::cmp::Ordering {
    a.split(['/', '\\']).cmp(b.split(['/', '\\']))
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
