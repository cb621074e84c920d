//! Parsers: bytes in, indexed mesh out. They take `&[u8]`, never paths, so the browser and the
//! CLI share them. No input may panic; every failure is a [`LoadError`] naming what and where.

mod error;
mod gltf;
mod obj;
mod ply;
mod ply_ascii;
mod ply_binary;
mod stl;
mod text;
mod weld;

pub use error::{LoadError, Location};
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
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Format::Stl => "STL",
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
            Format::Glb => "GLB",
            Format::Gltf => "glTF",
        })
    }
}

impl Format {
    /// The format named by a file name's extension (case-insensitive).
    pub fn from_name(name: &str) -> Option<Format> {
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
}

/// Reads a mesh, choosing the parser by the file name's extension.
pub fn load(bytes: &[u8], name: &str) -> Result<Mesh, LoadError> {
    let format = Format::from_name(name).ok_or_else(|| LoadError::UnknownFormat {
        name: name.to_string(),
    })?;
    load_as(bytes, format)
}

/// Reads a mesh in the given format.
pub fn load_as(bytes: &[u8], format: Format) -> Result<Mesh, LoadError> {
    if bytes.is_empty() {
        return Err(LoadError::Empty { format });
    }
    match format {
        Format::Stl => stl::parse(bytes),
        Format::Obj => obj::parse(bytes),
        Format::Ply => ply::parse(bytes),
        Format::Glb | Format::Gltf => gltf::parse(bytes, format),
    }
}
