//! Parsers: bytes in, indexed mesh (or label map) out. They take `&[u8]`, never paths, so the
//! browser and the CLI share them. No input may panic; every failure is a [`LoadError`] naming
//! what and where.

mod codes;
mod color_table;
mod dicom;
mod error;
mod freesurfer_lut;
mod gltf;
mod gzip;
mod image;
mod intensity;
mod label_map;
mod label_map_checks;
mod mgh;
mod nifti;
mod nifti_names;
mod nrrd;
mod obj;
mod ply;
mod ply_ascii;
mod ply_binary;
mod read_label_map;
mod stl;
mod text;
mod voxels;
mod weld;

pub use codes::{Code, StructureCodes};
pub use color_table::{is_color_table, parse_color_table, LabelEntry};
pub use dicom::series::{load_image_series, SeriesError};
pub use error::{LoadError, Location};
pub use gltf::{GltfNode, GltfScene, Mat4};
pub use image::{load_image, reduced_affine, ImageVolume};
pub use intensity::BlockMeans;
pub use label_map::{Affine, LabelLayer, LabelMap, LabelMapOptions, Segment, MAX_LABELS};
pub use nifti_names::readable as readable_class_name;
pub use read_label_map::{is_label_map, load_label_map};
pub use weld::weld_exact;

use crate::mesh::Mesh;

/// Input formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Stl,
    Obj,
    Ply,
    Glb,
    Gltf,
    /// A label map (segmentation), read by [`load_label_map`], not by [`load`].
    Nifti,
    /// A label map (segmentation), read by [`load_label_map`], not by [`load`].
    Nrrd,
    /// FreeSurfer's MGH/MGZ volume: a label map, read by [`load_label_map`].
    Mgh,
    /// A DICOM Segmentation object: a label map, read by [`load_label_map`].
    DicomSeg,
    /// One slice of a DICOM image series (CT or MR), read by [`load_image_series`].
    DicomImage,
    /// A label map's colour table, read by [`parse_color_table`].
    ColorTable,
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Format::Stl => "STL",
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
            Format::Glb => "GLB",
            Format::Gltf => "glTF",
            Format::Nifti => "NIfTI",
            Format::Nrrd => "NRRD",
            Format::Mgh => "MGH",
            Format::DicomSeg => "DICOM SEG",
            Format::DicomImage => "DICOM image",
            Format::ColorTable => "colour table",
        })
    }
}

impl Format {
    /// The format named by a file name's extension (case-insensitive): a mesh format, or a
    /// label-map one (`.nii`, `.nii.gz`, `.nrrd`, `.nhdr`, `.mgh`, `.mgz`, `.dcm`).
    pub fn from_name(name: &str) -> Option<Format> {
        if let Some(format) = read_label_map::label_format_of(name) {
            return Some(format);
        }
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        Some(match ext.as_str() {
            "stl" => Format::Stl,
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "glb" => Format::Glb,
            "gltf" => Format::Gltf,
            _ => return None,
        })
    }

    /// Whether files of this format hold label maps (segmentations) rather than meshes.
    pub fn is_label_map(self) -> bool {
        matches!(
            self,
            Format::Nifti | Format::Nrrd | Format::Mgh | Format::DicomSeg
        )
    }
}

/// Reads a glTF scene node by node (a case's structures), choosing `.glb` or `.gltf` by the
/// bytes; `name` names the file in errors' formats only.
pub fn load_gltf_scene(bytes: &[u8], name: &str) -> Result<GltfScene, LoadError> {
    let format = match Format::from_name(name) {
        Some(f @ (Format::Glb | Format::Gltf)) => f,
        _ => Format::Gltf,
    };
    if bytes.is_empty() {
        return Err(LoadError::Empty { format });
    }
    gltf::read_scene(bytes, format)
}

/// Reads a mesh, choosing the parser by the file name's extension. A label map's name gives an
/// error that says so (see [`load_label_map`]).
pub fn load(bytes: &[u8], name: &str) -> Result<Mesh, LoadError> {
    let format = Format::from_name(name).ok_or_else(|| LoadError::UnknownFormat {
        name: name.to_string(),
    })?;
    if format.is_label_map() {
        return Err(LoadError::Unsupported {
            format,
            detail: format!(
                "'{name}' is a label map: open it as a segmentation (meshsmooth extract)"
            ),
        });
    }
    load_as(bytes, format)
}

/// Reads a mesh in the given format.
pub fn load_as(bytes: &[u8], format: Format) -> Result<Mesh, LoadError> {
    let is_mesh = !format.is_label_map() && format != Format::ColorTable;
    if bytes.is_empty() && is_mesh {
        return Err(LoadError::Empty { format });
    }
    match format {
        Format::Stl => stl::parse(bytes),
        Format::Obj => obj::parse(bytes),
        Format::Ply => ply::parse(bytes),
        Format::Glb | Format::Gltf => gltf::parse(bytes, format),
        Format::Nifti
        | Format::Nrrd
        | Format::Mgh
        | Format::DicomSeg
        | Format::DicomImage
        | Format::ColorTable => Err(LoadError::Unsupported {
            format,
            detail: "not a mesh format: open label maps as a segmentation (meshsmooth extract)"
                .into(),
        }),
    }
}
