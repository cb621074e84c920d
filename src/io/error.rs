//! Typed load errors: every message says what is wrong and where (format, line or byte offset).
//! Label maps (NIfTI, NRRD) and colour tables report through the same variants.

use super::Format;

/// Why a file could not be read as a mesh (or a label map, or a colour table).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadError {
    #[error("{format}: the file is empty")]
    Empty { format: Format },
    #[error(
        "cannot tell the format of '{name}': use one of .stl .obj .ply .glb .gltf (meshes) or \
         .nii .nii.gz .nrrd .mgz .mgh .dcm (label maps)"
    )]
    UnknownFormat { name: String },
    #[error(
        "cannot tell the image format of '{name}': use one of .nii .nii.gz .nrrd .mgz .mgh .dcm \
         (or a folder of a DICOM series)"
    )]
    UnknownImageFormat { name: String },
    #[error("{format}: not a {format} file ({detail})")]
    BadMagic { format: Format, detail: String },
    #[error("{format}: file ends early at byte {offset}: {detail}")]
    Truncated {
        format: Format,
        offset: usize,
        detail: String,
    },
    #[error("{format}: header claims {claimed} {what} but the data can hold at most {possible}")]
    CountTooLarge {
        format: Format,
        what: &'static str,
        claimed: u64,
        possible: u64,
    },
    #[error("{format}: {location}: {detail}")]
    Syntax {
        format: Format,
        location: Location,
        detail: String,
    },
    #[error("{format}: {location}: vertex index {index} is out of range (the file has {count} vertices)")]
    IndexOutOfRange {
        format: Format,
        location: Location,
        index: i64,
        count: usize,
    },
    #[error("{format}: {location}: coordinate is not a finite number ({value})")]
    NonFinite {
        format: Format,
        location: Location,
        value: String,
    },
    #[error("{format}: the file holds no triangles")]
    NoTriangles { format: Format },
    #[error("{format}: {detail}")]
    Unsupported { format: Format, detail: String },
}

/// Where in a file an error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    Line(usize),
    Byte(usize),
    /// An element of a structured file (glTF accessor, mesh or buffer index).
    Item(&'static str, usize),
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::Item(what, i) => write!(f, "{what} {i}"),
        }
    }
}
