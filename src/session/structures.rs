//! The open case's structures as the author arranges them: each one's name, colour, opacity,
//! visibility and group, and which one is the model. Each keeps its own smoothing, so the view
//! shows every structure smoothed its own way and selecting one again finds it as it was.

use super::{CaseDocument, Model};
use crate::case::names::{self, Names};
use crate::case::{Case, CaseStructure};
use crate::io::{self, Format};
use crate::mesh::Mesh;
use crate::metrics::Metrics;
use crate::model;
use crate::segmentation::default_color;
use crate::smooth::Params;

/// What [`CaseDocument::set_structure`] changes; `None` leaves a field as it is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StructureChange {
    pub name: Option<String>,
    /// Display (sRGB) colour, each in [0, 1].
    pub color: Option<[f32; 3]>,
    pub opacity: Option<f32>,
    pub visible: Option<bool>,
    /// `Some(None)` takes the structure out of its group.
    pub group: Option<Option<String>>,
    pub description: Option<String>,
    /// Its names in other languages, all of them (see [`crate::case::names`]).
    pub names: Option<Names>,
}

/// A structure drawn around the model.
pub struct OtherStructure<'a> {
    pub index: usize,
    pub positions: &'a [[f32; 3]],
    pub triangles: &'a [[u32; 3]],
    /// Display (sRGB) colour and opacity.
    pub color: [f32; 4],
    /// Closed and wound outward (see [`CaseStructure::closed_outward`]).
    pub closed: bool,
}

impl CaseDocument {
    /// Which structure the model is, while one is open.
    pub fn current_structure(&self) -> Option<usize> {
        self.model().map(|_| self.current)
    }

    /// The name of the file the case was opened from.
    pub fn case_file(&self) -> &str {
        &self.case_file
    }

    /// Counts the changes of the structures (their looks, what they keep, how many), for the
    /// view.
    pub fn case_version(&self) -> u64 {
        self.case_version
    }

    /// The structure that is the model.
    pub fn model_structure(&self) -> Option<&CaseStructure> {
        self.case.structures.get(self.current_structure()?)
    }

    /// The surface the model's structure has for the current parameters without the
    /// per-vertex measures (a case glTF's, a "Suggest all" result), shown while the engine
    /// measures it.
    pub fn kept_surface(&self) -> Option<&[[f32; 3]]> {
        let s = self.structure()?;
        let kept = s.smoothed_now()?;
        (kept.positions.len() == s.original.positions.len()).then_some(&kept.positions[..])
    }

    /// Makes structure `index` the model: its model is built here the first time (then kept),
    /// and its settings and result are where they were. Whether it changed the model; errors
    /// as [`Self::model_to_build`].
    pub(super) fn select(&mut self, index: usize) -> Result<bool, String> {
        if let Some((name, mesh)) = self.model_to_build(index)? {
            let built = model::open_structure(&name, mesh.clone(), &mut |_| {});
            return Ok(self.select_built(index, built));
        }
        if index == self.current {
            return Ok(false);
        }
        self.models.touch(index);
        self.current = index;
        self.became_model();
        Ok(true)
    }

    /// What making structure `index` the model takes: `None` when it is the model or its
    /// model is kept, else the name and the surface to build its model from. Errors when
    /// nothing is open or the case has no such structure.
    pub(super) fn model_to_build(&self, index: usize) -> Result<Option<(String, &Mesh)>, String> {
        if self.model().is_none() {
            return Err("nothing is open".to_string());
        }
        let count = self.case.structures.len();
        let Some(structure) = self.case.structures.get(index) else {
            return Err(format!(
                "structure {index} does not exist: the case has {count}"
            ));
        };
        if index == self.current || self.models.get(index).is_some() {
            return Ok(None);
        }
        let name = format!("{}: {}", self.case_file, structure.name);
        Ok(Some((name, &structure.original)))
    }

    /// Makes structure `index` the model with `model`, built from its surface (by a worker);
    /// false, keeping nothing, when the case has no such surface there now.
    pub(super) fn select_built(&mut self, index: usize, model: Model) -> bool {
        let fits = (self.case.structures.get(index)).is_some_and(|s| s.original == *model.mesh());
        if fits {
            self.models.keep(index, model);
            self.current = index;
            self.became_model();
        }
        fits
    }

