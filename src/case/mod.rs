//! The case: the document an author edits and a student opens. A title, a description and an
//! ordered list of structures (liver, vessels, tumour), each with its own filter, parameters
//! and measures, smoothed independently and written as one glTF.
//!
//! Layout: the document here; opening files as a case in `from_files` (a folder's listing in
//! `folder`); smoothing and "Suggest all" in `pipeline`; the quality record the glTF carries
//! (and reads back) in `record`; checks between structures in `relations`; the tour, labels and
//! quiz in `lesson`, and what a student did with them as xAPI statements in `xapi`.

mod checks;
mod clip;
mod folder;
mod from_files;
mod image;
mod image_frame;
mod lesson;
pub mod names;
mod pipeline;
mod record;
pub mod relations;
mod suggest_all;
mod voxel_grid;
pub mod xapi;

pub use checks::{check, check_marks, check_refitting, checks_json, checks_text};
pub use clip::{Clip, ClipAxis, Planes};
pub use folder::{
    folder_order, read_in_folder, EntryKind, FolderListing, FOLDER_DEPTH, FOLDER_ENTRIES,
};
pub use from_files::{
    file_name, first_structure_file, open, open_staged, reading_stages, split_color_table,
    surface_structure, CaseOpenError,
};
pub use image::{CaseImage, Window, WindowPreset, DEFAULT_IMAGE_VOXELS};
pub use image_frame::{check_frame, StructureGrid};
pub use lesson::{Camera, Label, Lesson, Quiz, QuizMode, Step};
pub use pipeline::smooth_structure;
pub use record::{from_gltf_scene, structure_record, CaseRecordError, CASE_KEY};
pub use suggest_all::{
    starts_from, suggest_all, suggest_structure, SuggestAllOptions, SuggestAllPlan,
    SuggestAllProgress, SuggestAllSearch, SuggestJob, DEFAULT_MAX_VOLUME_CHANGE, LEARNING_BATCH,
    LEARNING_LAG,
};

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::io::{Affine, StructureCodes};
use crate::mesh::Mesh;
use crate::metrics::Metrics;
use crate::segmentation::Structure;
use crate::smooth::{Filter, Params};

/// The filter structures start with: Laplace+HC keeps volume best on staircase surfaces.
pub const DEFAULT_FILTER: Filter = Filter::Hc;

/// A case: what one glTF holds. It travels between the page and its engine workers too.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Case {
    pub title: String,
    pub description: String,
    pub structures: Vec<CaseStructure>,
    /// The image the segmentation was drawn on, shown under the surfaces; shared, not
    /// copied, when the case is cloned.
    #[serde(default)]
    pub image: Option<Arc<CaseImage>>,
    /// The tour, labels and quiz a student goes through.
    #[serde(default)]
    pub lesson: Lesson,
}

/// One structure of a case. Two are equal when they would be written the same: the memory of
/// other filters and the revision count are the editor's, not the case's.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseStructure {
    pub name: String,
    /// Its name in other languages, by language tag (see [`names`]).
    #[serde(default)]
    pub names: names::Names,
    /// Display (sRGB) colour and opacity, each in [0, 1].
    pub color: [f32; 4],
    pub visible: bool,
    /// The group the structure is listed under ("Vessels"), if any.
    pub group: Option<String>,
    /// What a reader is told about it (its anatomy, why it matters in this case); may be empty.
    pub description: String,
    /// The name of the file it came from (never anything of the file's header).
    pub source: Option<String>,
    /// Its label value, when it came from a label map.
    pub label: Option<i64>,
    /// Voxel size along i, j, k (mm), when it came from a label map.
    pub voxel_size: Option<[f64; 3]>,
    /// Its voxels in the label map (after dropping specks), when it came from one.
    pub voxels: Option<usize>,
    /// The voxel grid it was extracted on, when it came from a label map: its original's
    /// vertices lie at the grid's edge midpoints, which a quantized file's reader snaps to.
    pub grid: Option<Affine>,
    /// What it is in standard codes (SNOMED CT), when its source or its name says.
    pub codes: Option<StructureCodes>,
    /// The surface as opened (the staircase of a label map), in world millimetres.
    pub original: Mesh,
    /// The structure's own filter and parameters, bound included.
    pub params: Params,
    /// Target smoothness its parameters were suggested for, and its score weight.
    pub tau: f64,
    /// Per-vertex weights (0 locks a vertex); `None` = all 1.
    pub weights: Option<Vec<f32>>,
    /// The latest smoothing; it is the result of the settings above while
    /// [`Self::smoothed_now`] gives it, and shown until a newer one replaces it.
    pub smoothed: Option<Smoothed>,
    /// Each other filter's parameters as last set, so choosing it again brings them back.
    #[serde(skip)]
    pub other_params: Vec<Params>,
    /// Counts the changes of its filter, parameters, tau and weights; a smoothed surface
    /// records the count it was made for.
    #[serde(skip)]
    pub revision: u64,
}

