//! The viewer's tour: the step asked for shown (structures, clip, slide, selection) with the
//! camera flying to its view, and the panel that steps through it with the step's caption.

use eframe::egui;

use super::sharing::show_view;
use super::Shell;
use crate::app::document::now_ms;
use crate::view::{step_view, Flight};

impl Shell {
    /// Shows the tour step asked for, if one was: its view now, its camera on the way.
    pub(super) fn take_up_step(&mut self) {
        let mut doc = self.doc.borrow_mut();
        let Some(index) = doc.view_asks.step.take() else {
            return;
        };
        let Some(step) = doc.session().case().lesson().steps.get(index).cloned() else {
            return;
        };
        let link = step_view(&step, &doc.session().case().as_case().names());
        let problems = show_view(&mut doc, &link);
        if !problems.is_empty() {
            log::warn!("tour step {}: {}", index + 1, problems.join("; "));
        }
        doc.tour = Some(index);
        if let (Some(to), Some((viewer, _))) = (link.camera, &self.view) {
            self.flight = Some(Flight::new(viewer.pose(), to, now_ms()));
        }
    }

    /// Moves the camera along its flight to a step's view, asking for frames until it is
    /// there or the student takes the camera.
    pub(super) fn fly(&mut self, ctx: &egui::Context) {
        let (Some(f), Some((viewer, _))) = (&mut self.flight, &mut self.view) else {
            return;
        };
        let Some(pose) = f.advance(viewer.pose(), now_ms()) else {
            self.flight = None;
            return;
        };
        viewer.set_pose(pose);
        f.left_at(viewer.pose());
        if f.arrived() {
            self.flight = None;
        } else {
            ctx.request_repaint();
        }
    }

    /// The labels' switch and the tour's controls with the step's caption, where the case has
    /// them.
    pub(super) fn tour_panel(&mut self, ui: &mut egui::Ui) {
        let mut doc = self.doc.borrow_mut();
        if !doc.session().case().lesson().labels.is_empty() {
            let mut shown = !doc.view_asks.hide_labels;
            let toggle = ui.checkbox(&mut shown, "Labels");
            doc.panel.lesson.push(("labels".into(), toggle.rect.into()));
            doc.view_asks.hide_labels = !shown;
        }
        let steps = &doc.session().case().lesson().steps;
        if steps.is_empty() {
            return;
        }
        let count = steps.len();
        let Some(index) = doc.tour else {
            let start = ui.button(format!("▶ Take the tour ({count} steps)"));
            doc.panel.lesson.push(("start".into(), start.rect.into()));
            let mut asked = start.clicked().then_some(0);
            if let Some(left) = doc.tour_left.filter(|&i| i < count) {
                let resume = ui.button(format!("Back to step {} of {count}", left + 1));
                doc.panel.lesson.push(("resume".into(), resume.rect.into()));
                asked = asked.or(resume.clicked().then_some(left));
            }
            if let Some(i) = asked {
                let _ = doc.ask_step(i);
            }
            ui.separator();
            return;
        };
        let languages = doc.words().languages;
        let lesson = doc.session().case().lesson();
        let (title, caption) = (lesson.step_text(index.min(count - 1), languages))
            .map(|(t, c)| (t.to_string(), c.to_string()))
            .unwrap_or_default();
        ui.strong(format!("Step {} of {count}: {title}", index + 1));
        if !caption.is_empty() {
            ui.label(caption);
        }
        let mut asked = None;
        let mut leave = false;
        let mut drawn = Vec::new();
        ui.horizontal_wrapped(|ui| {
            let back = ui.add_enabled(index > 0, egui::Button::new("◀ Back"));
            let next = ui.add_enabled(index + 1 < count, egui::Button::new("Next ▶"));
            let out = ui.button("Leave the tour");
            asked = (back.clicked().then(|| index - 1)).or(next.clicked().then_some(index + 1));
            leave = out.clicked();
            drawn = vec![
                ("back", back.rect),
                ("next", next.rect),
                ("leave", out.rect),
            ];
        });
        (doc.panel.lesson).extend(drawn.into_iter().map(|(k, r)| (k.into(), r.into())));
        if let Some(i) = asked {
            let _ = doc.ask_step(i);
        }
        if leave {
            doc.leave_tour();
        }
        ui.separator();
    }
}
