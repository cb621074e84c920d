//! The case in words, for screen readers: egui draws on a canvas that assistive technology
//! cannot read, so the page keeps the canvas's label, a list of the structures and a list of
//! what the lesson shows (the tour's step and caption, the labels drawn, the quiz's question
//! and answer, read out as they change), hidden from sight, up to date with the case. Element
//! ids match `index.html`.

use super::document::Document;

const CANVAS_ID: &str = "meshsmooth_canvas";
const LIST_ID: &str = "case_structures";
const LESSON_ID: &str = "case_lesson";

/// What the page's words were last written for: the structures' version, the selected one,
/// whether the author previews (names in the reader's language), the case's file and title.
#[derive(Default)]
pub struct CaseText {
    written: Option<(u64, Option<usize>, bool, String, String)>,
    /// The lesson's lines last written.
    lesson: Vec<String>,
}

impl CaseText {
    /// Rewrites the canvas's label and the structures' list where the case changed.
    pub fn update(&mut self, doc: &Document) {
        let session = doc.session();
        let (version, current) = (
            session.case().case_version(),
            session.case().current_structure(),
        );
        let (file, title) = (
            session.case().case_file(),
            session.case().as_case().title.as_str(),
        );
        if let Some((v, c, p, f, t)) = &self.written {
            let now = (version, current, doc.previewing, file, title);
            if (*v, *c, *p, f.as_str(), t.as_str()) == now {
                return;
            }
        }
        let (file, title) = (file.to_string(), title.to_string());
        self.written = Some((version, current, doc.previewing, file, title));
        let words = (label(doc), lines(doc));
        let Some(document) = web_sys::window().and_then(|w| w.document()) else {
            return;
        };
        if let Some(canvas) = document.get_element_by_id(CANVAS_ID) {
            let _ = canvas.set_attribute("aria-label", &words.0);
        }
        write_list(LIST_ID, &words.1);
    }

    /// Rewrites the lesson's list where what it shows changed.
    pub fn update_lesson(&mut self, doc: &Document) {
        let lines = lesson_lines(doc);
        if lines != self.lesson {
            write_list(LESSON_ID, &lines);
            self.lesson = lines;
        }
    }
}

/// Replaces the items of the list `id` with `lines`.
fn write_list(id: &str, lines: &[String]) {
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    if let Some(list) = document.get_element_by_id(id) {
        list.set_inner_html("");
        for line in lines {
            if let Ok(item) = document.create_element("li") {
                item.set_text_content(Some(line));
                let _ = list.append_child(&item);
            }
        }
    }
}

/// The tour's step with its caption, the labels drawn, the quiz's question, its choices and
/// the answer's outcome.
fn lesson_lines(doc: &Document) -> Vec<String> {
    let mut lines = Vec::new();
    let steps = &doc.session().case().lesson().steps;
    let lesson = doc.session().case().lesson();
    let shown = doc
        .tour
        .and_then(|i| Some((i, lesson.step_text(i, doc.words().languages)?)));
    if let Some((i, (title, caption))) = shown {
        let mut line = format!("Tour step {} of {}: {title}.", i + 1, steps.len());
        if !caption.is_empty() {
            line.push_str(&format!(" {caption}"));
        }
        lines.push(line);
    }
    for label in &doc.view.labels {
        let behind = if label.faded {
            " (behind a surface)"
        } else {
            ""
        };
        let note = match label.note.is_empty() {
            true => String::new(),
            false => format!(". Note: {}", label.note),
        };
        lines.push(format!("Label: {}{behind}{note}", label.text));
    }
    let words = doc.quiz_words();
    if !words.heading.is_empty() {
        lines.push(format!("{}. {}", words.heading, words.question));
        let choices = (doc.quiz.as_ref().and_then(|r| r.current()))
            .map(|(_, q)| q.choices.iter().map(|&c| doc.words().name(c)))
            .map(|c| c.collect::<Vec<_>>().join(", "))
            .filter(|c| !c.is_empty());
        if let Some(choices) = choices {
            lines.push(format!("Choices: {choices}."));
        }
        if let Some((_, outcome)) = words.outcome {
            lines.push(outcome);
        }
    }
    lines
}

/// The canvas's label: what the view shows.
fn label(doc: &Document) -> String {
    let session = doc.session();
    let structures = session.case().as_case().structures.as_slice();
    let shown = structures.iter().filter(|s| s.visible).count();
    let title = session.case().as_case().title.as_str();
    let what = if title.is_empty() {
        session.case().case_file()
    } else {
        title
    };
    let mut text = format!(
        "3D view of {what}: {} structures, {shown} shown",
        structures.len()
    );
    if let Some(i) = session.case().current_structure() {
        text.push_str(&format!("; selected: {}", doc.words().name(i)));
    }
    text
}

/// One line per structure: its name, group, whether it is shown and how opaque, whether it is
/// selected, and its description.
fn lines(doc: &Document) -> Vec<String> {
    let current = doc.session().case().current_structure();
    (doc.session().case().as_case().structures.iter().enumerate())
        .map(|(i, s)| {
            let mut line = doc.words().name(i).to_string();
            if let Some(group) = &s.group {
                line.push_str(&format!(" ({group})"));
            }
            line.push_str(if s.visible { ", shown" } else { ", hidden" });
            if s.visible && s.color[3] < 1.0 {
                line.push_str(&format!(", {:.0}% opaque", s.color[3] * 100.0));
            }
            if Some(i) == current {
                line.push_str(", selected");
            }
            if !s.description.is_empty() {
                line.push_str(&format!(": {}", s.description));
            }
            line
        })
        .collect()
}