/// A structure's smoothed surface and its measures against the original; equal when they
/// would be written the same.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Smoothed {
    #[serde(with = "crate::mesh::flat_bytes")]
    pub positions: Vec<[f32; 3]>,
    #[serde(with = "crate::metrics::as_json_text")]
    pub metrics: Metrics,
    /// Per-vertex local error (mm), when measured here (a reopened case may lack it).
    pub local_error: Option<Vec<f32>>,
    /// Per-vertex Gaussian curvature, when measured here (a case glTF does not keep it).
    #[serde(skip)]
    pub curvature: Option<Vec<f32>>,
    /// The structure's [`CaseStructure::revision`] it was made for.
    #[serde(skip)]
    pub revision: u64,
}

impl PartialEq for CaseStructure {
    fn eq(&self, o: &Self) -> bool {
        (self.name == o.name
            && self.names == o.names
            && self.color == o.color
            && self.visible == o.visible)
            && (self.group == o.group && self.description == o.description)
            && (self.source == o.source && self.label == o.label)
            && (self.voxel_size == o.voxel_size && self.voxels == o.voxels && self.grid == o.grid)
            && self.codes == o.codes
            && (self.original == o.original && self.params == o.params && self.tau == o.tau)
            && (self.weights == o.weights && self.smoothed == o.smoothed)
    }
}

impl PartialEq for Smoothed {
    fn eq(&self, o: &Self) -> bool {
        self.positions == o.positions
            && self.metrics == o.metrics
            && self.local_error == o.local_error
    }
}

impl Smoothed {
    /// A smoothed surface and its measures; the per-vertex ones where they were measured.
    pub fn new(positions: Vec<[f32; 3]>, metrics: Metrics, local_error: Option<Vec<f32>>) -> Self {
        Self {
            positions,
            metrics,
            local_error,
            curvature: None,
            revision: 0,
        }
    }

    /// The per-vertex local error and curvature, when both were measured here.
    pub fn vertex_measures(&self) -> Option<(&[f32], &[f32])> {
        Some((self.local_error.as_deref()?, self.curvature.as_deref()?))
    }
}

impl CaseStructure {
    /// A structure from a surface, with the default filter and no bound.
    pub fn from_mesh(name: &str, mesh: Mesh, color: [f32; 3]) -> Self {
        Self {
            name: name.to_string(),
            names: names::Names::new(),
            color: [color[0], color[1], color[2], 1.0],
            visible: true,
            group: None,
            description: String::new(),
            source: None,
            label: None,
            voxel_size: None,
            grid: None,
            codes: None,
            voxels: None,
            original: mesh,
            params: Params::defaults(DEFAULT_FILTER),
            tau: 0.5,
            weights: None,
            smoothed: None,
            other_params: Vec::new(),
            revision: 0,
        }
    }

    /// A structure extracted from a label map: it knows its voxel size, so it smooths with the
    /// displacement bound at half its voxel diagonal (Gibson's constraint: the true boundary
    /// lies within that distance of the staircase), which keeps thin structures whole.
    pub fn from_label_map(structure: Structure, source: Option<&str>) -> Self {
        let mut s = Self::from_mesh(&structure.name, structure.mesh, structure.color);
        s.source = source.map(str::to_string);
        s.label = Some(structure.label);
        s.voxel_size = Some(structure.voxel_size);
        s.voxels = Some(structure.voxels);
        s.grid = Some(structure.grid);
        s.codes = structure.codes;
        s.params.max_displacement = s.default_bound();
        s
    }

    /// Half the voxel diagonal (mm), the default bound of a label-map structure.
    pub fn default_bound(&self) -> Option<f32> {
        self.voxel_diagonal().map(|d| (0.5 * d) as f32)
    }

    /// The voxel diagonal (mm), the unit its errors are also reported in.
    pub fn voxel_diagonal(&self) -> Option<f64> {
        self.voxel_size
            .map(|s| s.iter().map(|v| v * v).sum::<f64>().sqrt())
    }

    /// Makes `filter` the active one: with the parameters it had when last active, else its
    /// defaults with the bound kept.
    pub fn set_filter(&mut self, filter: Filter) {
        if filter == self.params.filter {
            return;
        }
        let remembered = self.other_params.iter().position(|p| p.filter == filter);
        let params = remembered.map_or_else(
            || Params {
                max_displacement: self.params.max_displacement,
                ..Params::defaults(filter)
            },
            |i| self.other_params[i],
        );
        self.set_params(params);
    }

