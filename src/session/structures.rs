//! The structures of an open segmentation as the author arranges them: each one's name, colour,
//! opacity and visibility, and its smoothing kept while another structure is the model, so the
//! view shows every structure smoothed its own way and coming back to one restores it.

use super::{Session, Structures};
use crate::case::Smoothed;
use crate::segmentation::Structure;
use crate::smooth::Params;

/// How a structure is shown, and what it was smoothed with.
#[derive(Clone, Debug, PartialEq)]
pub struct StructureLook {
    pub name: String,
    /// Display (sRGB) colour and opacity, each in [0, 1].
    pub color: [f32; 4],
    pub visible: bool,
    /// Its smoothing, kept when another structure became the model.
    pub kept: Option<Kept>,
}

/// A structure's smoothing while it is not the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Kept {
    pub params: Params,
    pub tau: f64,
    pub weights: Option<Vec<f32>>,
    /// The smoothed surface and its measures, when it had been smoothed.
    pub smoothed: Option<Smoothed>,
}

/// What [`Session::set_structure`] changes; `None` leaves a field as it is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StructureChange {
    pub name: Option<String>,
    /// Display (sRGB) colour, each in [0, 1].
    pub color: Option<[f32; 3]>,
    pub opacity: Option<f32>,
    pub visible: Option<bool>,
}

/// A structure drawn around the model.
pub struct OtherStructure<'a> {
    pub index: usize,
    pub positions: &'a [[f32; 3]],
    pub triangles: &'a [[u32; 3]],
    /// Display (sRGB) colour and opacity.
    pub color: [f32; 4],
}

impl StructureLook {
    fn of(structure: &Structure) -> Self {
        let [r, g, b] = structure.color;
        Self {
            name: structure.name.clone(),
            color: [r, g, b, 1.0],
            visible: true,
            kept: None,
        }
    }
}

impl Session {
    /// How each structure of the open segmentation is shown (empty without one).
    pub fn structure_looks(&self) -> &[StructureLook] {
        &self.looks
    }

    /// Counts the changes of how the structures look or what they keep, for the view.
    pub fn looks_version(&self) -> u64 {
        self.looks_version
    }

    /// The look of the structure that is the model, when it is one.
    pub fn model_look(&self) -> Option<&StructureLook> {
        self.looks.get(self.structures()?.current)
    }

