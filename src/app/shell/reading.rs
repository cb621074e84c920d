//! The viewer's frame (`?mode=viewer`): a top bar to open a case and reset the view, and the
//! case's panel on the left; the view and its tools are the author's.

use eframe::egui;

use super::Shell;
use crate::app::case_reader;
use crate::app::structure_list::StructureAction;
use crate::session::ColorField;

impl Shell {
    pub(super) fn reading_top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.heading("meshsmooth viewer");
            ui.separator();
            if ui.button("Open…").on_hover_text("O").clicked() {
                self.open_picker(false);
            }
            if let Some((viewer, _)) = &mut self.view {
                if ui.button("Reset view").on_hover_text("R").clicked() {
                    viewer.reset_view();
                }
            }
            ui.separator();
            if ui.button("Help").on_hover_text("H").clicked() {
                self.help_open = !self.help_open;
            }
            ui.label("Drop a case glTF on the page to open it.");
        });
    }

    /// The case's title, its structures and the selected one's record.
    pub(super) fn reading_panel(&mut self, ui: &mut egui::Ui) {
        egui::Panel::left("case")
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    let mut guard = self.doc.borrow_mut();
                    let doc = &mut *guard;
                    let was = self.coloring == Some(ColorField::LocalError);
                    let mut error_colours = was;
                    let actions =
                        case_reader::show(ui, &doc.session, &mut doc.panel, &mut error_colours);
                    if error_colours != was {
                        self.coloring = error_colours.then_some(ColorField::LocalError);
                    }
                    for action in actions {
                        let done = match action {
                            StructureAction::Select(i) => doc.begin_open_structure(i, None),
                            StructureAction::Change(i, change) => {
                                doc.session.set_structure(i, change)
                            }
                            StructureAction::Solo(i) => doc.session.solo_structure(i),
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
