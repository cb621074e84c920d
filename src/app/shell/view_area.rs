//! The middle of the page: the 3D view, its colour legend, its tools, the orientation marker,
//! the name of the structure under the pointer and the messages over its corner.

use eframe::egui;

use super::view_sync::Positions;
use super::Shell;
use crate::app::document::Document;
use crate::app::layout::ViewReport;
use crate::app::pointing::Pointing;
use crate::app::{legend, orientation_marker, status, view_tools, viewer};

impl Shell {
    /// The colour legend, in a strip at the right of the space left; returns the rest, the
    /// view's.
    fn legend(&self, ui: &mut egui::Ui) -> egui::Rect {
        let whole = ui.available_rect_before_wrap();
        let strip = self.shown.legend.as_ref().map(|l| {
            let width = legend::width(ui, l).min(whole.width() * 0.4);
            let strip = whole.with_min_x(whole.max.x - width);
            (strip, l)
        });
        if let Some((strip, l)) = strip {
            legend::paint(ui, strip, l, viewer::BACKGROUND);
        }
        strip.map_or(whole, |(s, _)| whole.with_max_x(s.min.x))
    }

    /// The 3D view with its legend, its tools and the messages over it; the structure under
    /// the pointer is named (and, in the viewer, selected by a click).
    pub(super) fn view(&mut self, ui: &mut egui::Ui) {
        let view_rect = self.legend(ui);
        let reads = super::reading::reads(&self.doc.borrow());
        // The student's clicks in the view select; they paint no weights.
        self.brush.active &= !reads;
        let rect = match &mut self.view {
            Some((viewer, _)) => {
                viewer.painting = self.brush.active;
                let mut doc = self.doc.borrow_mut();
                let doc = &mut *doc;
                viewer.clip = doc.view_asks.clip;
                viewer.planes = doc.view_asks.planes;
                if let Some(side) = doc.view_asks.look_from.take() {
                    viewer.look_from(side);
                }
                let response = ui
                    .scope_builder(egui::UiBuilder::new().max_rect(view_rect), |ui| {
                        viewer.show(ui)
                    })
                    .inner;
                // A label's plate takes the pointer: the structure behind it is not named.
                let on_label = (response.hover_pos())
                    .is_some_and(|p| doc.view.labels.iter().any(|l| l.plate.contains(p.into())));
                if !self.brush.active && !self.picture.pending && !on_label {
                    let at = (viewer.camera(), viewer.clip_plane());
                    point(&mut self.pointing, reads, ui, &response, at, doc);
                } else {
                    self.pointing = Default::default();
                }
                doc.pointed = self.pointing.named.as_ref().map(|(_, name)| name.clone());
                let asked = doc.view_asks;
                orientation_marker::paint(ui, response.rect, viewer.camera());
                let quiet = doc.view_asks.hide_labels || doc.quiz.is_some();
                let labels = match quiet || self.picture.pending {
                    true => Vec::new(),
                    false => self.labels.paint(ui, response.rect, viewer, doc),
                };
                // A picture shows the view alone (and which way the patient lies).
                if !self.picture.pending {
                    let has_image = doc.session().case().as_case().image.is_some();
                    let asks = &mut doc.view_asks;
                    doc.panel.planes = view_tools::show(ui, response.rect, asks, has_image);
                }
                if doc.view_asks != asked {
                    ui.ctx().request_repaint();
                }
                let shown = match self.shown.positions {
                    Some(Positions::Cpu(r) | Positions::Gpu(r)) => Some(r),
                    _ => None,
                };
                let surface = (doc.session().case().model_id(), shown);
                let camera = viewer.camera();
                self.brush
                    .interact(ui, &response, camera, doc.session_mut().case_mut(), surface);
                self.drag_params
                    .interact(ui, &response, doc.session_mut().case_mut());
                doc.view = ViewReport {
                    rect: response.rect.into(),
                    pose: Some(viewer.pose()),
                    clip_plane: viewer.clip_plane(),
                    brush_on: self.brush.active,
                    pick_ms: self.brush.pick_ms,
                    labels,
                };
                response.rect
            }
            None => {
                ui.label("The 3D view needs WebGPU or WebGL2, which this browser did not provide.");
                view_rect
            }
        };
        if !self.picture.pending {
            self.messages(ui, rect);
        }
    }

    /// Messages over the view's top-left corner.
    fn messages(&self, ui: &mut egui::Ui, rect: egui::Rect) {
        let doc = self.doc.borrow();
        let reading = self.files.reading();
        let error = self.export_error.as_deref();
        let lines = status::view_messages(ui, &doc, error, &reading, self.show_original);
        status::paint_messages(ui, rect, lines);
    }
}

/// Names the structure under the pointer; in the viewer (`reading`) a click selects it.
/// While a quiz runs nothing is named, and a click answers "Find it".
fn point(
    pointing: &mut Pointing,
    reading: bool,
    ui: &egui::Ui,
    response: &egui::Response,
    at: (&crate::view::OrbitCamera, [f32; 4]),
    doc: &mut Document,
) {
    let quiz = doc.quiz.is_some();
    let clicked = pointing.update(ui, response, at, doc, quiz);
    if quiz {
        if let Some(i) = clicked.filter(|_| doc.quiz_wants_click()) {
            if let Err(e) = doc.answer_quiz(i) {
                log::warn!("{e}");
            }
            ui.ctx().request_repaint();
        }
        return;
    }
    if let (true, Some(i), Some(at)) = (doc.placing_label, clicked, pointing.point) {
        doc.placing_label = false;
        if let Err(e) = doc.place_label(i, at) {
            log::warn!("{e}");
        }
        return;
    }
    let current = doc.session().case().current_structure();
    if let (true, Some(i)) = (reading, clicked.filter(|&i| Some(i) != current)) {
        if let Err(e) = doc.select(i) {
            log::warn!("{e}");
        }
    }
}
