//! The `eframe::App`: the top bar (Open, Export, view toggles, help), the smoothing panel on the
//! left (filter, parameters, measures, colours), the mesh report on the right, the status bar,
//! and the view in the middle. Owns no algorithm: edits go to the shared document's session.

use super::controls::{self, Controls};
use super::document::{Backend, Document, SharedDocument};
use super::file_input::FileInput;
use super::gpu_engine::GpuEngine;
use super::shortcuts::{self, Action};
use super::{api, download, legend, query, report_view, SAMPLE_BYTES, SAMPLE_NAME};
use crate::export::ExportFormat;
use crate::session::ColorField;
use crate::smooth::Filter;
use eframe::egui;
use std::cell::RefCell;
use std::rc::Rc;

pub struct Shell {
    doc: SharedDocument,
    files: FileInput,
    controls: Controls,
    coloring: Option<ColorField>,
    bake_colors: bool,
    show_original: bool,
    help_open: bool,
    /// Why the last export failed.
    export_error: Option<String>,
    /// The WebGPU engine, where the page has WebGPU.
    gpu: Option<GpuEngine>,
    /// Why the GPU engine was given up for the CPU engine.
    gpu_fallback: Option<String>,
}

impl Shell {
    pub fn new(cc: &eframe::CreationContext<'_>) -> Self {
        // WebGPU: the GPU engine on eframe's device. WebGL2 (no compute shaders): the CPU engine.
        let gpu = cc.wgpu_render_state.as_ref().and_then(|rs| {
            let info = rs.adapter.get_info();
            log::info!("adapter: {} ({:?})", info.name, info.backend);
            (info.backend == wgpu::Backend::BrowserWebGpu)
                .then(|| GpuEngine::new(&rs.device, &rs.queue))
        });
        let backend = if gpu.is_some() { Backend::WebGpu } else { Backend::Cpu };
        let doc = Rc::new(RefCell::new(Document::new(backend)));
        // Dark, as on radiology workstations: the model stands out and colours read true.
        cc.egui_ctx.set_theme(egui::Theme::Dark);
        let files = FileInput::new(&cc.egui_ctx);
        open_start_model(&doc, &files, &cc.egui_ctx);
        if let Err(e) = api::install(&doc, &cc.egui_ctx) {
            log::error!("no embedding API: {e}");
        }
        Self {
            doc,
            files,
            controls: Controls::default(),
            coloring: Some(ColorField::LocalError),
            bake_colors: false,
            show_original: false,
            help_open: false,
            export_error: None,
            gpu,
            gpu_fallback: None,
        }
    }

    /// This frame's engine work: the GPU engine where there is one, else the CPU engine.
    fn compute(&mut self) {
        let mut doc = self.doc.borrow_mut();
        if let Some(gpu) = &mut self.gpu {
            match gpu.step(&mut doc) {
                Ok(_) => return,
                Err(why) => {
                    log::error!("GPU engine failed, using the CPU engine: {why}");
                    self.gpu = None;
                    self.gpu_fallback = Some(why);
                    doc.backend = Backend::Cpu;
                }
            }
        }
        doc.compute_on_cpu();
    }

    fn receive_files(&mut self, ctx: &egui::Context) {
        self.files.collect_dropped(ctx);
        for file in self.files.take_arrived() {
            let mut doc = self.doc.borrow_mut();
            match file.bytes {
                Ok(bytes) => {
                    let _ = doc.open(&file.name, &bytes);
                }
                Err(reason) => {
                    doc.session.fail(&file.name, &reason);
                }
            }
        }
    }

    fn open_picker(&mut self) {
        if let Err(e) = self.files.open_picker() {
            self.doc.borrow_mut().session.fail("a file", &e);
        }
    }

    fn export(&mut self, format: ExportFormat) {
        let doc = self.doc.borrow();
        let session = &doc.session;
        let Some(model) = session.model() else { return };
        let colors = self
            .coloring
            .filter(|_| self.bake_colors)
            .and_then(|f| session.colors(f))
            .map(|(c, _)| c);
        let (ext, mime) = match format {
            ExportFormat::Glb => ("glb", "model/gltf-binary"),
            ExportFormat::Stl => ("stl", "model/stl"),
            ExportFormat::Ply => ("ply", "application/octet-stream"),
            ExportFormat::Obj => ("obj", "model/obj"),
        };
        let stem = model
            .name
            .rsplit_once('.')
            .map_or(model.name.as_str(), |s| s.0);
        let name = format!("{stem}_smoothed.{ext}");
        self.export_error = session
            .export(format, colors.as_deref())
            .and_then(|bytes| download::save(&name, &bytes, mime))
            .err();
    }

