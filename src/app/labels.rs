//! The case's labels over the 3D view: a dot on the point, a leader line out to the text, the
//! text on a dark plate so it reads over any surface; a label goes with its structure.

use std::collections::HashSet;

use eframe::egui;
use glam::Vec2;

use super::document::Document;
use super::viewer::Viewer;
use crate::view::{label_spots, LabelSpot, OrbitCamera, Ray};

/// The labels' spots as last worked out, and for what: each label's fading casts a ray through
/// every opaque structure, so it is done again only when the view or the case changed.
#[derive(Default)]
pub struct LabelPainter {
    asked: Option<Asked>,
    spots: Vec<LabelSpot>,
}

#[derive(Clone, Copy, PartialEq)]
struct Asked {
    camera: OrbitCamera,
    plane: [f32; 4],
    size: [f32; 2],
    /// The case's version (its lesson and looks) and its results' revision (its surfaces).
    case: (u64, u64),
}

impl LabelPainter {
    /// Draws the labels of the open case that the view shows; returns each drawn label's
    /// text, its point on the page and whether it is faded.
    pub fn paint(
        &mut self,
        ui: &egui::Ui,
        rect: egui::Rect,
        viewer: &Viewer,
        doc: &Document,
    ) -> Vec<(String, [f32; 2], bool)> {
        let labels = &doc.case().lesson().labels;
        if labels.is_empty() {
            return Vec::new();
        }
        let asked = Asked {
            camera: *viewer.camera(),
            plane: viewer.clip_plane(),
            size: [rect.width(), rect.height()],
            case: (doc.case().case_version(), doc.case().revision()),
        };
        if self.asked != Some(asked) {
            self.spots = spots(rect, viewer, doc);
            self.asked = Some(asked);
        }
        draw(ui, rect, &self.spots, doc)
    }
}

/// Where the case's labels go in the view, and which are faded.
fn spots(rect: egui::Rect, viewer: &Viewer, doc: &Document) -> Vec<LabelSpot> {
    let labels = &doc.case().lesson().labels;
    let visible: HashSet<&str> = (doc.case().case_structures().iter())
        .filter(|s| s.visible)
        .map(|s| s.name.as_str())
        .collect();
    let shown = |name: &str| visible.contains(name);
    let size = Vec2::new(rect.width(), rect.height());
    let plane = viewer.clip_plane();
    let structures = doc.case().case_structures();
    let nearest = |ray: &Ray, structure: &str| {
        let (i, hit) = doc.case().opaque_at(ray, plane)?;
        Some((hit.distance, structures[i].name == structure))
    };
    label_spots(labels, shown, (viewer.camera(), nearest), size, plane)
}

/// The labels at `spots`, each with its point, leader line and text.
fn draw(
    ui: &egui::Ui,
    rect: egui::Rect,
    spots: &[LabelSpot],
    doc: &Document,
) -> Vec<(String, [f32; 2], bool)> {
    let labels = &doc.case().lesson().labels;
    let painter = ui.painter_at(rect);
    let font = egui::FontId::proportional(14.0);
    let mut drawn = Vec::with_capacity(spots.len());
    for spot in spots {
        let Some(label) = labels.get(spot.index) else {
            continue;
        };
        // A label whose point lies behind a surface stays, faint, so it does not jump away.
        let (ink, shade) = match spot.faded {
            false => (egui::Color32::from_gray(240), 170),
            true => (egui::Color32::from_gray(240).gamma_multiply(0.35), 60),
        };
        let at = |v: Vec2| rect.min + egui::vec2(v.x, v.y);
        let (point, text) = (at(spot.point), at(spot.text));
        painter.line_segment([point, text], egui::Stroke::new(1.5, ink));
        painter.circle_filled(point, 3.0, ink);
        let said = doc.label_text(label).to_string();
        let galley = painter.layout_no_wrap(said.clone(), font.clone(), ink);
        // The text on the side of its end away from the point, unless the view's edge would
        // cut it there.
        let width = galley.size().x;
        let (before, after) = (text.x - width - 6.0, text.x + 6.0);
        let left = match spot.text.x < spot.point.x {
            true if before < rect.left() => after,
            false if after + width > rect.right() => before,
            true => before,
            false => after,
        };
        let corner = egui::pos2(left, text.y - galley.size().y / 2.0);
        let plate = egui::Rect::from_min_size(corner, galley.size()).expand(3.0);
        painter.rect_filled(plate, 3.0, egui::Color32::from_black_alpha(shade));
        painter.galley(corner, galley, ink);
        drawn.push((said, [point.x, point.y], spot.faded));
    }
    drawn
}
