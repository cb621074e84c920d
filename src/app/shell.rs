//! The `eframe::App`: a top bar (title, Open), the report of the open mesh, the last error.
//! No 3D view yet; the renderer will take the central panel's place beside the report.

use super::file_input::FileInput;
use super::{report_view, AppState, SAMPLE_BYTES, SAMPLE_NAME};
use eframe::egui;

pub struct Shell {
    state: AppState,
    files: FileInput,
}

impl Shell {
    pub fn new(cc: &eframe::CreationContext<'_>) -> Self {
        let mut state = AppState::default();
        state.open(SAMPLE_NAME, SAMPLE_BYTES);
        Self {
            state,
            files: FileInput::new(&cc.egui_ctx),
        }
    }

    fn receive_files(&mut self, ctx: &egui::Context) {
        self.files.collect_dropped(ctx);
        for file in self.files.take_arrived() {
            match file.bytes {
                Ok(bytes) => self.state.open(&file.name, &bytes),
                Err(reason) => self.state.fail(&file.name, &reason),
            }
        }
    }
}

impl eframe::App for Shell {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.receive_files(&ctx);

        egui::Panel::top("top_bar").show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.heading("meshsmooth");
                ui.separator();
                if ui.button("Open…").clicked() {
                    if let Err(e) = self.files.open_picker() {
                        self.state.fail("a file", &e);
                    }
                }
                ui.label("or drop an STL, OBJ, PLY or glTF file on the page.");
            });
        });
        egui::Panel::bottom("privacy").show(ui, |ui| {
            ui.small("Files are read inside this browser tab; nothing is uploaded.");
        });
        egui::CentralPanel::default_margins().show(ui, |ui| {
            if self.files.reading() > 0 {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label("Reading file…");
                });
            }
            if let Some(error) = &self.state.error {
                ui.colored_label(ui.visuals().error_fg_color, error);
                ui.add_space(8.0);
            }
            egui::ScrollArea::vertical().show(ui, |ui| match &self.state.model {
                Some(model) => report_view::show(ui, model),
                None => {
                    ui.label("No mesh open.");
                }
            });
        });

        let hovering = ctx.input(|i| !i.raw.hovered_files.is_empty());
        if hovering {
            drop_hint(&ctx);
        }
    }
}

/// Dims the page while a file is dragged over it.
fn drop_hint(ctx: &egui::Context) {
    let painter = ctx.layer_painter(egui::LayerId::new(
        egui::Order::Foreground,
        egui::Id::unique("drop_hint"),
    ));
    let rect = ctx.content_rect();
    painter.rect_filled(rect, 0.0, egui::Color32::from_black_alpha(160));
    painter.text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        "Drop to open",
        egui::FontId::proportional(28.0),
        egui::Color32::WHITE,
    );
}
