//! The authoring page's Lesson panel: the tour's steps recorded from the view as it stands,
//! their titles and captions edited, reordered, deleted and shown again; labels placed by
//! clicking a structure in the view, their texts and notes edited; the quiz's modes, structures
//! and pass mark; and "Export for LMS" (see `lms_export`). Titles, captions, texts and notes are edited in the own (English) words or in
//! another language the author picks. Every edit goes through `CaseDocument::set_lesson`, which
//! checks it against the case.

use eframe::egui;
use glam::Vec3;

use super::document::Document;
use crate::case::names::{self, Names};
use crate::case::{Label, Lesson, Quiz, QuizMode};
use crate::export::lms::LmsFormat;
use crate::view::recorded_step;

impl Document {
    /// Adds the view as it stands as the tour's last step; returns the number of steps.
    pub fn record_step(&mut self, title: &str, caption: &str) -> Result<usize, String> {
        let names = self.session().case().as_case().names();
        let step = recorded_step(&self.view_link(), &names, title, caption)?;
        let mut lesson = self.session().case().lesson().clone();
        lesson.steps.push(step);
        let steps = lesson.steps.len();
        self.session_mut().case_mut().set_lesson(lesson)?;
        Ok(steps)
    }

    /// Adds a label on structure `index` at `point` (where the author clicked it), its text
    /// the structure's name until edited.
    pub fn place_label(&mut self, index: usize, point: Vec3) -> Result<(), String> {
        let name = (self.session().case().as_case().structures.get(index))
            .map(|s| s.name.clone())
            .ok_or(format!("the case has no structure {index}"))?;
        let mut lesson = self.session().case().lesson().clone();
        lesson
            .labels
            .push(Label::new(&name, point.to_array(), &name));
        self.session_mut().case_mut().set_lesson(lesson)
    }

    /// Back from the preview to authoring: a quiz taken there ends (it asked nothing of the case).
    pub fn end_preview(&mut self) {
        self.previewing = false;
        self.end_quiz();
    }
}

/// What the panel's controls asked this frame besides edits of the lesson itself.
#[derive(Default)]
struct Asked {
    record: bool,
    show_step: Option<usize>,
    /// Whether a control changed the lesson (the panel's copy of it then replaces the case's).
    edited: bool,
}

/// The Lesson panel.
pub fn show(ui: &mut egui::Ui, doc: &mut Document) {
    // The panel edits a copy: every edit must pass the case's checks before it lands.
    let mut lesson = doc.session().case().lesson().clone();
    // What of the panel is in sight: its controls below scroll into view.
    let mut drawn: Vec<(String, egui::Rect)> = vec![("in-sight".into(), ui.clip_rect())];
    let mut asked = Asked::default();
    let preview = ui.button("Preview as the student sees it");
    drawn.push(("preview".into(), preview.rect));
    if preview.clicked() {
        doc.previewing = true;
        doc.placing_label = false;
        ui.ctx().request_repaint();
    }
    ui.separator();
    let record = ui.button("Record the view as a step");
    drawn.push(("record".into(), record.rect));
    asked.record = record.clicked();
    let language = language(ui, &lesson, &mut doc.lesson_language, &mut drawn);
    // While the field holds no language, nothing is edited: not the English words by mistake.
    let editing = match &language {
        Ok(None) => Editing::Own,
        Ok(Some(tag)) => Editing::In(tag),
        Err(()) => Editing::Nothing,
    };
    steps(ui, &mut lesson, editing, &mut drawn, &mut asked);
    ui.separator();
    let place = ui.toggle_value(&mut doc.placing_label, "Place a label");
    drawn.push(("place-label".into(), place.rect));
    if doc.placing_label {
        ui.small("Click a structure in the view where the label points.");
    }
    labels(ui, &mut lesson, editing, &mut drawn, &mut asked);
    ui.separator();
    let names = doc.session().case().as_case().names();
    quiz(ui, &mut lesson, &names, &mut drawn, &mut asked);
    ui.separator();
    let lms = export_for_lms(ui, &mut drawn);
    (doc.panel.lesson).extend(drawn.into_iter().map(|(k, r)| (k, r.into())));
    if asked.edited {
        if let Err(e) = doc.session_mut().case_mut().set_lesson(lesson) {
            // An emptied title or text: the edit waits for a non-empty one.
            log::info!("lesson edit refused: {e}");
        }
    }
    if asked.record {
        let n = doc.session().case().lesson().steps.len() + 1;
        if let Err(e) = doc.record_step(&format!("Step {n}"), "") {
            log::warn!("{e}");
        }
    }
    if let Some(i) = asked.show_step {
        let _ = doc.ask_step(i);
    }
    if let Some(format) = lms {
        super::lms_export::save(doc.session(), format, ui.ctx());
    }
}

