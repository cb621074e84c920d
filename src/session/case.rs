//! The open model as a case: a title and description, and the case glTF of every structure of
//! its segmentation as the author arranged and smoothed it (a mesh alone is a case of one).

use super::{Kept, Session};
use crate::case::{Case, CaseStructure};
use crate::export::{self, CaseGltfOptions, Container};
use crate::segmentation::default_color;

impl Session {
    pub fn case_title(&self) -> &str {
        &self.case_text.0
    }

    pub fn case_description(&self) -> &str {
        &self.case_text.1
    }

    /// Sets the case's title and description (`None` keeps one as it is).
    pub fn set_case_text(&mut self, title: Option<&str>, description: Option<&str>) {
        if let Some(title) = title {
            self.case_text.0 = title.trim().to_string();
        }
        if let Some(description) = description {
            self.case_text.1 = description.trim().to_string();
        }
    }

    /// The case as it stands: each structure with its name, colour, opacity and visibility, its
    /// filter and parameters, and its smoothed surface where it was smoothed (the model's
    /// current result, the others' kept ones). `None` without a model.
    pub fn to_case(&self) -> Option<Case> {
        let model = self.model.as_ref()?;
        let take = |s: &mut CaseStructure, kept: Kept| {
            s.params = kept.params;
            s.tau = kept.tau;
            s.weights = kept.weights;
            s.smoothed = kept.smoothed;
        };
        let current = |s: &mut CaseStructure| take(s, self.model_smoothing());
        let structures = match &model.structures {
            None => {
                let mut s =
                    CaseStructure::from_mesh(&model.name, model.mesh().clone(), default_color(0));
                s.source = Some(model.name.clone());
                current(&mut s);
                vec![s]
            }
            Some(list) => (list.list.iter().zip(&self.looks).enumerate())
                .map(|(i, (structure, look))| {
                    let mut s = CaseStructure::from_label_map(structure.clone(), Some(&list.file));
                    s.name = look.name.clone();
                    s.color = look.color;
                    s.visible = look.visible;
                    if i == list.current {
                        current(&mut s);
                    } else if let Some(kept) = &look.kept {
                        take(&mut s, kept.clone());
                    }
                    s
                })
                .collect(),
        };
        Some(Case {
            title: self.case_text.0.clone(),
            description: self.case_text.1.clone(),
            structures,
        })
    }

    /// The case glTF (`.glb`, or `.gltf` with its buffer embedded): metres with +Y up, each
    /// smoothed structure with its original as a morph target and its local error.
    pub fn export_case(&self, container: Container) -> Result<Vec<u8>, String> {
        let case = self.to_case().ok_or("no mesh is open")?;
        let options = CaseGltfOptions {
            container,
            local_error: true,
            ..CaseGltfOptions::default()
        };
        export::write_case(&case, &options).map_err(|e| e.to_string())
    }
}
