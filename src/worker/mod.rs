//! What one of the page's engine workers does: the CPU engine's jobs as plain blocking calls, the
//! very calls the CLI makes, asked and answered in messages. Free of any web API: the page's
//! workers (`app::workers`) carry the bytes, the native tests hand them to [`Worker::handle`]
//! on their own thread ([`InThread`]). [`Pool`] keeps the queue on the asking side.

#[cfg(test)]
pub(crate) mod deferred;
mod in_thread;
mod pool;

pub use in_thread::InThread;
pub use pool::{Carrier, LoadJob, Pool, SmoothJob, StructureJob};

use serde::{Deserialize, Serialize};

use crate::case::{self, Case, CaseStructure, SuggestAllOptions};
use crate::evaluate::{Evaluator, Terms};
use crate::mesh::{Mesh, Topology};
use crate::metrics::{self, Metrics, Original, VertexMeasures};
use crate::model::{self, Model};
use crate::segmentation::NamedBytes;
use crate::smooth::Params;
use crate::suggest::MeshEvaluator;

/// A file's name and bytes, as a message carries them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NamedFile {
    pub name: String,
    #[serde(with = "crate::mesh::flat_bytes")]
    pub bytes: Vec<u8>,
}

/// What a [`Request::Load`] opens.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Input {
    /// Files opened together as one case (one file, several masks, a label map with its colour
    /// table: [`model::open_files`]), its first structure as the model.
    Files(Vec<NamedFile>),
    /// A file's bytes read as a case only, to add its structures to the open one.
    Add(#[serde(with = "crate::mesh::flat_bytes")] Vec<u8>),
    /// A structure of the open case, its surface made the model ([`model::open_structure`]),
    /// so a large one is not built on the page's thread.
    Structure(Mesh),
    /// The image the segmentation was drawn on, read as a case holding only it
    /// ([`crate::case::CaseImage::read`]: one file, or the slices of a DICOM series): windowed
    /// by the preset so named, checked against the open case's grids.
    Image {
        files: Vec<NamedFile>,
        preset: String,
        grids: Vec<case::StructureGrid>,
    },
}

/// A message to a worker.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Request {
    /// Open `input` as a model named `name` and send it back whole ([`Reply::Loaded`]), telling
    /// each stage as it begins ([`Reply::Progress`]).
    Load {
        job: u64,
        name: String,
        input: Input,
    },
    /// Hold `mesh` as model `model` (its topology and the original's measures are built here,
    /// unless this worker just opened that very mesh), dropping any other.
    Hold { model: u64, mesh: Mesh },
    /// The per-vertex weights of `model` from now on (`None`: all 1), known as `version`.
    Weights {
        model: u64,
        version: u64,
        weights: Option<Vec<f32>>,
    },
    /// Smooth the model with `params` and measure the result at `tau`.
    Smooth { job: u64, params: Params, tau: f64 },
    /// "Suggest all" for one structure: the suggestion at `tau` from `params` (its filter and
    /// bound) on `mesh` with `weights`, then the structure smoothed with it and measured.
    SuggestStructure {
        job: u64,
        mesh: Mesh,
        params: Params,
        weights: Option<Vec<f32>>,
        options: SuggestAllOptions,
        /// Where its local search starts ([`crate::case::starts_from`]); empty: the corners.
        starts: Vec<Params>,
    },
    /// The checks between `case`'s structures: as opened, and as shown ([`Reply::Checked`]).
    CheckCase { job: u64, case: Box<Case> },
    /// The terms of `params` after each count of `at` ([`Evaluator::measure`]).
    Terms {
        job: u64,
        params: Params,
        at: Vec<u32>,
    },
}