    /// Sets the filter and parameters (checked by the caller); the filter left keeps its
    /// parameters for when it is chosen again.
    pub fn set_params(&mut self, params: Params) {
        if params == self.params {
            return;
        }
        if params.filter != self.params.filter {
            self.other_params
                .retain(|p| p.filter != params.filter && p.filter != self.params.filter);
            self.other_params.push(self.params);
        }
        self.params = params;
        self.revision += 1;
    }

    /// Sets the score's weight tau (checked by the caller).
    pub fn set_tau(&mut self, tau: f64) {
        if tau != self.tau {
            self.tau = tau;
            self.revision += 1;
        }
    }

    /// Sets the per-vertex weights (`None`: all 1).
    pub fn set_weights(&mut self, weights: Option<Vec<f32>>) {
        self.weights = weights;
        self.revision += 1;
    }

    /// Keeps `smoothed` as the result of the structure's settings now.
    pub fn keep(&mut self, smoothed: Smoothed) {
        self.smoothed = Some(Smoothed {
            revision: self.revision,
            ..smoothed
        });
    }

    /// The smoothed surface when it is the result of the structure's settings now.
    pub fn smoothed_now(&self) -> Option<&Smoothed> {
        (self.smoothed.as_ref()).filter(|m| m.revision == self.revision)
    }

    /// The surface as its settings make it: smoothed when it has been, else the original.
    pub fn surface(&self) -> Mesh {
        match self.smoothed_now() {
            Some(s) => Mesh::new(s.positions.clone(), self.original.triangles.clone()),
            None => self.original.clone(),
        }
    }

    /// Whether its surface is closed and wound outward, so that from outside only its front
    /// faces can be seen: a label map's structure (closed by construction) enclosing a positive
    /// volume.
    pub fn closed_outward(&self) -> bool {
        self.label.is_some() && self.original.signed_volume() > 0.0
    }

    /// The positions as shown: the latest smoothing until a newer one replaces it.
    pub fn positions(&self) -> &[[f32; 3]] {
        match &self.smoothed {
            Some(s) => &s.positions,
            None => &self.original.positions,
        }
    }
}

impl Case {
    /// A case of the structures of a label map named `source`.
    pub fn from_label_map(structures: Vec<Structure>, source: Option<&str>) -> Self {
        Self {
            structures: structures
                .into_iter()
                .map(|s| CaseStructure::from_label_map(s, source))
                .collect(),
            ..Self::default()
        }
    }

    /// Adds the structures of another case (another file opened into this one).
    pub fn add(&mut self, other: Case) {
        if self.title.is_empty() {
            self.title = other.title;
        }
        if self.description.is_empty() {
            self.description = other.description;
        }
        if self.image.is_none() {
            self.image = other.image;
        }
        if self.lesson.is_empty() {
            self.lesson = other.lesson;
        }
        self.structures.extend(other.structures);
    }

    /// The structures' names, in the case's order.
    pub fn names(&self) -> Vec<&str> {
        self.structures.iter().map(|s| s.name.as_str()).collect()
    }

    /// The structures' groups in the order they first appear.
    pub fn groups(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for g in self.structures.iter().filter_map(|s| s.group.as_deref()) {
            if !out.contains(&g) {
                out.push(g);
            }
        }
        out
    }
}

/// The structures as a list shows them: the ungrouped ones, then each group's, groups in
/// the order they first appear; only those whose name (in any of its languages) or group
/// contains `filter` (any case), and no group left empty by it.
pub fn listed<'a>(
    structures: &'a [CaseStructure],
    filter: &str,
) -> Vec<(Option<&'a str>, Vec<usize>)> {
    let filter = filter.trim().to_lowercase();
    let matches = |text: &str| text.to_lowercase().contains(&filter);
    let mut listed: Vec<(Option<&str>, Vec<usize>)> = vec![(None, Vec::new())];
    for (i, s) in structures.iter().enumerate() {
        let group = s.group.as_deref();
        let named = matches(&s.name) || s.names.values().any(|n| matches(n));
        if !filter.is_empty() && !named && !group.is_some_and(matches) {
            continue;
        }
        match listed.iter_mut().find(|(g, _)| *g == group) {
            Some((_, rows)) => rows.push(i),
            None => listed.push((group, vec![i])),
        }
    }
    listed.retain(|(_, rows)| !rows.is_empty());
    listed
}

#[cfg(test)]
mod tests;
