//! The page's two bars: the top bar (files, export, what the view shows, help) and the status
//! bar (the model, the engine, its timings and the work under way).

use eframe::egui;

use super::Shell;
use crate::app::status;
use crate::export::ExportFormat;

impl Shell {
    pub(super) fn top_bar(&mut self, ui: &mut egui::Ui) {
        if super::reading::reads(&self.doc.borrow()) {
            self.reading_top_bar(ui);
            return;
        }
        ui.horizontal(|ui| {
            ui.heading("meshsmooth");
            ui.separator();
            if ui.button("Open…").on_hover_text("O").clicked() {
                self.open_picker(super::FilesFor::NewCase);
            }
            ui.menu_button("Export", |ui| {
                for (label, format) in [
                    ("glTF binary (.glb)", ExportFormat::Glb),
                    ("STL (.stl)", ExportFormat::Stl),
                    ("PLY (.ply)", ExportFormat::Ply),
                    ("OBJ (.obj)", ExportFormat::Obj),
                ] {
                    if ui.button(label).clicked() {
                        self.export(format);
                        ui.close();
                    }
                }
                ui.checkbox(&mut self.bake_colors, "Bake colours (GLB, PLY)");
            });
            ui.separator();
            if ui
                .toggle_value(&mut self.bottom.open, "Graphs")
                .on_hover_text("Model quality graphs of the active filter (G)")
                .changed()
            {
                let open = self.bottom.open;
                self.bottom
                    .set_open(open, self.doc.borrow_mut().session_mut());
            }
            ui.toggle_value(&mut self.show_original, "Original")
                .on_hover_text("Before/after: show the original mesh (B)");
            if let Some((viewer, _)) = &mut self.view {
                ui.toggle_value(&mut viewer.wireframe, "Wireframe")
                    .on_hover_text("W");
                if ui.button("Reset view").on_hover_text("R").clicked() {
                    viewer.reset_view();
                }
                self.sharing_buttons(ui);
            }
            ui.separator();
            if ui.button("Help").on_hover_text("H").clicked() {
                self.help_open = !self.help_open;
            }
            ui.label(
                "Drop meshes (STL, OBJ, PLY, glTF), a segmentation (NIfTI, NRRD, MGZ, DICOM SEG) or a case glTF on the page to open them as a case.",
            );
        });
    }

    pub(super) fn status_bar(&self, ui: &mut egui::Ui) {
        let doc = self.doc.borrow();
        ui.horizontal(|ui| {
            // A quiz names no structure but in its questions; a phone has room for the
            // privacy note alone.
            let narrow = ui.ctx().content_rect().width() < super::reading::NARROW;
            let reads = super::reading::reads(&doc);
            let named = doc.quiz.is_none() && !(narrow && reads);
            if let Some(model) = doc.session().case().model().filter(|_| named) {
                ui.label(format!(
                    "{}: {} vertices, {} faces",
                    model.name, model.report.vertices, model.report.faces
                ));
                // The mesh report, the engine and its timings are the author's business.
                if !model.warnings.is_empty() && !reads {
                    ui.colored_label(
                        ui.visuals().warn_fg_color,
                        format!("{} warning(s): see the report", model.warnings.len()),
                    );
                }
                ui.separator();
            }
            if !reads {
                ui.label(format!("engine: {}", doc.backend().name()));
                if let Some(t) = doc.timings {
                    ui.label(t.describe());
                }
                if let Some(why) = doc.gpu_fallback() {
                    ui.colored_label(ui.visuals().warn_fg_color, "CPU fallback")
                        .on_hover_text(why);
                }
            }
            status::progress(ui, &doc, &self.files.reading());
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                ui.small("Files are read inside this browser tab; nothing is uploaded.");
            });
        });
    }
}
