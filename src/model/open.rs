//! Opening a file as a [`Model`], stage by stage: parse (or read a label map and extract its
//! structures, the first becoming the model), topology, checks, the original's measures. The
//! caller hears each stage as it begins, so a worker can tell the page how far it got.

use std::sync::Arc;

use super::{Model, Structures};
use crate::io::{self, LabelMapOptions, LoadError};
use crate::mesh::{Mesh, MeshReport, Topology};
use crate::metrics::Original;
use crate::segmentation::{self, ExtractOptions};

/// The stages of a mesh file, in order, as the progress bar names them.
const FILE_STAGES: [&str; 4] = [
    "reading the file",
    "building the topology",
    "checking the mesh",
    "measuring the original",
];

/// The stages of a label map: read, extract, then the first structure's mesh stages.
const LABEL_MAP_STAGES: [&str; 5] = [
    "reading the label map",
    "extracting the structures",
    "building the topology",
    "checking the mesh",
    "measuring the original",
];

/// The stages of a structure already extracted.
const STRUCTURE_STAGES: [&str; 3] = [
    "building the topology",
    "checking the mesh",
    "measuring the original",
];

/// A stage that begins: `index` (0-based) of `total`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stage {
    pub index: usize,
    pub total: usize,
    pub doing: &'static str,
}

/// Why a file could not be opened.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpenFailure {
    #[error(transparent)]
    Load(#[from] LoadError),
    #[error(transparent)]
    Extract(#[from] segmentation::ExtractError),
}

/// Announces the stages of one list in order.
struct Stages<'a> {
    names: &'static [&'static str],
    next: usize,
    on_stage: &'a mut dyn FnMut(Stage),
}

impl Stages<'_> {
    fn begin(&mut self) {
        let index = self.next.min(self.names.len() - 1);
        self.next += 1;
        (self.on_stage)(Stage {
            index,
            total: self.names.len(),
            doing: self.names[index],
        });
    }
}

/// Opens `bytes` (the format from `name`'s extension) as a model; `on_stage` hears each stage
/// as it begins. A label map opens its first structure, the others listed in the model.
pub fn open_file(
    name: &str,
    bytes: &[u8],
    on_stage: &mut dyn FnMut(Stage),
) -> Result<Model, OpenFailure> {
    if !io::is_label_map(name) {
        let mut stages = Stages {
            names: &FILE_STAGES,
            next: 0,
            on_stage,
        };
        stages.begin();
        let mesh = io::load(bytes, name)?;
        return Ok(build(name.to_string(), mesh, None, &mut stages));
    }
    let mut stages = Stages {
        names: &LABEL_MAP_STAGES,
        next: 0,
        on_stage,
    };
    stages.begin();
    let map = io::load_label_map(bytes, name, &LabelMapOptions::default())?;
    stages.begin();
    let list = segmentation::extract(&map, &[], &ExtractOptions::default())?;
    // `extract` fails rather than find nothing; an empty list reads as that failure.
    let first = list.first().ok_or(segmentation::ExtractError::Empty)?;
    let (model_name, mesh) = (format!("{name}: {}", first.name), first.mesh.clone());
    let structures = Structures {
        file: name.to_string(),
        list: Arc::new(list),
        current: 0,
    };
    Ok(build(model_name, mesh, Some(structures), &mut stages))
}

/// Opens an extracted structure's `mesh` as a model named `name` (its structures list is the
/// caller's to attach).
pub fn open_structure(name: &str, mesh: Mesh, on_stage: &mut dyn FnMut(Stage)) -> Model {
    let mut stages = Stages {
        names: &STRUCTURE_STAGES,
        next: 0,
        on_stage,
    };
    build(name.to_string(), mesh, None, &mut stages)
}

/// The mesh stages: topology, checks, the original's measures.
fn build(
    name: String,
    mesh: Mesh,
    structures: Option<Structures>,
    stages: &mut Stages<'_>,
) -> Model {
    stages.begin();
    let topology = Topology::build(&mesh);
    stages.begin();
    let report = MeshReport::new(&mesh, &topology);
    stages.begin();
    let edges = topology.edges();
    let original = Original::new(&mesh, &topology);
    Model {
        name,
        warnings: report.warnings(),
        original,
        report,
        edges,
        structures,
    }
}
