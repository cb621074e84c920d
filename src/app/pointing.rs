//! Names the structure under the pointer in the view, beside the pointer; in the viewer a
//! click selects it. Asked again only when the pointer, the camera, the clip or the case
//! moved.

use eframe::egui;
use glam::Vec2;

use super::document::Document;
use crate::view::OrbitCamera;

/// What the pointer was over last time it was asked.
#[derive(Default)]
pub struct Pointing {
    asked: Option<Asked>,
    /// The structure under the pointer (index, its own name).
    pub named: Option<(usize, String)>,
    /// Where the pointer meets it (RAS mm).
    pub point: Option<glam::Vec3>,
}

#[derive(Clone, Copy, PartialEq)]
struct Asked {
    pointer: egui::Pos2,
    camera: OrbitCamera,
    plane: [f32; 4],
    case: (u64, u64, usize),
}

impl Pointing {
    /// Finds the structure under the pointer over the view (`response`), names it beside the
    /// pointer (in the reader's language) unless `quiet` (a quiz asks for it), and returns it
    /// when it was clicked.
    /// `plane` is the view's clipping plane.
    pub fn update(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        (camera, plane): (&OrbitCamera, [f32; 4]),
        doc: &Document,
        quiet: bool,
    ) -> Option<usize> {
        let pointer = response.hover_pos().filter(|_| !response.dragged());
        let Some(pointer) = pointer else {
            self.asked = None;
            self.named = None;
            self.point = None;
            return None;
        };
        let session = doc.session();
        let asked = Asked {
            pointer,
            camera: *camera,
            plane,
            case: (
                session.case().case_version(),
                session.case().revision(),
                session.case().as_case().structures.len(),
            ),
        };
        if self.asked != Some(asked) {
            let rect = response.rect;
            let at = Vec2::new(pointer.x - rect.left(), pointer.y - rect.top());
            let ray = camera.ray_through(at, Vec2::new(rect.width(), rect.height()));
            let hit = ray.and_then(|ray| {
                crate::view::structure_at(&session.case().as_case().structures, &ray, plane)
            });
            self.point = hit.map(|(_, h)| h.point);
            self.named = hit.and_then(|(i, _)| {
                Some((i, session.case().as_case().structures.get(i)?.name.clone()))
            });
            self.asked = Some(asked);
        }
        let index = self.named.as_ref()?.0;
        let name = doc.words().name(index).to_string();
        if quiet {
            return response.clicked().then_some(index);
        }
        let font = egui::TextStyle::Body.resolve(ui.style());
        let place = pointer + egui::vec2(14.0, -6.0);
        let painter = ui.painter_at(response.rect);
        let galley = painter.layout_no_wrap(name, font, egui::Color32::WHITE);
        let back = egui::Rect::from_min_size(place, galley.size()).expand(3.0);
        painter.rect_filled(back, 3.0, egui::Color32::from_black_alpha(170));
        painter.galley(place, galley, egui::Color32::WHITE);
        response.clicked().then_some(index)
    }
}
