//! The open case as a document: its title and description, and its case glTF of every
//! structure as the author arranged and smoothed it (a mesh alone is a case of one).

use super::CaseDocument;

use crate::case::{Case, Lesson};
use crate::export::{self, CaseGltfOptions};

impl CaseDocument {
    /// The case itself, read-only: its title, description, image and structures (its edits
    /// go through this document).
    pub fn as_case(&self) -> &Case {
        &self.case
    }

    /// The tour, labels and quiz the case carries.
    pub fn lesson(&self) -> &Lesson {
        &self.case.lesson
    }

    /// Replaces the case's lesson, when it names only structures the case has and holds
    /// nothing a viewer cannot show ([`Lesson::check`]).
    pub fn set_lesson(&mut self, lesson: Lesson) -> Result<(), String> {
        lesson.check(&self.case)?;
        self.case.lesson = lesson;
        self.case_version += 1;
        Ok(())
    }

    /// Sets the case's title and description (`None` keeps one as it is).
    pub fn set_case_text(&mut self, title: Option<&str>, description: Option<&str>) {
        if let Some(title) = title {
            self.case.title = title.trim().to_string();
        }
        if let Some(description) = description {
            self.case.description = description.trim().to_string();
        }
    }

    /// The case as it stands: each structure with its name, colour, opacity, visibility and
    /// group, its filter and parameters, and its smoothed surface where it has one for them
    /// (the model's while its result is still to come: none). `None` without a model.
    pub fn to_case(&self) -> Option<Case> {
        self.current_structure()?;
        let mut case = self.case.clone();
        for s in &mut case.structures {
            if s.smoothed_now().is_none() {
                s.smoothed = None;
            }
        }
        Some(case)
    }

    /// The case glTF with `options`: metres with +Y up, each smoothed structure with its
    /// original as a morph target.
    pub fn export_case(&self, options: &CaseGltfOptions) -> Result<Vec<u8>, String> {
        let case = self.to_case().ok_or("no mesh is open")?;
        export::write_case(&case, options).map_err(|e| e.to_string())
    }
}
