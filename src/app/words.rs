//! The case in the words the page shows it in: a structure's name, a label's text and note in
//! the reader's language where the page is read (the viewer, the author's preview), else the
//! author's own ([`crate::case::names`] picks).

use crate::case::{CaseStructure, Label};

/// The open case's structures and the languages to show them in (none: the author's words).
#[derive(Clone, Copy)]
pub struct Words<'a> {
    pub structures: &'a [CaseStructure],
    pub languages: &'a [String],
}

impl<'a> Words<'a> {
    /// Structure `index`'s name ("" past the last).
    pub fn name(&self, index: usize) -> &'a str {
        let Some(s) = self.structures.get(index) else {
            return "";
        };
        crate::case::names::pick(&s.name, &s.names, self.languages)
    }

    /// A lesson label's text: one naming its structure says the structure's name
    /// ([`crate::case::names::label_text`]).
    pub fn label_text(&self, label: &'a Label) -> &'a str {
        let Some(s) = self.structures.iter().find(|s| s.name == label.structure) else {
            return &label.text;
        };
        let text = (label.text.as_str(), &label.texts);
        crate::case::names::label_text(text, (&s.name, &s.names), self.languages)
    }

    /// A lesson label's note.
    pub fn label_note(&self, label: &'a Label) -> &'a str {
        crate::case::names::pick(&label.note, &label.notes, self.languages)
    }
}
