//! The `eframe::App`: a top bar (title, Open, view options), the 3D view of the open mesh in
//! the centre, its report on the right, the last error.

use super::file_input::FileInput;
use super::viewer::Viewer;
use super::{page, report_view, AppState, LoadedModel, SAMPLE_BYTES, SAMPLE_NAME};
use eframe::egui;
use eframe::egui_wgpu;

pub struct Shell {
    state: AppState,
    files: FileInput,
    /// The 3D view and the GPU it draws with; `None` when eframe has no wgpu renderer.
    view: Option<(Viewer, egui_wgpu::RenderState)>,
}

impl Shell {
    pub fn new(cc: &eframe::CreationContext<'_>) -> Self {
        let view = cc.wgpu_render_state.as_ref().map(|rs| {
            let mut viewer = Viewer::new(rs);
            viewer.wireframe = page::query_flag("wireframe");
            (viewer, rs.clone())
        });
        let mut shell = Self {
            state: AppState::default(),
            files: FileInput::new(&cc.egui_ctx),
            view,
        };
        shell.open(SAMPLE_NAME, SAMPLE_BYTES);
        shell
    }

    fn receive_files(&mut self, ctx: &egui::Context) {
        self.files.collect_dropped(ctx);
        for file in self.files.take_arrived() {
            match file.bytes {
                Ok(bytes) => self.open(&file.name, &bytes),
                Err(reason) => self.state.fail(&file.name, &reason),
            }
        }
    }

    /// Opens a file and, when it became the open model, shows it in the 3D view.
    fn open(&mut self, name: &str, bytes: &[u8]) {
        self.state.open(name, bytes);
        // `open` clears the error exactly when the file replaced the model.
        if self.state.error.is_none() {
            if let (Some(model), Some((viewer, rs))) = (&self.state.model, &mut self.view) {
                show_model(viewer, rs, model);
            }
        }
    }
}

/// Uploads `model` to the 3D view: positions, area-weighted normals, triangles, edges.
fn show_model(viewer: &mut Viewer, rs: &egui_wgpu::RenderState, model: &LoadedModel) {
    let mesh = &model.mesh;
    let normals = crate::mesh::vertex_normals(&mesh.positions, &mesh.triangles);
    let edges = model.topology.edges();
    viewer.set_mesh(rs, &mesh.positions, &normals, &mesh.triangles, &edges);
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
                if let Some((viewer, _)) = &mut self.view {
                    ui.separator();
                    ui.checkbox(&mut viewer.wireframe, "Wireframe");
                    if ui.button("Reset view").clicked() {
                        viewer.reset_view();
                    }
                }
            });
        });
        egui::Panel::bottom("privacy").show(ui, |ui| {
            ui.small("Files are read inside this browser tab; nothing is uploaded.");
        });
        egui::Panel::right("report")
            .resizable(true)
            .default_size(320.0)
            .show(ui, |ui| {
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
        egui::CentralPanel::no_frame().show(ui, |ui| match &mut self.view {
            Some((viewer, _)) => {
                viewer.show(ui);
            }
            None => {
                ui.label("The 3D view needs WebGPU or WebGL2, which this browser did not provide.");
            }
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
