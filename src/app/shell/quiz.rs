//! The viewer's quiz panel: the question asked ("Find it": a name to click in the view; "Name
//! it": a highlighted structure and four names to pick from), right or wrong at once, and the
//! score at the end. It takes the place of the structure list, whose names would give the
//! answers away.

use eframe::egui;

use super::Shell;
use crate::app::document::Document;

const RIGHT: egui::Color32 = egui::Color32::from_rgb(110, 200, 120);
const WRONG: egui::Color32 = egui::Color32::from_rgb(235, 110, 100);

impl Shell {
    /// The quiz's start button, where the case has a quiz and none runs.
    pub(super) fn quiz_start(&mut self, ui: &mut egui::Ui) {
        let mut doc = self.doc.borrow_mut();
        if doc.session().case().lesson().quiz.is_none() || doc.quiz.is_some() {
            return;
        }
        let start = ui.button("Take the quiz");
        doc.panel.lesson.push(("quiz".into(), start.rect.into()));
        if start.clicked() {
            ui.ctx().request_repaint();
            if let Err(e) = doc.start_quiz() {
                log::warn!("{e}");
            }
        }
        ui.separator();
    }

    /// The running quiz; whether one runs (the panel then shows nothing else).
    pub(super) fn quiz_panel(&mut self, ui: &mut egui::Ui) -> bool {
        let mut held = self.doc.borrow_mut();
        let doc = &mut *held;
        let Some(run) = &doc.quiz else {
            return false;
        };
        // The structure list is not drawn while the quiz runs.
        doc.panel.structures.clear();
        doc.panel.structure_filter = None;
        let mut drawn: Vec<(&'static str, egui::Rect)> = Vec::new();
        let mut act = Act::None;
        let words = doc.quiz_words();
        ui.strong(&words.heading);
        ui.label(&words.question);
        let choices = run.current().map_or(&[][..], |(_, q)| &q.choices[..]);
        const KEYS: [&str; 4] = ["choice-0", "choice-1", "choice-2", "choice-3"];
        for (k, &c) in choices.iter().enumerate() {
            let label = doc.words().name(c);
            let button = ui.add_enabled(run.answered().is_none(), egui::Button::new(label));
            drawn.push((KEYS[k.min(3)], button.rect));
            if button.clicked() {
                act = Act::Answer(c);
            }
        }
        if let Some((good, text)) = &words.outcome {
            let mark = if *good { "✔" } else { "✘" };
            ui.colored_label(if *good { RIGHT } else { WRONG }, format!("{mark} {text}"));
        }
        if let Some((i, _)) = run.current().filter(|_| run.answered().is_some()) {
            let last = i + 1 == run.questions().len();
            let next = ui.button(if last {
                "See the score"
            } else {
                "Next question ▶"
            });
            drawn.push(("next-question", next.rect));
            if next.clicked() {
                act = Act::Next;
            }
        }
        if run.finished() {
            let again = ui.button("Try again");
            drawn.push(("again", again.rect));
            if again.clicked() {
                act = Act::Again;
            }
        }
        ui.separator();
        let end = ui.button("End the quiz");
        drawn.push(("end-quiz", end.rect));
        if end.clicked() {
            act = Act::End;
        }
        (doc.panel.lesson).extend(drawn.into_iter().map(|(k, r)| (k.into(), r.into())));
        // What changed is drawn at once, not at the next input.
        if !matches!(act, Act::None) {
            ui.ctx().request_repaint();
        }
        if let Err(e) = act.on(doc) {
            log::warn!("{e}");
        }
        true
    }
}

/// What the student's click in the panel asks.
enum Act {
    None,
    Answer(usize),
    Next,
    Again,
    End,
}

impl Act {
    fn on(self, doc: &mut Document) -> Result<(), String> {
        match self {
            Act::None => Ok(()),
            Act::Answer(given) => doc.answer_quiz(given),
            Act::Next => doc.next_question(),
            Act::Again => doc.start_quiz(),
            Act::End => {
                doc.end_quiz();
                Ok(())
            }
        }
    }
}
