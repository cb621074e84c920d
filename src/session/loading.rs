//! Opening a file in stages (parse, topology, checks, the original's measures; all but the
//! parse a part at a time; a label map is read, then its structures extracted, and the first
//! structure opens as the model), so a page without threads can draw a frame with the progress between
//! them instead of freezing while a large mesh opens. [`Loading::finish`] runs every stage in one
//! call; the stages are the same.

use std::sync::Arc;

use super::{Model, Structures};
use crate::io::{self, LabelMapOptions, LoadError};
use crate::mesh::{Mesh, MeshReport, ReportInParts, Topology, TopologyInParts};
use crate::metrics::OriginalInParts;
use crate::segmentation::{self, ExtractOptions, LabelMap};

/// What is left to do, with what the done stages produced.
enum Stage {
    Parse(Vec<u8>),
    /// A label map read, its structures to extract.
    Extract(Box<LabelMap>),
    /// The incidence first (`None`), then the 1-rings a part per step.
    Topology(Mesh, Option<Box<TopologyInParts>>),
    /// The per-vertex checks, then the per-triangle checks, a part per step.
    Check(Mesh, Topology, Box<ReportInParts>),
    /// The original's precomputation (shown as preparing the measures) a step at a time, then
    /// its measures a part per step.
    Measure(Box<OriginalInParts>, MeshReport, Vec<[u32; 2]>),
}

/// Vertices (or triangles) per step of the stages done in parts: each step of the 206k-vertex
/// benchmark mesh takes about 10 ms or less in the browser.
const PART: usize = 32 * 1024;

/// Stage names, in order, as the progress bar shows them.
const STAGES: [&str; 5] = [
    "reading the file",
    "building the topology",
    "checking the mesh",
    "preparing the measures",
    "measuring the original",
];

/// The stages of a label map: read, extract, then a mesh's stages after its reading.
const LABEL_MAP_STAGES: [&str; 6] = [
    "reading the label map",
    "extracting the structures",
    "building the topology",
    "checking the mesh",
    "preparing the measures",
    "measuring the original",
];

/// How far an opening got: the stage under way (0-based) of [`LoadProgress::total`].
#[derive(Clone, Debug, PartialEq)]
pub struct LoadProgress {
    pub name: String,
    pub stage: usize,
    pub total: usize,
    /// What the stage under way does.
    pub doing: &'static str,
    /// The whole opening's part done, in [0, 1].
    pub fraction: f32,
}

/// A file being opened.
pub struct Loading {
    name: String,
    stage: Stage,
    /// The structures of the label map being opened, and which one becomes the model.
    structures: Option<Structures>,
}

/// What one stage left.
pub enum Loaded {
    /// More stages to go.
    Pending(Box<Loading>),
    Done(Box<Model>),
    Failed(OpenFailure),
}