/// "Export for LMS": a button a format; the one clicked, if any.
fn export_for_lms(ui: &mut egui::Ui, drawn: &mut Vec<(String, egui::Rect)>) -> Option<LmsFormat> {
    let mut asked = None;
    ui.label("Export for LMS (a package to upload as a course activity):");
    ui.horizontal_wrapped(|ui| {
        for (format, label) in [
            (LmsFormat::Scorm12, "SCORM 1.2"),
            (LmsFormat::Scorm2004, "SCORM 2004"),
            (LmsFormat::Cmi5, "cmi5"),
        ] {
            let button = ui.button(label).on_hover_text(
                "The case, its lesson and the student viewer as one zip; the LMS records the \
                 tour, each quiz answer and the score",
            );
            drawn.push((format!("lms-{}", format.name()), button.rect));
            if button.clicked() {
                asked = Some(format);
            }
        }
    });
    match super::lms_export::outcome() {
        Some(Ok(said)) => {
            ui.small(said);
        }
        Some(Err(why)) => {
            ui.colored_label(ui.visuals().error_fg_color, format!("Not exported: {why}"));
        }
        None => {}
    }
    asked
}

/// The language the words below are edited in, typed or picked among those the lesson has:
/// `None` for the own (English) words; an error (said there) while the field holds no language
/// tag.
fn language(
    ui: &mut egui::Ui,
    lesson: &Lesson,
    typed: &mut String,
    drawn: &mut Vec<(String, egui::Rect)>,
) -> Result<Option<String>, ()> {
    let mut known: Vec<&String> = (lesson.steps.iter())
        .flat_map(|s| s.titles.keys().chain(s.captions.keys()))
        .chain((lesson.labels.iter()).flat_map(|l| l.texts.keys().chain(l.notes.keys())))
        .collect();
    known.sort();
    known.dedup();
    ui.horizontal_wrapped(|ui| {
        ui.label("Words in");
        let field = egui::TextEdit::singleline(typed)
            .hint_text("English")
            .desired_width(60.0);
        drawn.push(("lesson-language".into(), ui.add(field).rect));
        let english = ui.selectable_label(typed.trim().is_empty(), "English");
        drawn.push(("lesson-language-own".into(), english.rect));
        if english.clicked() {
            typed.clear();
        }
        for tag in known {
            let picked = ui.selectable_label(typed.trim() == tag.as_str(), tag.as_str());
            drawn.push((format!("lesson-language-{tag}"), picked.rect));
            if picked.clicked() {
                typed.clone_from(tag);
            }
        }
    });
    if typed.trim().is_empty() {
        return Ok(None);
    }
    match names::tag(typed) {
        Ok(tag) => Ok(Some(tag)),
        Err(e) => {
            ui.colored_label(ui.visuals().error_fg_color, e);
            Err(())
        }
    }
}

/// The kind of a field of words.
#[derive(Clone, Copy)]
enum Field {
    /// One line, this wide.
    Line(f32),
    /// A caption, with this hint while empty.
    Caption(&'static str),
}

/// Which words the fields edit.
#[derive(Clone, Copy)]
enum Editing<'a> {
    /// The own (English) words.
    Own,
    /// Those in this language.
    In(&'a str),
    /// None, while the language field holds no tag: the own words are shown in fields that
    /// take focus but no edit, so keys typed there do not reach the page's shortcuts.
    Nothing,
}

/// A field editing the own words `own`, or those in a language in `others` (the own words as
/// its hint; emptied, the language's words are removed and the own stand).
fn words(
    ui: &mut egui::Ui,
    own: &mut String,
    others: &mut Names,
    editing: Editing,
    field: Field,
) -> egui::Response {
    let tag = match editing {
        Editing::Own => return ui.add(text_edit(own, field, None)),
        Editing::Nothing => return ui.add(text_edit(&mut own.as_str(), field, None)),
        Editing::In(tag) => tag,
    };
    let mut text = others.get(tag).cloned().unwrap_or_default();
    let response = ui.add(text_edit(&mut text, field, Some(own.as_str())));
    if response.changed() {
        if text.trim().is_empty() {
            others.remove(tag);
        } else {
            others.insert(tag.to_string(), text);
        }
    }
    response
}

/// The text field of a [`Field`] editing `text`, showing `own` words (when not empty) where it
/// is empty, else the field's hint.
fn text_edit<'t>(
    text: &'t mut dyn egui::TextBuffer,
    field: Field,
    own: Option<&str>,
) -> egui::TextEdit<'t> {
    let edit = match field {
        Field::Line(width) => egui::TextEdit::singleline(text).desired_width(width),
        Field::Caption(hint) => egui::TextEdit::multiline(text)
            .desired_rows(1)
            .hint_text(hint),
    };
    match own.filter(|own| !own.is_empty()) {
        Some(own) => edit.hint_text(own),
        None => edit,
    }
}

