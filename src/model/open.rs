//! Opening a file, stage by stage: read it as a case (a label map's structures extracted, a
//! case glTF's read back, a surface as a case of one), then the first structure's topology,
//! checks and the original's measures. The caller hears each stage as it begins, so a worker
//! can tell the page how far it got.

use super::{Model, Opened};
use crate::case::{self, Case, CaseRecordError};
use crate::io::{self, Format, LabelMapOptions, LoadError};
use crate::mesh::{Mesh, MeshReport, Topology};
use crate::metrics::Original;
use crate::segmentation::{self, ExtractOptions};

/// The stages of a surface or glTF file, in order, as the progress bar names them.
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
    #[error(transparent)]
    Case(#[from] CaseRecordError),
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

/// Opens `bytes` (the format from `name`'s extension) as a case, its first structure the
/// model; `on_stage` hears each stage as it begins.
pub fn open_file(
    name: &str,
    bytes: &[u8],
    on_stage: &mut dyn FnMut(Stage),
) -> Result<Opened, OpenFailure> {
    let mut stages = Stages {
        names: stage_names(name),
        next: 0,
        on_stage,
    };
    let case = read_case(name, bytes, &mut stages)?;
    let first = case.structures.first().ok_or(CaseRecordError::Empty)?;
    let model_name = if case.structures.len() == 1 && !io::is_label_map(name) {
        name.to_string()
    } else {
        format!("{name}: {}", first.name)
    };
    let model = build(model_name, first.original.clone(), &mut stages);
    Ok(Opened { case, model })
}

/// Opens `bytes` as a case only (structures to add to an open case): the reading stages.
pub fn open_case(
    name: &str,
    bytes: &[u8],
    on_stage: &mut dyn FnMut(Stage),
) -> Result<Case, OpenFailure> {
    let names = stage_names(name);
    let reading = if io::is_label_map(name) { 2 } else { 1 };
    let mut stages = Stages {
        names: &names[..reading],
        next: 0,
        on_stage,
    };
    read_case(name, bytes, &mut stages)
}

/// Opens a structure's `mesh` as a model named `name`.
pub fn open_structure(name: &str, mesh: Mesh, on_stage: &mut dyn FnMut(Stage)) -> Model {
    let mut stages = Stages {
        names: &STRUCTURE_STAGES,
        next: 0,
        on_stage,
    };
    build(name.to_string(), mesh, &mut stages)
}

fn stage_names(name: &str) -> &'static [&'static str] {
    if io::is_label_map(name) {
        &LABEL_MAP_STAGES
    } else {
        &FILE_STAGES
    }
}

/// The reading stages: the file as a case.
fn read_case(name: &str, bytes: &[u8], stages: &mut Stages<'_>) -> Result<Case, OpenFailure> {
    stages.begin();
    let file = case::file_name(name);
    if io::is_label_map(name) {
        let map = io::load_label_map(bytes, name, &LabelMapOptions::default())?;
        stages.begin();
        let list = segmentation::extract(&map, &[], &ExtractOptions::default())?;
        // `extract` fails rather than find nothing; an empty list reads as that failure.
        if list.is_empty() {
            return Err(segmentation::ExtractError::Empty.into());
        }
        return Ok(Case::from_label_map(list, Some(file)));
    }
    if matches!(Format::from_name(name), Some(Format::Glb | Format::Gltf)) {
        let scene = io::load_gltf_scene(bytes, name)?;
        return Ok(case::from_gltf_scene(scene, file)?);
    }
    let mesh = io::load(bytes, name)?;
    Ok(Case {
        structures: vec![case::surface_structure(name, mesh, 0)],
        ..Case::default()
    })
}

/// The mesh stages: topology, checks, the original's measures.
fn build(name: String, mesh: Mesh, stages: &mut Stages<'_>) -> Model {
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
    }
}