/// A worker's answer to [`Request::Load`], [`Request::Smooth`] or [`Request::Terms`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Reply {
    /// A stage of an opening begins: `stage` (0-based) of `stages`. Not the job's answer.
    Progress {
        job: u64,
        stage: u32,
        stages: u32,
        doing: String,
    },
    Loaded {
        job: u64,
        /// The model (none for an [`Input::Add`] or an [`Input::Image`]).
        model: Option<Box<Model>>,
        /// The case the files make (none for an [`Input::Structure`]).
        case: Option<Box<Case>>,
        /// Each stage with the milliseconds it took, in order.
        stages: Vec<(String, f64)>,
    },
    Smoothed {
        job: u64,
        positions: Vec<[f32; 3]>,
        /// [`Metrics`] as JSON: its optional exact-error fields are left out when absent,
        /// which a binary format cannot express.
        metrics: String,
        vertex: VertexMeasures,
        /// Milliseconds the smoothing (with the drifting reference) and the measures took.
        smooth_ms: f64,
        measure_ms: f64,
    },
    Terms {
        job: u64,
        terms: Vec<Terms>,
        ms: f64,
    },
    /// A structure's suggestion and its surface smoothed with it (`None`: nothing to smooth).
    Suggested {
        job: u64,
        suggested: Option<Box<StructureSuggestion>>,
    },
    /// The checks between a case's structures: [`case::checks_json`] with the lines of
    /// [`case::checks_text`] under `text` and the structures of its warnings (by index) under
    /// `flagged`, as JSON text; and per structure the vertices of its surface as shown that
    /// make a warning ([`case::check_marks`]).
    Checked {
        job: u64,
        report: String,
        marks: Vec<Vec<u32>>,
    },
    /// The job could not be done (no model, weights of another length).
    Failed { job: u64, why: String },
    /// The worker stopped in the middle of its job (a trap in its module): whatever it was
    /// doing fails. The page's carrier makes this of a worker's error message.
    Broken { why: String },
    /// The bytes of the worker's memory after a job (its peak: wasm memory only grows). Not a
    /// job's answer.
    Memory { bytes: u64 },
}

impl Reply {
    /// The job this answers (`None`: the worker's job under way, see [`Reply::Broken`]).
    pub fn job(&self) -> Option<u64> {
        match self {
            Reply::Progress { job, .. }
            | Reply::Loaded { job, .. }
            | Reply::Smoothed { job, .. }
            | Reply::Terms { job, .. }
            | Reply::Suggested { job, .. }
            | Reply::Checked { job, .. }
            | Reply::Failed { job, .. } => Some(*job),
            Reply::Broken { .. } | Reply::Memory { .. } => None,
        }
    }
}

/// What [`Request::SuggestStructure`] found.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StructureSuggestion {
    pub params: Params,
    /// Parameter sets measured.
    pub evaluations: usize,
    pub positions: Vec<[f32; 3]>,
    /// [`Metrics`] as JSON, as in [`Reply::Smoothed`].
    pub metrics: String,
    pub local_error: Vec<f32>,
}

/// Encodes a message for the wire.
pub fn encode<T: Serialize>(message: &T) -> Vec<u8> {
    postcard::to_allocvec(message).expect("postcard serializes every message type here")
}

/// Decodes a message from the wire.
pub fn decode<'a, T: Deserialize<'a>>(bytes: &'a [u8]) -> Result<T, String> {
    postcard::from_bytes(bytes).map_err(|e| format!("a worker message did not decode: {e}"))
}

/// The model a worker holds, with its weights.
struct Held {
    id: u64,
    original: Original,
    weights: Option<Vec<f32>>,
}

/// A worker's state: the model it holds, and the one it opened last until the page asks it
/// to hold that. Requests come one at a time and each is done whole.
#[derive(Default)]
pub struct Worker {
    held: Option<Held>,
    opened: Option<Original>,
}