    /// Changes structure `index`'s name, colour, opacity or visibility; all or nothing.
    pub fn set_structure(&mut self, index: usize, change: StructureChange) -> Result<(), String> {
        let count = self.looks.len();
        let look = self
            .looks
            .get(index)
            .ok_or_else(|| format!("structure {index} does not exist: there are {count}"))?;
        let mut look = look.clone();
        if let Some(name) = change.name {
            let name = name.trim();
            if name.is_empty() {
                return Err("a structure's name cannot be empty".to_string());
            }
            look.name = name.to_string();
        }
        if let Some(color) = change.color {
            if !color.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(format!("colour {color:?}: each channel must be in [0, 1]"));
            }
            look.color[..3].copy_from_slice(&color);
        }
        if let Some(opacity) = change.opacity {
            if !(0.0..=1.0).contains(&opacity) {
                return Err(format!("opacity {opacity}: must be in [0, 1]"));
            }
            look.color[3] = opacity;
        }
        if let Some(visible) = change.visible {
            look.visible = visible;
        }
        if self.looks[index] != look {
            self.looks[index] = look;
            self.looks_version += 1;
        }
        Ok(())
    }

    /// Shows structure `index` alone (or, when it already is alone, every structure again).
    pub fn solo_structure(&mut self, index: usize) -> Result<(), String> {
        if index >= self.looks.len() {
            return Err(format!("structure {index} does not exist"));
        }
        let alone = self
            .looks
            .iter()
            .enumerate()
            .all(|(i, l)| l.visible == (i == index));
        for (i, look) in self.looks.iter_mut().enumerate() {
            look.visible = alone || i == index;
        }
        self.looks_version += 1;
        Ok(())
    }

    /// The visible structures other than the model, as they were last smoothed (else as
    /// extracted).
    pub fn other_structures(&self) -> Vec<OtherStructure<'_>> {
        let Some(structures) = self.structures() else {
            return Vec::new();
        };
        (structures.list.iter().zip(&self.looks).enumerate())
            .filter(|(i, (_, look))| *i != structures.current && look.visible)
            .map(|(index, (s, look))| {
                let smoothed = look.kept.as_ref().and_then(|k| k.smoothed.as_ref());
                OtherStructure {
                    index,
                    positions: smoothed.map_or(&s.mesh.positions, |k| &k.positions),
                    triangles: &s.mesh.triangles,
                    color: look.color,
                }
            })
            .collect()
    }

    /// Looks for the structures of a segmentation just opened from its file.
    pub(super) fn reset_looks(&mut self) {
        // A "Suggest all" of the structures before is of no use now.
        self.cancel_suggest_all();
        self.suggest_all = Default::default();
        self.looks = self
            .structures()
            .map(|s| s.list.iter().map(StructureLook::of).collect())
            .unwrap_or_default();
        self.looks_version += 1;
    }

    /// The model's smoothing as a structure keeps it: what a case structure takes too.
    pub(super) fn model_smoothing(&self) -> Kept {
        Kept {
            params: *self.params(),
            tau: self.tau,
            weights: self.weights.clone(),
            smoothed: self.result().map(|r| Smoothed {
                positions: r.positions.clone(),
                metrics: r.metrics.clone(),
                local_error: Some(r.vertex.local_error.clone()),
            }),
        }
    }

    /// Keeps the model's smoothing in its structure's look, before another structure opens.
    pub(super) fn keep_model_structure(&mut self) {
        let Some(current) = self.structures().map(|s| s.current) else {
            return;
        };
        let kept = self.model_smoothing();
        if let Some(look) = self.looks.get_mut(current) {
            look.kept = Some(kept);
            self.looks_version += 1;
        }
    }

    /// Restores what the structure that just became the model kept, if anything.
    pub(super) fn restore_model_structure(&mut self) {
        let Some(current) = self.structures().map(|s| s.current) else {
            return;
        };
        let Some(kept) = self.looks.get_mut(current).and_then(|l| l.kept.take()) else {
            return;
        };
        self.looks_version += 1;
        // Values it was smoothed with were valid then; a refusal leaves the defaults.
        let _ = self.set_params(kept.params);
        let _ = self.set_tau(kept.tau);
        if kept.weights.is_some() {
            self.weights = kept.weights;
            self.weights_version += 1;
        }
    }

    /// The structures of the open segmentation for `state()` and the page's API: what each is,
    /// how it is shown and, where it was smoothed, its measures.
    pub fn structures_json(&self) -> Option<serde_json::Value> {
        let structures: &Structures = self.structures()?;
        let mut json = structures.to_json();
        let list = json["structures"].as_array_mut()?;
        for (i, (entry, look)) in list.iter_mut().zip(&self.looks).enumerate() {
            entry["name"] = look.name.clone().into();
            entry["color"] = serde_json::json!([look.color[0], look.color[1], look.color[2]]);
            entry["opacity"] = look.color[3].into();
            entry["visible"] = look.visible.into();
            let metrics = if i == structures.current {
                self.result().map(|r| &r.metrics)
            } else {
                look.kept
                    .as_ref()
                    .and_then(|k| k.smoothed.as_ref())
                    .map(|k| &k.metrics)
            };
            entry["metrics"] = serde_json::to_value(metrics).unwrap_or_default();
        }
        Some(json)
    }
}

impl StructureChange {
    /// `{index, name, color: [r, g, b], opacity, visible}` as the page's `setStructure` takes
    /// it (every key optional; `index` defaults to the model's structure). Unknown keys and
    /// values of the wrong kind are refused, naming the key.
    pub fn from_json(value: &serde_json::Value) -> Result<(Option<usize>, Self), String> {
        let object = value
            .as_object()
            .ok_or("setStructure takes an object: {index, name, color, opacity, visible}")?;
        let mut change = Self::default();
        let mut index = None;
        for (key, v) in object {
            let wrong = |what: &str| format!("setStructure: {key} must be {what}, not {v}");
            match key.as_str() {
                "index" => {
                    let i = v.as_u64().ok_or_else(|| wrong("a whole number >= 0"))?;
                    index = Some(usize::try_from(i).map_err(|_| wrong("a structure's index"))?);
                }
                "name" => change.name = Some(v.as_str().ok_or_else(|| wrong("a string"))?.into()),
                "color" => {
                    let c: Vec<f32> = (v.as_array().into_iter().flatten())
                        .filter_map(|c| c.as_f64().map(|c| c as f32))
                        .collect();
                    let rgb: [f32; 3] =
                        c.try_into().map_err(|_| wrong("three numbers in [0, 1]"))?;
                    change.color = Some(rgb);
                }
                "opacity" => {
                    change.opacity = Some(v.as_f64().ok_or_else(|| wrong("a number"))? as f32)
                }
                "visible" => {
                    change.visible = Some(v.as_bool().ok_or_else(|| wrong("true or false"))?)
                }
                other => {
                    return Err(format!(
                        "setStructure: unknown key {other} (index, name, color, opacity, visible)"
                    ))
                }
            }
        }
        Ok((index, change))
    }
}
