//! Writers: an indexed mesh out as bytes (binary PLY, binary STL, OBJ, GLB), vertex order kept,
//! a case (several named, coloured structures) as one glTF scene, and a case with the student
//! viewer as a package a learning management system imports (`lms`).
//! Nothing from an input file's header is ever written (STL headers often carry patient names).

mod case_gltf;
mod case_lesson;
mod compressed;
mod glb;
pub mod lms;
mod meshopt;
mod obj;
mod ply;
mod simplified;
mod stl;

pub use case_gltf::{
    write_case, CaseGltfOptions, CaseWriter, Container, SceneFrame, RAS_MM_TO_GLTF,
};
pub use simplified::Simplification;

use crate::mesh::Mesh;
use crate::metrics::Metrics;
use crate::smooth::Params;

/// Output formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    Ply,
    Stl,
    Obj,
    Glb,
}

impl ExportFormat {
    pub const ALL: [ExportFormat; 4] = [
        ExportFormat::Glb,
        ExportFormat::Stl,
        ExportFormat::Ply,
        ExportFormat::Obj,
    ];

    /// The format named by a file name's extension (case-insensitive).
    pub fn from_name(name: &str) -> Option<ExportFormat> {
        Self::from_extension(name.rsplit_once('.')?.1)
    }

    /// The format of an extension without its dot (`glb stl ply obj`, case-insensitive).
    pub fn from_extension(ext: &str) -> Option<ExportFormat> {
        Self::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(ext))
    }

    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Ply => "ply",
            ExportFormat::Stl => "stl",
            ExportFormat::Obj => "obj",
            ExportFormat::Glb => "glb",
        }
    }

    /// The media type a download of this format carries.
    pub fn mime(self) -> &'static str {
        match self {
            ExportFormat::Glb => "model/gltf-binary",
            ExportFormat::Stl => "model/stl",
            ExportFormat::Obj => "model/obj",
            ExportFormat::Ply => "application/octet-stream",
        }
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
    /// GLB only: keep the data's millimetres as glTF's units, without the root node that turns
    /// RAS millimetres into metres with +Y up (for pipelines that expect the raw frame).
    pub millimetres: bool,
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
    #[error("the mesh has no triangles: there is nothing to write")]
    NoTriangles,
    #[error("triangle {triangle} uses vertex {index} but the mesh has {count} vertices")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("{what} of vertex {vertex} is not finite")]
    NonFinite { what: &'static str, vertex: usize },
    #[error("the lesson: {0}")]
    Lesson(String),
}

/// The GLB `extras` of a smoothed mesh: which filter made it, with which parameters, and its
/// measures (the same object the CLI's `smooth --json` prints, less the timing).
pub fn smoothing_extras(params: &Params, metrics: &Metrics) -> serde_json::Value {
    serde_json::json!({
        "generator": "meshsmooth",
        "filter": params.filter.name(),
        "params": params.to_json(),
        "metrics": metrics,
    })
}

/// Serialises `mesh` in `format`.
pub fn write(
    mesh: &Mesh,
    format: ExportFormat,
    options: &ExportOptions,
) -> Result<Vec<u8>, ExportError> {
    check(mesh, options)?;
    match format {
        ExportFormat::Ply => ply::write(mesh, options),
        ExportFormat::Stl => stl::write(mesh),
        ExportFormat::Obj => Ok(obj::write(mesh, options)),
        ExportFormat::Glb => glb::write(mesh, options),
    }
}

/// What every format needs: triangles, valid indices, finite coordinates and per-vertex
/// arrays as long as the vertex list.
fn check(mesh: &Mesh, options: &ExportOptions) -> Result<(), ExportError> {
    if mesh.triangles.is_empty() {
        return Err(ExportError::NoTriangles);
    }
    let count = mesh.vertex_count();
    for (what, got) in [
        ("normals", options.normals.map(<[_]>::len)),
        ("colors", options.colors.map(<[_]>::len)),
    ] {
        if let Some(got) = got.filter(|&g| g != count) {
            return Err(ExportError::LengthMismatch {
                what,
                got,
                expected: count,
            });
        }
    }
    for (triangle, t) in mesh.triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= count) {
            return Err(ExportError::IndexOutOfRange {
                triangle,
                index,
                count,
            });
        }
    }
    let finite = |p: &[f32; 3]| p.iter().all(|v| v.is_finite());
    for (what, values) in [
        ("position", Some(mesh.positions.as_slice())),
        ("normal", options.normals),
    ] {
        if let Some(vertex) = values.and_then(|v| v.iter().position(|p| !finite(p))) {
            return Err(ExportError::NonFinite { what, vertex });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> Mesh {
        Mesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        )
    }

    #[test]
    fn refuses_meshes_it_cannot_write_faithfully() {
        let none = ExportOptions::default();
        for format in [
            ExportFormat::Ply,
            ExportFormat::Stl,
            ExportFormat::Obj,
            ExportFormat::Glb,
        ] {
            let empty = Mesh::new(vec![[0.0; 3]], vec![]);
            assert_eq!(write(&empty, format, &none), Err(ExportError::NoTriangles));
            let normals = [[0.0, 0.0, 1.0]; 2];
            let short = ExportOptions {
                normals: Some(&normals),
                ..Default::default()
            };
            assert_eq!(
                write(&triangle(), format, &short),
                Err(ExportError::LengthMismatch {
                    what: "normals",
                    got: 2,
                    expected: 3
                })
            );
            let mut bad = triangle();
            bad.triangles[0][2] = 3;
            assert!(matches!(
                write(&bad, format, &none),
                Err(ExportError::IndexOutOfRange { index: 3, .. })
            ));
            let mut nan = triangle();
            nan.positions[1][0] = f32::NAN;
            assert_eq!(
                write(&nan, format, &none),
                Err(ExportError::NonFinite {
                    what: "position",
                    vertex: 1
                })
            );
        }
    }
}
