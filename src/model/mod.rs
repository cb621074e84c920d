//! The open model: a mesh with its topology, its report and its original's measures, as opening
//! a file (or one structure of a label map) builds it. The engine workers build it and send it
//! whole; the session holds it.

mod open;

pub use open::{open_file, open_structure, OpenFailure, Stage};

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::mesh::{Mesh, MeshReport, Topology};
use crate::metrics::Original;
use crate::segmentation::Structure;

/// A mesh the session opened, with what the measures precompute from it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Model {
    pub name: String,
    pub original: Original,
    pub report: MeshReport,
    pub warnings: Vec<String>,
    /// Each edge once (`i < j`), for the wireframe overlay.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub edges: Vec<[u32; 2]>,
    /// Where the model is one structure of a segmentation: all of them, and which it is.
    pub structures: Option<Structures>,
}

/// The structures extracted from a label map, and which one is the open model.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Structures {
    /// The label map's file name.
    pub file: String,
    pub list: Arc<Vec<Structure>>,
    pub current: usize,
}

impl Structures {
    pub fn current(&self) -> &Structure {
        &self.list[self.current]
    }

    /// The list for `state()` and the page's API: what each structure is, without its mesh.
    pub fn to_json(&self) -> serde_json::Value {
        let list: Vec<_> = self
            .list
            .iter()
            .map(|s| {
                serde_json::json!({
                    "label": s.label,
                    "name": s.name,
                    "color": s.color,
                    "voxels": s.voxels,
                    "voxel_size": s.voxel_size,
                    "vertices": s.mesh.vertex_count(),
                    "triangles": s.mesh.triangle_count(),
                    "volume": s.mesh.signed_volume(),
                })
            })
            .collect();
        serde_json::json!({ "file": self.file, "current": self.current, "structures": list })
    }
}

impl Model {
    /// Parses `bytes` (the format chosen by `name`'s extension), builds topology, report and
    /// the original's measures: [`open_file`] without watching its stages.
    pub fn load(name: &str, bytes: &[u8]) -> Result<Self, OpenFailure> {
        open_file(name, bytes, &mut |_| {})
    }

    pub fn mesh(&self) -> &Mesh {
        self.original.mesh()
    }

    pub fn topology(&self) -> &Topology {
        self.original.topology()
    }
}
