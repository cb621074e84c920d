//! The case document: the open case, which of its structures is the model, and the settings
//! and result of that structure, read and written where they live (its entry in the case).
//! Selecting another structure moves a pointer; each structure's model (topology and the
//! original's measures) is built once and cached (`models`).

use super::colors::{self, ColorField, Legend};
use super::{models, Model, DEFAULT_TAU};
use crate::case::{Case, CaseStructure, Smoothed, DEFAULT_FILTER};
use crate::export::{self, ExportFormat, ExportOptions};
use crate::mesh::{vertex_normals, Mesh};
use crate::smooth::{Filter, Params};

/// Nothing open: the parameters the controls show.
const NO_PARAMS: Params = Params::defaults(DEFAULT_FILTER);

/// The open case and which structure is the model.
#[derive(Default)]
pub struct CaseDocument {
    /// Every structure opened, as the author arranges them, each with its settings and
    /// result; the model is structure `current`'s surface (empty: nothing open).
    pub(super) case: Case,
    /// The file the case was opened from.
    pub(super) case_file: String,
    pub(super) current: usize,
    /// Counts changes of the case's structures, for the view.
    pub(super) case_version: u64,
    /// The models of the structures selected so far (the current one always among them).
    pub(super) models: models::Models,
    /// Counts what the model is smoothed with and which structure it is; see the session's
    /// module docs.
    pub(super) revision: u64,
    /// Counts the models opened, so background results of another model are told apart.
    pub(super) model_id: u64,
    /// Counts changes of the model's weights (the GPU engine uploads them once per change).
    pub(super) weights_version: u64,
    /// A structure the file holds no smoothing of is shown as the file holds it (the viewer:
    /// a student sees only what the file holds), not smoothed with its default settings.
    pub(super) as_read: bool,
}

impl CaseDocument {
    pub fn model(&self) -> Option<&Model> {
        self.models.get(self.current)
    }

    /// The structure that is the model, where its settings and result live.
    pub(super) fn structure(&self) -> Option<&CaseStructure> {
        self.model()?;
        self.case.structures.get(self.current)
    }

    /// [`Self::structure`] to change: what it is smoothed with changes, so the revision does.
    pub(super) fn structure_mut(&mut self) -> Option<&mut CaseStructure> {
        self.model()?;
        self.revision += 1;
        self.case.structures.get_mut(self.current)
    }

    /// Counts the models opened: it changes when another model (file or structure) opens.
    pub fn model_id(&self) -> u64 {
        self.model_id
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
        self.model().is_some() && self.result().is_none() && !self.shown_as_read(self.current)
    }

    /// Shows structures the file holds no smoothing of as it holds them, from now on.
    pub fn show_as_read(&mut self, on: bool) {
        self.as_read = on;
    }

    /// Whether structure `index` is shown as its file holds it: no smoothing of its own, in a
    /// document that does not smooth such structures.
    pub fn shown_as_read(&self, index: usize) -> bool {
        self.as_read && (self.case.structures.get(index)).is_some_and(|s| s.smoothed.is_none())
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
    /// input file's header is written. Refused while the result is of parameters since changed,
    /// so that a file never states parameters its surface was not made with.
    pub fn export(
        &self,
        format: ExportFormat,
        colors: Option<&[[u8; 4]]>,
    ) -> Result<Vec<u8>, String> {
        let model = self.model().ok_or("no mesh is open")?;
        let triangles = model.mesh().triangles.clone();
        if self.result().is_none() && self.last_result().is_some() {
            return Err("the surface for the current parameters is still being computed".into());
        }
        let (mesh, extras) = match self.result() {
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

    /// Structure `current` (its model built) became the model.
    pub(super) fn became_model(&mut self) {
        self.revision += 1;
        self.model_id += 1;
        self.weights_version += 1;
    }

    /// Keeps a result measured for `revision` as the model's; false, keeping nothing, when
    /// the document moved on since or the arrays do not fit the model.
    pub(super) fn keep_result(&mut self, revision: u64, result: Smoothed) -> bool {
        let Some(model) = self.model() else {
            return false;
        };
        let n = model.mesh().vertex_count();
        let fits = result.positions.len() == n
            && result.local_error.as_ref().is_some_and(|e| e.len() == n)
            && result.curvature.as_ref().is_some_and(|c| c.len() == n);
        if revision != self.revision || !fits {
            return false;
        }
        let structure = &mut self.case.structures[self.current];
        let mut result = result;
        // A surface the structure already holds for these settings (a case file's, quantized;
        // a search's) stays the one shown and written: the engine's recomputation brings its
        // per-vertex measures, made on a surface within the file's stated quantization error.
        if let Some(held) = (structure.smoothed.take())
            .filter(|h| h.revision == structure.revision && h.vertex_measures().is_none())
            .filter(|h| h.positions.len() == n)
        {
            result.positions = held.positions;
        }
        structure.keep(result);
        true
    }
}
