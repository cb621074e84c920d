//! The document the app and its embedding API edit, free of any UI, so the browser app, its
//! JavaScript API and the native tests drive the same state the same way: the open case and
//! which of its structures is the model (`case_document`, `structures`, `case`, `models`),
//! the files being opened by the workers (`opening`), the CPU engine's runs (`cpu`), the
//! background work that guides the author (`guidance`: graphs, suggestion, gallery;
//! `suggest_all`; `checks`), the case glTF written a structure at a time (`case_export`), and
//! the colours the view asks for (`colors`).
//!
//! Each structure's filter, parameters, tau, weights and result live in the case, and only
//! there: the getters and setters here read and write the structure that is the model.
//! Selecting another structure moves a pointer; the session caches each structure's model
//! (topology and the original's measures) so coming back finds it built.
//!
//! Every change (a new model, filter or parameter) bumps `revision`; a result belongs to the
//! revision it was computed for, so a result that arrives late (from the GPU) for an older
//! revision is refused and the measures shown always match the parameters shown.

mod case;
mod case_document;
mod case_export;
mod checks;
mod colors;
mod cpu;
mod guidance;
mod models;
mod opening;
mod structures;
mod suggest_all;
mod weights;

pub use crate::model::{Model, OpenFailure};
pub use case_document::CaseDocument;
pub use case_export::{CaseExportMut, CaseExportOf, ExportProgress, WrittenCase};
pub use colors::{shared_error_colors, ColorField, Legend, LegendTick};
pub use guidance::{Activity, GalleryPick, Suggested, GALLERY_TAUS};
pub use opening::{LoadProgress, Openings, BUILT_ELSEWHERE_ABOVE};
pub use structures::{OtherStructure, StructureChange};
pub use suggest_all::{structure_work, StructureOutcome, SuggestAllReport};
pub use weights::{Dab, WeightsSummary};

use crate::worker::{Pool, SmoothJob};

/// The score's default weight (ALGORITHMS.md: `tau` in [0, 1], default 0.5).
pub const DEFAULT_TAU: f64 = 0.5;

/// How long a result took, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Smoothing, with the drifting reference's updates.
    pub smooth_ms: f64,
    /// The measure pass with the per-vertex measures.
    pub measure_ms: f64,
}

/// The background work on the open case, read: the guidance's graphs, suggestion and gallery
/// (`guidance`), "Suggest all" (`suggest_all`) and the checks between structures (`checks`).
/// The session starts, steps and stops it, lending it its engines.
pub struct Background<'a> {
    doc: &'a CaseDocument,
    guidance: &'a guidance::Guidance,
    suggest_all: &'a suggest_all::SuggestAll,
    checks: &'a checks::Checks,
}

/// The open case document, the engines that smooth its model and the background work that
/// guides its author.
pub struct Session {
    doc: CaseDocument,
    /// The CPU engine: its workers, and the smoothing of the revision asked of them.
    cpu: Pool,
    cpu_job: Option<(u64, SmoothJob)>,
    /// Why the last file could not be opened; cleared by the next successful open.
    error: Option<String>,
    guidance: guidance::Guidance,
    /// A file the CPU engine's workers are opening.
    opening: Option<opening::WorkerOpening>,
    /// How the files asked to open ended.
    openings: opening::Openings,
    /// How long each stage of the latest opening took (ms), in order.
    open_stages: Vec<(String, f64)>,
    /// Files to add to the case once the one opening now is open.
    additions: std::collections::VecDeque<(String, Vec<u8>)>,
    suggest_all: suggest_all::SuggestAll,
    checks: checks::Checks,
    case_export: case_export::CaseExport,
    /// Whether a newly opened model gets a suggestion search (not in the viewer, which shows
    /// no suggestion).
    suggest_on_open: bool,
}

impl Default for Session {
    fn default() -> Self {
        Self {
            doc: CaseDocument::default(),
            cpu: Pool::in_thread(1),
            cpu_job: None,
            error: None,
            guidance: guidance::Guidance::default(),
            opening: None,
            openings: Default::default(),
            open_stages: Vec::new(),
            additions: Default::default(),
            suggest_all: Default::default(),
            checks: Default::default(),
            case_export: Default::default(),
            suggest_on_open: true,
        }
    }
}

impl Session {
    /// The open case, its model and the model's settings and result.
    pub fn case(&self) -> &CaseDocument {
        &self.doc
    }

    /// The case document to edit: the structures' looks, the model's settings and weights.
    pub fn case_mut(&mut self) -> &mut CaseDocument {
        &mut self.doc
    }

    /// The background work on the case and what it found.
    pub fn background(&self) -> Background<'_> {
        Background {
            doc: &self.doc,
            guidance: &self.guidance,
            suggest_all: &self.suggest_all,
            checks: &self.checks,
        }
    }

    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Another structure became the model: what was asked or found for the one before is
    /// dropped.
    fn became_model(&mut self) {
        self.error = None;
        self.cpu_job = None;
        self.reset_guidance();
        // A suggestion for the new model, ready to apply with one click.
        if self.suggest_on_open {
            self.queue_suggest(crate::suggest::SearchMethod::Local);
        }
    }

    /// Makes structure `index` of the open case the model (see [`CaseDocument`]: a pointer
    /// moves, nothing is reopened). The first time, its model is built: a large structure's
    /// by a worker, as a file opens ([`Self::loading`] tells how far, [`Self::selecting`]
    /// which), the model before staying until it is there; else at once. Errors when nothing
    /// is open or it has no such structure.
    pub fn select_structure(&mut self, index: usize) -> Result<(), String> {
        if self.selecting() == Some(index) {
            return Ok(());
        }
        if let Some((name, mesh)) = self.doc.model_to_build(index)? {
            if self.builds_elsewhere(mesh) {
                let mesh = mesh.clone();
                self.begin_select(index, name, mesh);
                return Ok(());
            }
        }
        self.drop_selecting();
        if self.doc.select(index)? {
            self.became_model();
        }
        Ok(())
    }

    /// Whether each model opened from now on gets a suggestion search at once.
    pub fn set_suggest_on_open(&mut self, on: bool) {
        self.suggest_on_open = on;
    }

    /// Records that `name` could not be opened because of `reason`; returns the message.
    pub fn fail(&mut self, name: &str, reason: &str) -> String {
        let message = format!("Cannot open {name}: {reason}");
        self.error = Some(message.clone());
        message
    }
}

#[cfg(test)]
pub(crate) mod testing;
#[cfg(test)]
mod tests;