/// Why a file could not be opened.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpenFailure {
    #[error(transparent)]
    Load(#[from] LoadError),
    #[error(transparent)]
    Extract(#[from] segmentation::ExtractError),
}

impl Loading {
    /// Opens `bytes` (the format from `name`'s extension).
    pub fn new(name: &str, bytes: Vec<u8>) -> Self {
        Self {
            name: name.to_string(),
            stage: Stage::Parse(bytes),
            structures: None,
        }
    }

    /// Opens structure `index` of an extracted segmentation as the model (its mesh's stages).
    pub fn structure(structures: Structures) -> Self {
        let s = structures.current();
        Self {
            name: format!("{}: {}", structures.file, s.name),
            stage: Stage::Topology(s.mesh.clone(), None),
            structures: Some(structures),
        }
    }

    /// The stage names of this opening: a label map has two before a mesh's.
    fn stages(&self) -> &'static [&'static str] {
        if self.structures.is_some() || io::is_label_map(&self.name) {
            &LABEL_MAP_STAGES
        } else {
            &STAGES
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn progress(&self) -> LoadProgress {
        let (stage, within) = match &self.stage {
            Stage::Parse(_) => (0, 0.0),
            Stage::Extract(_) => (1, 0.0),
            Stage::Topology(_, parts) => (1, parts.as_ref().map_or(0.0, |p| p.fraction())),
            Stage::Check(.., parts) => (2, parts.fraction()),
            Stage::Measure(original, ..) if original.preparing() => (3, original.fraction()),
            Stage::Measure(original, ..) => (4, original.fraction()),
        };
        let stages = self.stages();
        // A label map's mesh stages come one later (after the extraction).
        let stage = match &self.stage {
            Stage::Parse(_) | Stage::Extract(_) => stage,
            _ => stage + stages.len() - STAGES.len(),
        };
        LoadProgress {
            name: self.name.clone(),
            stage,
            total: stages.len(),
            doing: stages[stage],
            fraction: (stage as f32 + within) / stages.len() as f32,
        }
    }

    /// Runs the next stage.
    pub fn step(self) -> Loaded {
        let Self {
            mut name,
            stage,
            mut structures,
        } = self;
        let next = match stage {
            Stage::Parse(bytes) if io::is_label_map(&name) => {
                match io::load_label_map(&bytes, &name, &LabelMapOptions::default()) {
                    Ok(map) => Stage::Extract(Box::new(map)),
                    Err(e) => return Loaded::Failed(OpenFailure::Load(e)),
                }
            }
            Stage::Parse(bytes) => match io::load(&bytes, &name) {
                Ok(mesh) => Stage::Topology(mesh, None),
                Err(e) => return Loaded::Failed(OpenFailure::Load(e)),
            },
            Stage::Extract(map) => {
                match segmentation::extract(&map, &[], &ExtractOptions::default()) {
                    Ok(list) => {
                        let mesh = list[0].mesh.clone();
                        let file = std::mem::take(&mut name);
                        name = format!("{file}: {}", list[0].name);
                        structures = Some(Structures {
                            file,
                            list: Arc::new(list),
                            current: 0,
                        });
                        Stage::Topology(mesh, None)
                    }
                    Err(e) => return Loaded::Failed(OpenFailure::Extract(e)),
                }
            }
            Stage::Topology(mesh, None) => {
                let parts = Box::new(TopologyInParts::new(&mesh));
                Stage::Topology(mesh, Some(parts))
            }
            Stage::Topology(mesh, Some(mut parts)) => {
                if parts.advance(&mesh, PART) {
                    let topology = parts.finish();
                    let report = Box::new(ReportInParts::new(&mesh));
                    Stage::Check(mesh, topology, report)
                } else {
                    Stage::Topology(mesh, Some(parts))
                }
            }
            Stage::Check(mesh, topology, mut parts) => {
                if parts.advance(&mesh, &topology, PART) {
                    let report = parts.finish(&mesh, &topology);
                    let edges = topology.edges();
                    let original = Box::new(OriginalInParts::new(mesh, topology));
                    Stage::Measure(original, report, edges)
                } else {
                    Stage::Check(mesh, topology, parts)
                }
            }
            Stage::Measure(mut original, report, edges) => {
                if !original.advance(PART) {
                    let stage = Stage::Measure(original, report, edges);
                    return Loaded::Pending(Box::new(Self {
                        name,
                        stage,
                        structures,
                    }));
                }
                return Loaded::Done(Box::new(Model {
                    name,
                    warnings: report.warnings(),
                    original: original.finish(),
                    report,
                    edges,
                    structures,
                }));
            }
        };
        Loaded::Pending(Box::new(Self {
            name,
            stage: next,
            structures,
        }))
    }

    /// Every stage left, in one call.
    pub fn finish(self) -> Result<Model, OpenFailure> {
        let mut loading = self;
        loop {
            match loading.step() {
                Loaded::Pending(next) => loading = *next,
                Loaded::Done(model) => return Ok(*model),
                Loaded::Failed(e) => return Err(e),
            }
        }
    }
}