/// Each step's title and caption, with its buttons: up, down, delete, show.
fn steps(
    ui: &mut egui::Ui,
    lesson: &mut Lesson,
    editing: Editing,
    drawn: &mut Vec<(String, egui::Rect)>,
    asked: &mut Asked,
) {
    let mut moved: Option<(usize, usize)> = None;
    let mut deleted = None;
    let count = lesson.steps.len();
    for (i, step) in lesson.steps.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.label(format!("{}.", i + 1));
            let (own, others) = (&mut step.title, &mut step.titles);
            let title = words(ui, own, others, editing, Field::Line(130.0));
            asked.edited |= title.changed();
            drawn.push((format!("step-title-{i}"), title.rect));
            let up = ui.add_enabled(i > 0, egui::Button::new("▲").small());
            let down = ui.add_enabled(i + 1 < count, egui::Button::new("▼").small());
            let delete = ui.small_button("✕").on_hover_text("Delete the step");
            let show = ui.small_button("Show");
            for (key, r) in [("up", &up), ("down", &down), ("delete", &delete)] {
                drawn.push((format!("step-{key}-{i}"), r.rect));
            }
            drawn.push((format!("step-show-{i}"), show.rect));
            moved = moved
                .or(up.clicked().then(|| (i, i - 1)))
                .or(down.clicked().then_some((i, i + 1)));
            deleted = deleted.or(delete.clicked().then_some(i));
            asked.show_step = asked.show_step.or(show.clicked().then_some(i));
        });
        let (own, others) = (&mut step.caption, &mut step.captions);
        let hint = Field::Caption("Caption: what the student sees here");
        let caption = words(ui, own, others, editing, hint);
        drawn.push((format!("step-caption-{i}"), caption.rect));
        asked.edited |= caption.changed();
    }
    if let Some((a, b)) = moved {
        lesson.steps.swap(a, b);
    }
    if let Some(i) = deleted {
        lesson.steps.remove(i);
    }
    asked.edited |= moved.is_some() || deleted.is_some();
}

/// Each label's structure, text and note, and its delete button.
fn labels(
    ui: &mut egui::Ui,
    lesson: &mut Lesson,
    editing: Editing,
    drawn: &mut Vec<(String, egui::Rect)>,
    asked: &mut Asked,
) {
    let mut deleted = None;
    for (i, label) in lesson.labels.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.small(&label.structure);
            let (own, others) = (&mut label.text, &mut label.texts);
            let text = words(ui, own, others, editing, Field::Line(120.0));
            let delete = ui.small_button("✕").on_hover_text("Delete the label");
            asked.edited |= text.changed();
            drawn.push((format!("label-text-{i}"), text.rect));
            drawn.push((format!("label-delete-{i}"), delete.rect));
            deleted = deleted.or(delete.clicked().then_some(i));
        });
        let (own, others) = (&mut label.note, &mut label.notes);
        let hint = Field::Caption("Note: what the student reads on asking");
        let note = words(ui, own, others, editing, hint);
        asked.edited |= note.changed();
        drawn.push((format!("label-note-{i}"), note.rect));
    }
    if let Some(i) = deleted {
        lesson.labels.remove(i);
        asked.edited = true;
    }
}

/// Whether the case asks a quiz, in which modes, about which of the case's structures (`names`;
/// none ticked: those shown when the student starts it), and its pass mark.
fn quiz(
    ui: &mut egui::Ui,
    lesson: &mut Lesson,
    names: &[&str],
    drawn: &mut Vec<(String, egui::Rect)>,
    asked: &mut Asked,
) {
    let mut on = lesson.quiz.is_some();
    let toggle = ui.checkbox(&mut on, "Quiz the student");
    drawn.push(("quiz-on".into(), toggle.rect));
    asked.edited |= toggle.changed();
    match (on, &mut lesson.quiz) {
        (false, quiz) => *quiz = None,
        (true, None) => {
            lesson.quiz = Some(Quiz {
                structures: Vec::new(),
                modes: vec![QuizMode::FindIt, QuizMode::NameIt],
                pass_mark: 0.5,
            })
        }
        (true, Some(quiz)) => {
            ui.horizontal(|ui| {
                for (mode, word, key) in [
                    (QuizMode::FindIt, "Find it", "quiz-find-it"),
                    (QuizMode::NameIt, "Name it", "quiz-name-it"),
                ] {
                    let mut ticked = quiz.modes.contains(&mode);
                    let r = ui.checkbox(&mut ticked, word);
                    drawn.push((key.into(), r.rect));
                    if r.changed() {
                        asked.edited = true;
                        quiz.modes.retain(|m| *m != mode);
                        if ticked {
                            quiz.modes.push(mode);
                        }
                    }
                }
            });
            // Find it before Name it, whatever order they were ticked in.
            quiz.modes.sort_by_key(|m| *m == QuizMode::NameIt);
            ui.small("Asking about (none ticked: the structures shown):");
            ui.horizontal_wrapped(|ui| {
                for (i, &name) in names.iter().enumerate() {
                    let mut ticked = quiz.structures.iter().any(|s| s == name);
                    let r = ui.checkbox(&mut ticked, name);
                    drawn.push((format!("quiz-structure-{i}"), r.rect));
                    if r.changed() {
                        asked.edited = true;
                        quiz.structures.retain(|s| s != name);
                        if ticked {
                            quiz.structures.push(name.to_string());
                        }
                    }
                }
            });
            let mut percent = (quiz.pass_mark * 100.0).round();
            let slider = egui::Slider::new(&mut percent, 0.0..=100.0).text("pass mark %");
            if ui.add(slider).changed() {
                asked.edited = true;
                quiz.pass_mark = percent / 100.0;
            }
        }
    }
}
