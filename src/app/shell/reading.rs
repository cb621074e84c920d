//! The viewer's frame (`?mode=viewer`): a top bar to open a case and reset the view, and the
//! case's panel on the left; the view and its tools are the author's.

use eframe::egui;

use super::Shell;
use crate::app::document::Document;
use crate::app::structure_list::StructureAction;
use crate::app::{case_reader, query};
use crate::session::ColorField;

/// Below this page width (points) the case's panel goes under the view: a phone held upright.
pub(super) const NARROW: f32 = 700.0;

/// Whether the viewer's frame is shown: the viewer's page, or the author's preview. Takes the
/// document its caller has borrowed, so no borrow is hidden here.
pub(super) fn reads(doc: &Document) -> bool {
    query::is_viewer() || doc.previewing
}

impl Shell {
    /// The colouring the view shows: the reader's in the viewer's frame (none until the
    /// student asks how far the surfaces moved), else the author's.
    pub(super) fn shown_coloring(&self, doc: &Document) -> Option<ColorField> {
        match reads(doc) {
            true => self.reader_coloring,
            false => self.coloring,
        }
    }

    /// The author's way back from the preview.
    fn preview_back(&mut self, ui: &mut egui::Ui) {
        let mut doc = self.doc.borrow_mut();
        if !doc.previewing {
            return;
        }
        let back = ui.button("◀ Back to authoring");
        doc.panel
            .lesson
            .push(("end-preview".into(), back.rect.into()));
        ui.small("The case as the student will see it in the viewer.");
        ui.separator();
        if back.clicked() {
            doc.end_preview();
            ui.ctx().request_repaint();
        }
    }

    pub(super) fn reading_top_bar(&mut self, ui: &mut egui::Ui) {
        let narrow = ui.ctx().content_rect().width() < NARROW;
        ui.horizontal_wrapped(|ui| {
            ui.heading("meshsmooth viewer");
            ui.separator();
            if ui.button("Open…").on_hover_text("O").clicked() {
                self.open_picker(super::FilesFor::NewCase);
            }
            if let Some((viewer, _)) = &mut self.view {
                if ui.button("Reset view").on_hover_text("R").clicked() {
                    viewer.reset_view();
                }
                ui.separator();
                self.sharing_buttons(ui);
            }
            ui.separator();
            if ui.button("Help").on_hover_text("H").clicked() {
                self.help_open = !self.help_open;
            }
            if !narrow {
                ui.label("Drop a case glTF on the page to open it.");
            }
        });
    }

    /// The case's title, its structures and the selected one's record: left of the view, or
    /// under it on a narrow page.
    pub(super) fn reading_panel(&mut self, ui: &mut egui::Ui) {
        let page = ui.ctx().content_rect();
        let panel = if page.width() < NARROW {
            egui::Panel::bottom("case below").default_size(page.height() * 0.38)
        } else {
            // The view comes first: a list of long names would otherwise take the page.
            egui::Panel::left("case")
                .default_size(300.0)
                .max_size((page.width() * 0.4).max(300.0))
        };
        panel.resizable(true).show(ui, |ui| {
            // Filling the panel: under the view it would otherwise shrink to its first lines.
            let scroll = egui::ScrollArea::vertical().auto_shrink([false, false]);
            scroll.show(ui, |ui| {
                self.doc.borrow_mut().panel.lesson.clear();
                self.preview_back(ui);
                if self.quiz_panel(ui) {
                    return;
                }
                self.tour_panel(ui);
                self.quiz_start(ui);
                let mut guard = self.doc.borrow_mut();
                let doc = &mut *guard;
                let was = self.reader_coloring == Some(ColorField::LocalError);
                let mut error_colours = was;
                let languages = doc.words().languages.to_vec();
                let (session, panel) = doc.session_and_panel();
                let filter = &mut self.reading_filter;
                let reader = (&*session, &languages[..]);
                let actions = case_reader::show(ui, reader, panel, (filter, &mut error_colours));
                if error_colours != was {
                    self.reader_coloring = error_colours.then_some(ColorField::LocalError);
                }
                for action in actions {
                    let done = match action {
                        StructureAction::Select(i) => doc.select(i),
                        StructureAction::Change(i, change) => {
                            doc.session_mut().case_mut().set_structure(i, change)
                        }
                        StructureAction::Solo(i) => doc.session_mut().case_mut().solo_structure(i),
                        _ => Ok(()),
                    };
                    if let Err(e) = done {
                        log::warn!("{e}");
                    }
                }
            });
        });
    }
}
