//! The document the app and its embedding API edit, free of any UI, so the browser app, its
//! JavaScript API and the native tests drive the same state the same way: the open case and
//! which of its structures is the model (`structures`, `case`, `models`), the files being
//! opened by the workers (`opening`), the CPU engine's runs (`cpu`), the background work that
//! guides the author (`guidance`: graphs, suggestion, gallery; `suggest_all`; `checks`), and
//! the colours and pointing the view asks for (`colors`, `pointing`).
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
mod checks;
mod colors;
mod cpu;
mod guidance;
mod models;
mod opening;
mod pointing;
mod structures;
mod suggest_all;
mod weights;

pub use crate::model::{Model, OpenFailure};
pub use colors::{shared_error_colors, ColorField, Legend, LegendTick};
pub use guidance::{Activity, GalleryPick, Suggested, GALLERY_TAUS};
pub use opening::LoadProgress;
pub use structures::{OtherStructure, StructureChange};
pub use weights::WeightsSummary;

use crate::case::{Case, CaseStructure, Smoothed, DEFAULT_FILTER};
use crate::export::{self, ExportFormat, ExportOptions};
use crate::mesh::{vertex_normals, Mesh};
use crate::smooth::{Filter, Params};
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

/// Nothing open: the parameters the controls show.
const NO_PARAMS: Params = Params::defaults(DEFAULT_FILTER);

/// The open case, which structure is the model, and the engines and background work on it.
pub struct Session {
    /// The open case: every structure opened, as the author arranges them, each with its
    /// settings and result; the model is structure `current`'s surface (empty: nothing open).
    case: Case,
    /// The file the case was opened from.
    case_file: String,
    current: usize,
    /// Counts changes of the case's structures, for the view.
    case_version: u64,
    /// The models of the structures selected so far (the current one always among them).
    models: models::Models,
    /// Counts what the model is smoothed with and which structure it is; see the module docs.
    revision: u64,
    /// Counts the models opened, so background results of another model are told apart.
    model_id: u64,
    /// Counts changes of the model's weights (the GPU engine uploads them once per change).
    weights_version: u64,
    /// The CPU engine: its workers, and the smoothing of the revision asked of them.
    cpu: Pool,
    cpu_job: Option<(u64, SmoothJob)>,
    /// Why the last file could not be opened; cleared by the next successful open.
    error: Option<String>,
    guidance: guidance::Guidance,
    /// A file the CPU engine's workers are opening.
    opening: Option<opening::Opening>,
    /// How long each stage of the latest opening took (ms), in order.
    open_stages: Vec<(String, f64)>,
    /// Files to add to the case once the one opening now is open.
    additions: std::collections::VecDeque<(String, Vec<u8>)>,
    suggest_all: suggest_all::SuggestAll,
    checks: checks::Checks,
    /// Whether a newly opened model gets a suggestion search (not in the viewer, which shows
    /// no suggestion).
    suggest_on_open: bool,
}

impl Default for Session {
    fn default() -> Self {
        Self {
            case: Case::default(),
            case_file: String::new(),
            current: 0,
            case_version: 0,
            models: Default::default(),
            revision: 0,
            model_id: 0,
            weights_version: 0,
            cpu: Pool::in_thread(1),
            cpu_job: None,
            error: None,
            guidance: guidance::Guidance::default(),
            opening: None,
            open_stages: Vec::new(),
            additions: Default::default(),
            suggest_all: Default::default(),
            checks: Default::default(),
            suggest_on_open: true,
        }
    }
}

impl Session {
    pub fn model(&self) -> Option<&Model> {
        self.models.get(self.current)
    }

    /// The structure that is the model, where its settings and result live.
    fn structure(&self) -> Option<&CaseStructure> {
        self.model()?;
        self.case.structures.get(self.current)
    }

    /// [`Self::structure`] to change: what it is smoothed with changes, so the revision does.
    fn structure_mut(&mut self) -> Option<&mut CaseStructure> {
        self.model()?;
        self.revision += 1;
        self.case.structures.get_mut(self.current)
    }

    /// Counts the models opened: it changes when another model (file or structure) opens.
    pub fn model_id(&self) -> u64 {
        self.model_id
    }

    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    pub fn filter(&self) -> Filter {
        self.params().filter
    }

    /// The model's filter and parameters (the defaults with nothing open).
    pub fn params(&self) -> &Params {
        self.structure().map_or(&NO_PARAMS, |s| &s.params)
    }

    pub fn tau(&self) -> f64 {
        self.structure().map_or(DEFAULT_TAU, |s| s.tau)
    }

    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The voxel size of the segmentation the model came from (mm), when known.
    pub fn voxel_size(&self) -> Option<[f64; 3]> {
        self.structure()?.voxel_size
    }

    /// The voxel diagonal (mm) when the voxel size is known.
    pub fn voxel_diagonal(&self) -> Option<f64> {
        self.structure()?.voxel_diagonal()
    }

    /// The model's result with its per-vertex measures, if it is for the current parameters.
    pub fn result(&self) -> Option<&Smoothed> {
        let s = self.structure()?;
        s.smoothed_now().filter(|r| r.vertex_measures().is_some())
    }

    /// The model's latest result with its per-vertex measures even if the parameters changed
    /// since (shown until the new one lands).
    pub fn last_result(&self) -> Option<&Smoothed> {
        let s = self.structure()?;
        s.smoothed
            .as_ref()
            .filter(|r| r.vertex_measures().is_some())
    }

    /// Whether a model is open whose result for the current parameters is still to compute.
    pub fn needs_smoothing(&self) -> bool {
        self.model().is_some() && self.result().is_none()
    }