impl Worker {
    /// Does `request`; `clock` gives milliseconds, `tell` takes the replies sent before the
    /// answer ([`Reply::Progress`]). Hold and Weights answer nothing.
    pub fn handle(
        &mut self,
        request: Request,
        clock: &dyn Fn() -> f64,
        tell: &mut dyn FnMut(Reply),
    ) -> Option<Reply> {
        match request {
            Request::Load { job, name, input } => Some(self.load(job, &name, input, clock, tell)),
            Request::Hold { model, mesh } => {
                let original = match self.opened.take() {
                    Some(o) if *o.mesh() == mesh => o,
                    _ => Original::new(&mesh, &Topology::build(&mesh)),
                };
                self.held = Some(Held {
                    id: model,
                    original,
                    weights: None,
                });
                None
            }
            Request::Weights { model, weights, .. } => {
                if let Some(held) = self.held.as_mut().filter(|h| h.id == model) {
                    held.weights = weights;
                }
                None
            }
            // The student's viewer smooths the structure shown (its measures and how far it
            // moved), but searches and checks nothing: its build has neither.
            Request::Terms { job, .. }
            | Request::SuggestStructure { job, .. }
            | Request::CheckCase { job, .. }
                if !crate::AUTHORING =>
            {
                Some(Reply::Failed {
                    job,
                    why: "the viewer searches and checks nothing".into(),
                })
            }
            Request::Smooth { job, params, tau } => Some(self.smooth(job, &params, tau, clock)),
            Request::Terms { job, params, at } => Some(self.terms(job, &params, &at, clock)),
            Request::SuggestStructure {
                job,
                mesh,
                params,
                weights,
                options,
                starts,
            } => Some(suggest_structure(
                job, mesh, params, weights, &options, &starts,
            )),
            Request::CheckCase { job, case } => Some(check_case(job, &case, clock)),
        }
    }

    fn load(
        &mut self,
        job: u64,
        name: &str,
        input: Input,
        clock: &dyn Fn() -> f64,
        tell: &mut dyn FnMut(Reply),
    ) -> Reply {
        let mut stages: Vec<(String, f64)> = Vec::new();
        let mut began = clock();
        let mut on_stage = |stage: model::Stage| {
            let now = clock();
            if let Some(last) = stages.last_mut() {
                last.1 = now - began;
            }
            began = now;
            stages.push((stage.doing.to_string(), 0.0));
            tell(Reply::Progress {
                job,
                stage: stage.index as u32,
                stages: stage.total as u32,
                doing: stage.doing.to_string(),
            });
        };
        let opened = match input {
            Input::Files(files) => {
                let named: Vec<NamedBytes> = (files.iter())
                    .map(|f| NamedBytes {
                        name: &f.name,
                        bytes: &f.bytes,
                    })
                    .collect();
                (model::open_files(&named, &mut on_stage))
                    .map(|o| (Some(o.model), Some(o.case)))
                    .map_err(|e| e.reason())
            }
            Input::Add(bytes) => (model::open_case(name, &bytes, &mut on_stage))
                .map(|case| (None, Some(case)))
                .map_err(|e| e.reason()),
            Input::Structure(mesh) => {
                Ok((Some(model::open_structure(name, mesh, &mut on_stage)), None))
            }
            Input::Image { .. } if !crate::AUTHORING => {
                Err(format!("{name}: the viewer opens no image"))
            }
            Input::Image {
                files,
                preset,
                grids,
            } => {
                on_stage(model::Stage {
                    index: 0,
                    total: 1,
                    doing: "reading the image",
                });
                read_image(name, &files, &preset, &grids).map(|case| (None, Some(case)))
            }
        };
        let ended = clock();
        if let Some(last) = stages.last_mut() {
            last.1 = ended - began;
        }
        match opened {
            Ok((model, case)) => {
                if let Some(model) = &model {
                    self.opened = Some(model.original.clone());
                }
                Reply::Loaded {
                    job,
                    model: model.map(Box::new),
                    case: case.map(Box::new),
                    stages,
                }
            }
            Err(why) => Reply::Failed { job, why },
        }
    }

    fn smooth(&self, job: u64, params: &Params, tau: f64, clock: &dyn Fn() -> f64) -> Reply {
        let Some(held) = &self.held else {
            return no_model(job);
        };
        let start = clock();
        let (positions, reference) =
            metrics::smooth_drifting(&held.original, params, held.weights.as_deref());
        let smoothed = clock();
        let (measured, vertex) =
            metrics::measure_vertices(&held.original, &positions, &reference, tau);
        let measure_ms = clock() - smoothed;
        Reply::Smoothed {
            job,
            positions,
            metrics: serde_json::to_string(&measured).unwrap_or_default(),
            vertex,
            smooth_ms: smoothed - start,
            measure_ms,
        }
    }

