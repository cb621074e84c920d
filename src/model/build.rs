//! Building the model, stage by stage: files read as a case the one way
//! ([`case::open_staged`]: label maps, several masks, a colour table beside them, surfaces,
//! case glTFs), then the first structure's topology, checks and the original's measures. The
//! caller hears each stage as it begins, so a worker can tell the page how far it got.

use super::{Model, Opened};
use crate::case::{self, Case, CaseOpenError, CaseRecordError};
use crate::io::{self, Format};
use crate::mesh::{Mesh, MeshReport, Topology};
use crate::metrics::Original;
use crate::segmentation::{NamedBytes, OpenOptions};

/// The stages of a structure's mesh, after its file's.
const MESH_STAGES: [&str; 3] = [
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

/// Why files could not be opened, with the name they were opened under.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error}")]
pub struct OpenFailure {
    pub error: CaseOpenError,
    /// How many files were opened together: with one, its name need not be repeated.
    files: usize,
}

impl OpenFailure {
    /// What went wrong, naming the file at fault where several were opened together.
    pub fn reason(&self) -> String {
        if self.files == 1 {
            self.error.detail()
        } else {
            self.error.to_string()
        }
    }
}

/// Announces the stages of one list in order.
struct Stages<'a> {
    names: Vec<&'static str>,
    next: usize,
    on_stage: &'a mut dyn FnMut(Stage),
}

impl Stages<'_> {
    fn begin(&mut self, doing: &'static str) {
        let index = self.next.min(self.names.len().saturating_sub(1));
        self.next += 1;
        (self.on_stage)(Stage {
            index,
            total: self.names.len(),
            doing,
        });
    }
}

/// Opens `files`, dropped or chosen together, as one case (a colour table among them names
/// the label maps' labels), its first structure the model; `on_stage` hears each stage as it
/// begins.
pub fn open_files(
    files: &[NamedBytes],
    on_stage: &mut dyn FnMut(Stage),
) -> Result<Opened, OpenFailure> {
    let failed = |error| OpenFailure {
        error,
        files: files.len(),
    };
    let (files, table) = case::split_color_table(files).map_err(failed)?;
    let mut names = case::reading_stages(&files);
    names.extend(MESH_STAGES);
    let mut stages = Stages {
        names,
        next: 0,
        on_stage,
    };
    let case = case::open_staged(&files, table, &OpenOptions::default(), &mut |doing| {
        stages.begin(doing)
    })
    .map_err(failed)?;
    let first = case.structures.first().ok_or_else(|| {
        failed(CaseOpenError::Record {
            name: files.first().map_or("", |f| f.name).to_string(),
            error: CaseRecordError::Empty,
        })
    })?;
    let model = build(
        model_name(&files, &case),
        first.original.clone(),
        &mut stages,
    );
    Ok(Opened { case, model })
}

/// Opens `bytes` as a case only (structures to add to an open case): the reading stages.
pub fn open_case(
    name: &str,
    bytes: &[u8],
    on_stage: &mut dyn FnMut(Stage),
) -> Result<Case, OpenFailure> {
    let files = [NamedBytes { name, bytes }];
    let mut stages = Stages {
        names: case::reading_stages(&files),
        next: 0,
        on_stage,
    };
    case::open_staged(&files, None, &OpenOptions::default(), &mut |doing| {
        stages.begin(doing)
    })
    .map_err(|error| OpenFailure { error, files: 1 })
}

/// Builds the model of a structure of the open case (its `mesh`), named `name`;
/// `on_stage` hears each stage as it begins.
pub fn open_structure(name: &str, mesh: Mesh, on_stage: &mut dyn FnMut(Stage)) -> Model {
    let mut stages = Stages {
        names: MESH_STAGES.to_vec(),
        next: 0,
        on_stage,
    };
    build(name.to_string(), mesh, &mut stages)
}

/// The model's name: a surface file's own name, where its one structure is the model; else
/// the file and the structure ("case.nii.gz: liver").
fn model_name(files: &[NamedBytes], case: &Case) -> String {
    let first = case::first_structure_file(files).unwrap_or_default();
    let alone = match files {
        [_] => case.structures.len() == 1 && !io::is_label_map(first),
        _ => matches!(
            Format::from_name(first),
            Some(Format::Stl | Format::Obj | Format::Ply)
        ),
    };
    match case.structures.first() {
        Some(s) if !alone => format!("{first}: {}", s.name),
        _ => first.to_string(),
    }
}

/// The mesh stages: topology, checks, the original's measures.
fn build(name: String, mesh: Mesh, stages: &mut Stages<'_>) -> Model {
    stages.begin(MESH_STAGES[0]);
    let topology = Topology::build(&mesh);
    stages.begin(MESH_STAGES[1]);
    let report = MeshReport::new(&mesh, &topology);
    stages.begin(MESH_STAGES[2]);
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