    fn apply(&mut self, action: Action) {
        match action {
            Action::Open => self.open_picker(),
            Action::ToggleWireframe => {}
            Action::ToggleOriginal => self.show_original = !self.show_original,
            Action::ResetView => {}
            Action::NextColoring => {
                let all = ColorField::ALL;
                self.coloring = match self.coloring {
                    None => Some(all[0]),
                    Some(f) => all
                        .iter()
                        .position(|&g| g == f)
                        .and_then(|k| all.get(k + 1))
                        .copied(),
                };
            }
            Action::Filter(k) => self.doc.borrow_mut().session.set_filter(Filter::ALL[k]),
            Action::ExportGlb => self.export(ExportFormat::Glb),
            Action::ToggleHelp => self.help_open = !self.help_open,
        }
    }

    fn top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.heading("meshsmooth");
            ui.separator();
            if ui.button("Open…").on_hover_text("O").clicked() {
                self.open_picker();
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
            ui.toggle_value(&mut self.show_original, "Original")
                .on_hover_text("Before/after: show the original mesh (B)");
            ui.separator();
            if ui.button("Help").on_hover_text("H").clicked() {
                self.help_open = !self.help_open;
            }
            ui.label("Drop an STL, OBJ, PLY or glTF file on the page to open it.");
        });
    }

    fn smoothing_panel(&mut self, ui: &mut egui::Ui) {
        let mut doc = self.doc.borrow_mut();
        let timings = doc.timings;
        ui.heading("Smoothing");
        self.controls.filter(ui, &mut doc.session);
        ui.separator();
        ui.heading("Measures");
        controls::measures(ui, &doc.session, timings);
        ui.separator();
        ui.heading("Colours");
        controls::coloring(ui, &mut self.coloring, &mut doc.session);
    }

    fn status_bar(&self, ui: &mut egui::Ui) {
        let doc = self.doc.borrow();
        ui.horizontal(|ui| {
            if let Some(model) = doc.session.model() {
                ui.label(format!(
                    "{}: {} vertices, {} faces",
                    model.name, model.report.vertices, model.report.faces
                ));
                if !model.warnings.is_empty() {
                    ui.colored_label(
                        ui.visuals().warn_fg_color,
                        format!("{} warning(s): see the report", model.warnings.len()),
                    );
                }
                ui.separator();
            }
            ui.label(format!("engine: {}", doc.backend.name()));
            if let Some(t) = doc.timings {
                ui.label(t.describe());
            }
            if let Some(why) = &self.gpu_fallback {
                ui.colored_label(ui.visuals().warn_fg_color, "CPU fallback")
                    .on_hover_text(why);
            }
            if let Some((done, total)) = doc.session.progress() {
                ui.add(
                    egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                        .desired_width(160.0)
                        .text(format!("smoothing {done}/{total}")),
                );
            } else if doc.busy() || self.files.reading() > 0 {
                ui.spinner();
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                ui.small("Files are read inside this browser tab; nothing is uploaded.");
            });
        });
    }

    fn view(&mut self, ui: &mut egui::Ui) {
        let doc = self.doc.borrow();
        if let Some(error) = doc.session.error().or(self.export_error.as_deref()) {
            ui.colored_label(ui.visuals().error_fg_color, error);
        }
        if self.files.reading() > 0 {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label("Reading file…");
            });
        }
        let rect = ui.available_rect_before_wrap();
        if let Some(field) = self.coloring.filter(|_| !self.show_original) {
            if let Some((_, l)) = doc.session.colors(field) {
                legend::paint(ui, rect, &l);
            }
        }
    }
}

/// Opens `?model=URL` (same origin only) or else the bundled sample.
fn open_start_model(doc: &SharedDocument, files: &FileInput, ctx: &egui::Context) {
    match query::model_url() {
        None => {
            let _ = doc.borrow_mut().open(SAMPLE_NAME, SAMPLE_BYTES);
        }
        Some(Err(e)) => {
            let _ = doc.borrow_mut().open(SAMPLE_NAME, SAMPLE_BYTES);
            doc.borrow_mut().session.fail("?model", &e);
        }
        Some(Ok(model)) => files.fetch(model.url, model.name, ctx),
    }
}

impl eframe::App for Shell {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.receive_files(&ctx);
        for action in shortcuts::pressed(&ctx) {
            self.apply(action);
        }
        self.compute();
        {
            let mut doc = self.doc.borrow_mut();
            doc.answer_waiting();
            if doc.busy() {
                ctx.request_repaint();
            }
        }

        egui::Panel::top("top_bar").show(ui, |ui| self.top_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::left("smoothing")
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.smoothing_panel(ui));
            });
        egui::Panel::right("report")
            .resizable(true)
            .default_size(260.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    if let Some(model) = self.doc.borrow().session.model() {
                        report_view::show(ui, model);
                    }
                });
            });
        egui::CentralPanel::default_margins().show(ui, |ui| self.view(ui));
        shortcuts::help_window(&ctx, &mut self.help_open);

        if ctx.input(|i| !i.raw.hovered_files.is_empty()) {
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
