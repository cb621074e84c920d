//! Opening files as a case: label maps (each label a structure, or several masks one
//! structure each), surface meshes (one structure each, named by the file) and case glTFs
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
    #[error("{name}: not a label map, mesh or glTF file (by its extension)")]
    Unknown { name: String },
    #[error("no file given")]
    NoFiles,
}

/// Opens `files` as one case. Label maps go together to [`segmentation::open`] (one label map,
/// or several masks) with `table` and `options`; every other file adds its structures after
/// them. Only file names (never folders or headers) are kept as the structures' sources.
pub fn open(
    files: &[NamedBytes],
    table: Option<NamedBytes>,
    options: &OpenOptions,
) -> Result<Case, CaseOpenError> {
    if files.is_empty() {
        return Err(CaseOpenError::NoFiles);
    }
    let (maps, others): (Vec<&NamedBytes>, Vec<&NamedBytes>) =
        files.iter().partition(|f| io::is_label_map(f.name));
    let mut case = Case::default();
    if !maps.is_empty() {
        let maps: Vec<NamedBytes> = maps
            .iter()
            .map(|f| NamedBytes {
                name: f.name,
                bytes: f.bytes,
            })
            .collect();
        let structures = segmentation::open(&maps, table, options)?;
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
            Some(Format::Stl | Format::Obj | Format::Ply) => {
                let mesh = io::load(f.bytes, f.name).map_err(load)?;
                let ordinal = case.structures.len();
                case.structures
                    .push(surface_structure(f.name, mesh, ordinal));
            }
            _ => {
                return Err(CaseOpenError::Unknown {
                    name: f.name.to_string(),
                })
            }
        }
    }
    Ok(case)
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