    /// Changes structure `index`'s name, colour, opacity, visibility, group, description or
    /// names in other languages; all or nothing.
    pub fn set_structure(&mut self, index: usize, change: StructureChange) -> Result<(), String> {
        let count = self.case.structures.len();
        let s = self
            .case
            .structures
            .get_mut(index)
            .ok_or_else(|| format!("structure {index} does not exist: there are {count}"))?;
        let (mut name, mut color, mut visible, mut group) =
            (s.name.clone(), s.color, s.visible, s.group.clone());
        if let Some(new) = change.name {
            let new = new.trim();
            if new.is_empty() {
                return Err("a structure's name cannot be empty".to_string());
            }
            name = new.to_string();
        }
        if let Some(c) = change.color {
            if !c.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(format!("colour {c:?}: each channel must be in [0, 1]"));
            }
            color[..3].copy_from_slice(&c);
        }
        if let Some(opacity) = change.opacity {
            if !(0.0..=1.0).contains(&opacity) {
                return Err(format!("opacity {opacity}: must be in [0, 1]"));
            }
            color[3] = opacity;
        }
        if let Some(v) = change.visible {
            visible = v;
        }
        if let Some(g) = change.group {
            group = g.map(|g| g.trim().to_string()).filter(|g| !g.is_empty());
        }
        let description = (change.description.as_deref())
            .map_or_else(|| s.description.clone(), |d| d.trim().to_string());
        let names = match &change.names {
            Some(n) => names::checked(n).map_err(|e| format!("structure '{}': {e}", s.name))?,
            None => s.names.clone(),
        };
        let was = (&s.name, s.color, s.visible, &s.group, &s.description);
        if was != (&name, color, visible, &group, &description) || s.names != names {
            let old = std::mem::replace(&mut s.name, name);
            (s.color, s.visible, s.group) = (color, visible, group);
            (s.description, s.names) = (description, names);
            // The lesson names structures: it follows a rename.
            let new = &self.case.structures[index].name;
            self.case.lesson.rename(&old, new);
            self.case_version += 1;
        }
        Ok(())
    }

    /// Shows structure `index` alone (or, when it already is alone, every structure again).
    pub fn solo_structure(&mut self, index: usize) -> Result<(), String> {
        let list = &mut self.case.structures;
        if index >= list.len() {
            return Err(format!("structure {index} does not exist"));
        }
        let alone = list
            .iter()
            .enumerate()
            .all(|(i, s)| s.visible == (i == index));
        for (i, s) in list.iter_mut().enumerate() {
            s.visible = alone || i == index;
        }
        self.case_version += 1;
        Ok(())
    }

    /// The visible structures other than the model, as they were last smoothed (else as
    /// opened).
    pub fn other_structures(&self) -> Vec<OtherStructure<'_>> {
        let current = self.current_structure();
        (self.case.structures.iter().enumerate())
            .filter(|(i, s)| Some(*i) != current && s.visible)
            .map(|(index, s)| OtherStructure {
                index,
                positions: s.positions(),
                triangles: &s.original.triangles,
                color: s.color,
                closed: s.closed_outward(),
            })
            .collect()
    }

    /// Makes `case` (opened from `file`, the first of its files `first_file`) the open case, its
    /// first structure (with `model` built) the model.
    pub(super) fn adopt(&mut self, case: Case, file: &str, first_file: &str, model: Model) {
        // A bare surface has no settings of its own: it keeps the ones the user was trying.
        // Label maps and case glTFs bring each structure's own.
        let own_settings = io::is_label_map(first_file)
            || matches!(
                Format::from_name(first_file),
                Some(Format::Glb | Format::Gltf)
            );
        let before = (self.structure()).filter(|_| !own_settings).map(|s| {
            // Half the last structure's voxel diagonal was a bound for its voxels, not this
            // surface's.
            let voxels = s.default_bound();
            let unbound = |mut p: Params| {
                if voxels.is_some() && p.max_displacement == voxels {
                    p.max_displacement = None;
                }
                p
            };
            let others = s.other_params.iter().copied().map(unbound).collect();
            (unbound(s.params), others, s.tau)
        });
        self.case = case;
        self.case_file = file.to_string();
        self.current = 0;
        self.models.clear();
        self.models.keep(0, model);
        if let (Some((params, others, tau)), Some(s)) = (before, self.case.structures.first_mut()) {
            s.set_params(params);
            s.other_params = others;
            s.set_tau(tau);
        }
        self.case_version += 1;
        self.became_model();
    }

    /// Adds the structures of `other` (another file) to the open case. Surfaces, which carry
    /// no colour of their own, get the palette's colour of their place in the case.
    pub(super) fn add(&mut self, other: Case) {
        let start = self.case.structures.len();
        let mut other = other;
        for (i, s) in other.structures.iter_mut().enumerate() {
            if s.label.is_none() && s.smoothed.is_none() && s.voxel_size.is_none() {
                let [r, g, b] = default_color(start + i);
                s.color = [r, g, b, s.color[3]];
            }
        }
        self.case.add(other);
        self.case_version += 1;
    }

    /// The image under the surfaces from now on (`None`: none).
    pub(super) fn set_image(&mut self, image: Option<std::sync::Arc<crate::case::CaseImage>>) {
        self.case.image = image;
        self.case_version += 1;
    }

    /// Structure `index`'s measures as shown: the model's current result's, another's kept
    /// ones; `None` where it is not smoothed (or the model's result is still to come).
    pub fn structure_metrics(&self, index: usize) -> Option<&Metrics> {
        if Some(index) == self.current_structure() {
            self.result().map(|r| &r.metrics)
        } else {
            let s = self.case.structures.get(index)?;
            s.smoothed_now().map(|k| &k.metrics)
        }
    }
}