    /// Structure `current` (its model built) became the model: what was asked or found for
    /// the one before is dropped.
    fn became_model(&mut self) {
        self.error = None;
        self.revision += 1;
        self.model_id += 1;
        self.cpu_job = None;
        self.weights_version += 1;
        self.reset_guidance();
        // A suggestion for the new model, ready to apply with one click.
        if self.suggest_on_open {
            self.queue_suggest(crate::suggest::SearchMethod::Local);
        }
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

    /// Makes `filter` active (with the values it had when last active).
    pub fn set_filter(&mut self, filter: Filter) {
        if filter != self.filter() {
            if let Some(s) = self.structure_mut() {
                s.set_filter(filter);
            }
        }
    }

    /// [`Self::set_filter`] by name (`laplace taubin hc sinc`).
    pub fn set_filter_name(&mut self, name: &str) -> Result<(), String> {
        let filter = Filter::from_name(name)
            .ok_or_else(|| format!("unknown filter '{name}': use laplace, taubin, hc or sinc"))?;
        self.set_filter(filter);
        Ok(())
    }

    /// Sets the parameters of `params.filter` (and makes it active), if they are valid.
    pub fn set_params(&mut self, params: Params) -> Result<(), String> {
        params.validate().map_err(|e| e.to_string())?;
        if params != *self.params() {
            self.structure_mut()
                .ok_or("no mesh is open")?
                .set_params(params);
        }
        Ok(())
    }

    /// Applies a JSON object of parameter values to the active filter (see
    /// [`Params::with_json`]); all or nothing.
    pub fn set_params_json(&mut self, values: &serde_json::Value) -> Result<(), String> {
        let params = self.params().with_json(values)?;
        self.set_params(params)
    }

    /// The score's weight `tau` in [0, 1].
    pub fn set_tau(&mut self, tau: f64) -> Result<(), String> {
        if !(0.0..=1.0).contains(&tau) {
            return Err(format!("tau = {tau} is out of range: [0, 1]"));
        }
        if tau != self.tau() {
            self.structure_mut().ok_or("no mesh is open")?.set_tau(tau);
        }
        Ok(())
    }

    /// The voxel size (mm per voxel along x, y, z) of the segmentation the model came from,
    /// or `None` when unknown.
    pub fn set_voxel_size(&mut self, size: Option<[f64; 3]>) -> Result<(), String> {
        if let Some(v) = size {
            if !v.iter().all(|s| s.is_finite() && *s > 0.0) {
                return Err(format!("voxel size {v:?} must be three lengths > 0 mm"));
            }
        }
        self.model().ok_or("no mesh is open")?;
        let s = &mut self.case.structures[self.current];
        if s.voxel_size != size {
            s.voxel_size = size;
            self.case_version += 1;
        }
        Ok(())
    }

    /// The mesh report of the open model as the CLI's `info --json` prints it.
    pub fn info_json(&self) -> Option<serde_json::Value> {
        self.model()
            .and_then(|m| serde_json::to_value(&m.report).ok())
    }

    /// The current result's measures as the CLI's `measure --json` prints them.
    pub fn metrics_json(&self) -> Option<serde_json::Value> {
        self.result()
            .and_then(|r| serde_json::to_value(&r.metrics).ok())
    }

    /// Per-vertex colours of `field` on the latest result (the weights: as painted now), with
    /// the legend that explains them.
    pub fn colors(&self, field: ColorField) -> Option<(Vec<[u8; 4]>, Legend)> {
        let model = self.model()?;
        if field == ColorField::Weights {
            let n = model.mesh().vertex_count();
            return Some(colors::weight_colors(self.weights(), n));
        }
        let result = self.last_result()?;
        Some(colors::colorize(
            field,
            &model.mesh().positions,
            result,
            self.voxel_diagonal(),
        ))
    }

    /// The smoothed mesh (the original while nothing is smoothed) in `format`: normals, the
    /// given colours and, in GLB `extras`, the filter, parameters and measures. Nothing of the
    /// input file's header is written.
    pub fn export(
        &self,
        format: ExportFormat,
        colors: Option<&[[u8; 4]]>,
    ) -> Result<Vec<u8>, String> {
        let model = self.model().ok_or("no mesh is open")?;
        let triangles = model.mesh().triangles.clone();
        let (mesh, extras) = match self.last_result() {
            Some(r) => (
                Mesh::new(r.positions.clone(), triangles),
                Some(export::smoothing_extras(self.params(), &r.metrics)),
            ),
            None => (model.mesh().clone(), None),
        };
        let normals = vertex_normals(&mesh.positions, &mesh.triangles);
        let options = ExportOptions {
            normals: Some(&normals),
            colors,
            extras,
            millimetres: false,
        };
        export::write(&mesh, format, &options).map_err(|e| e.to_string())
    }

    /// What the embedding API's `state()` reports.
    pub fn state_json(&self, busy: bool) -> serde_json::Value {
        let model = self.model();
        serde_json::json!({
            "model": model.map(|m| m.name.as_str()),
            "vertices": model.map(|m| m.report.vertices),
            "faces": model.map(|m| m.report.faces),
            "error": self.error,
            "filter": self.filter().name(),
            "params": self.params().to_json(),
            "tau": self.tau(),
            "busy": busy,
            "cpu_engine": self.cpu.to_json(),
            "weights": self.weights_summary(),
            "structures": self.structures_json(),
            "loading": self.loading().map(|l| serde_json::json!({
                "name": l.name, "stage": l.stage, "stages": l.total, "doing": l.doing,
            })),
            "open_stages": self.open_stages().iter()
                .map(|(doing, ms)| serde_json::json!({"doing": doing, "ms": ms}))
                .collect::<Vec<_>>(),
        })
    }
}

#[cfg(test)]
mod tests;