    fn terms(&self, job: u64, params: &Params, at: &[u32], clock: &dyn Fn() -> f64) -> Reply {
        let Some(held) = &self.held else {
            return no_model(job);
        };
        let start = clock();
        match MeshEvaluator::new(&held.original, held.weights.as_deref()) {
            Ok(mut evaluator) => Reply::Terms {
                job,
                terms: evaluator.measure(params, at).unwrap_or_default(),
                ms: clock() - start,
            },
            Err(e) => Reply::Failed {
                job,
                why: e.to_string(),
            },
        }
    }
}

/// One structure's part of "Suggest all", as the CLI's `case build` does it.
fn suggest_structure(
    job: u64,
    mesh: Mesh,
    params: Params,
    weights: Option<Vec<f32>>,
    options: &SuggestAllOptions,
    starts: &[Params],
) -> Reply {
    let mut structure = CaseStructure::from_mesh("", mesh, [1.0; 3]);
    structure.set_params(params);
    structure.set_weights(weights);
    match case::suggest_structure(&mut structure, options, starts, &mut |_| true) {
        Ok(suggestion) => {
            let suggested = suggestion.zip(structure.smoothed).map(|(s, smoothed)| {
                Box::new(StructureSuggestion {
                    params: s.params,
                    evaluations: s.evaluations,
                    positions: smoothed.positions,
                    metrics: serde_json::to_string(&smoothed.metrics).unwrap_or_default(),
                    local_error: smoothed.local_error.unwrap_or_default(),
                })
            });
            Reply::Suggested { job, suggested }
        }
        Err(e) => Reply::Failed {
            job,
            why: e.to_string(),
        },
    }
}

/// The checks between a case's structures, as the CLI's `case build` reports them.
fn check_case(job: u64, case: &Case, clock: &dyn Fn() -> f64) -> Reply {
    let start = clock();
    let mut trees = case::relations::TreeShapes::default();
    let before = case::check_refitting(case, false, &mut trees);
    let after = case::check_refitting(case, true, &mut trees);
    let changes = case::relations::changes(&before, &after);
    let mut report = case::checks_json(case, &after, &changes);
    report["text"] = case::checks_text(case, &before, &after, &changes).into();
    let mut flagged: Vec<usize> = (changes.left_inside.iter())
        .chain(&changes.new_crossings)
        .flat_map(|&(a, b)| [a, b])
        .collect();
    flagged.sort_unstable();
    flagged.dedup();
    report["flagged"] = flagged.into();
    let marks = case::check_marks(case, &before, &changes);
    report["marked_vertices"] = marks.iter().map(Vec::len).collect::<Vec<_>>().into();
    report["ms"] = (clock() - start).into();
    Reply::Checked {
        job,
        report: report.to_string(),
        marks,
    }
}

fn no_model(job: u64) -> Reply {
    Reply::Failed {
        job,
        why: "the worker holds no model".to_string(),
    }
}

/// Milliseconds from a fixed moment, for the timings the replies carry.
#[cfg(not(target_arch = "wasm32"))]
pub fn clock_ms() -> f64 {
    static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
        * 1000.0
}

/// Milliseconds from a fixed moment (wasm32 has no `Instant`; this works in workers too).
#[cfg(target_arch = "wasm32")]
pub fn clock_ms() -> f64 {
    js_sys::Date::now()
}

/// [`Reply::Smoothed`]'s metrics back from JSON.
pub fn metrics_of(json: &str) -> Result<Metrics, String> {
    serde_json::from_str(json).map_err(|e| format!("a worker's measures did not decode: {e}"))
}

/// A case holding only the image `name` ([`Input::Image`]): one file, or the slices of a
/// DICOM series.
fn read_image(
    name: &str,
    files: &[NamedFile],
    preset: &str,
    grids: &[case::StructureGrid],
) -> Result<Case, String> {
    let preset = (case::WindowPreset::from_name(preset))
        .ok_or_else(|| format!("{name}: no window preset named {preset:?}"))?;
    let files: Vec<(&str, &[u8])> = (files.iter())
        .map(|f| (f.name.as_str(), f.bytes.as_slice()))
        .collect();
    let most = case::DEFAULT_IMAGE_VOXELS;
    let image = case::CaseImage::read(&files, name, preset, most, grids)?;
    Ok(Case {
        image: Some(std::sync::Arc::new(image)),
        ..Case::default()
    })
}

#[cfg(test)]
mod tests;
