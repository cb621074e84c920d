//! The open model: a mesh with its topology, its report and its original's measures, as opening
//! files (or selecting one structure of a case) builds it (`build`). The engine workers build a
//! file's and send it whole; the session builds a selected structure's and keeps each one built
//! beside the case.

mod build;

pub use build::{open_case, open_files, open_structure, OpenFailure, Stage};

use serde::{Deserialize, Serialize};

use crate::case::Case;
use crate::mesh::{Mesh, MeshReport, Topology};
use crate::metrics::Original;
use crate::segmentation::NamedBytes;

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
}

/// A file opened: the case it makes (a label map's structures, a case glTF's, a surface as a
/// case of one) and its first structure as the model.
#[derive(Clone, Debug)]
pub struct Opened {
    pub case: Case,
    pub model: Model,
}

impl Model {
    /// Parses `bytes` (the format chosen by `name`'s extension), builds topology, report and
    /// the original's measures of its first structure: [`open_files`] of one file, without
    /// watching its stages.
    pub fn load(name: &str, bytes: &[u8]) -> Result<Opened, OpenFailure> {
        open_files(&[NamedBytes { name, bytes }], &mut |_| {})
    }

    pub fn mesh(&self) -> &Mesh {
        self.original.mesh()
    }

    pub fn topology(&self) -> &Topology {
        self.original.topology()
    }
}
