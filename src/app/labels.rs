//! The case's labels over the 3D view: a dot on the point, a leader line out to the text, the
//! text on a dark plate so it reads over any surface; a label goes with its structure. A label
//! with a note shows a mark on its plate, and a click (a tap) on the plate shows the note under
//! it or hides it again.

use std::collections::HashSet;

use eframe::egui;
use glam::Vec2;

use super::document::Document;
use super::layout::DrawnLabel;
use super::viewer::Viewer;
use crate::view::{label_spots, LabelSpot, OrbitCamera, Ray};

/// The labels' spots as last worked out, and for what: each label's fading casts a ray through
/// every opaque structure, so it is done again only when the view or the case changed.
#[derive(Default)]
pub struct LabelPainter {
    asked: Option<Asked>,
    spots: Vec<LabelSpot>,
    /// The label whose note is shown (its index in the lesson).
    open: Option<usize>,
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
    /// Draws the labels of the open case that the view shows, taking clicks on their plates;
    /// returns them as drawn.
    pub fn paint(
        &mut self,
        ui: &egui::Ui,
        rect: egui::Rect,
        viewer: &Viewer,
        doc: &Document,
    ) -> Vec<DrawnLabel> {
        let labels = &doc.session().case().lesson().labels;
        if labels.is_empty() {
            return Vec::new();
        }
        let asked = Asked {
            camera: *viewer.camera(),
            plane: viewer.clip_plane(),
            size: [rect.width(), rect.height()],
            case: (
                doc.session().case().case_version(),
                doc.session().case().revision(),
            ),
        };
        if self.asked.is_some_and(|a| a.case != asked.case) {
            // Another lesson may number its labels otherwise.
            self.open = None;
        }
        if self.asked != Some(asked) {
            self.spots = spots(rect, viewer, doc);
            self.asked = Some(asked);
        }
        draw(ui, rect, &self.spots, doc, &mut self.open)
    }
}

/// Where the case's labels go in the view, and which are faded.
fn spots(rect: egui::Rect, viewer: &Viewer, doc: &Document) -> Vec<LabelSpot> {
    let labels = &doc.session().case().lesson().labels;
    let visible: HashSet<&str> = (doc.session().case().as_case().structures.iter())
        .filter(|s| s.visible)
        .map(|s| s.name.as_str())
        .collect();
    let shown = |name: &str| visible.contains(name);
    let size = Vec2::new(rect.width(), rect.height());
    let plane = viewer.clip_plane();
    let structures = doc.session().case().as_case().structures.as_slice();
    let nearest = |ray: &Ray, structure: &str| {
        let (i, hit) =
            crate::view::opaque_at(&doc.session().case().as_case().structures, ray, plane)?;
        Some((hit.distance, structures[i].name == structure))
    };
    label_spots(labels, shown, (viewer.camera(), nearest), size, plane)
}

/// The labels at `spots`, each with its point, leader line and text, and the open one's note.
fn draw(
    ui: &egui::Ui,
    rect: egui::Rect,
    spots: &[LabelSpot],
    doc: &Document,
    open: &mut Option<usize>,
) -> Vec<DrawnLabel> {
    let labels = &doc.session().case().lesson().labels;
    let painter = ui.painter_at(rect);
    let font = egui::FontId::proportional(14.0);
    let mut drawn = Vec::with_capacity(spots.len());
    let mut note_at = None;
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
        let said = doc.words().label_text(label).to_string();
        let note = doc.words().label_note(label).trim().to_string();
        let galley = painter.layout_no_wrap(said.clone(), font.clone(), ink);
        // Room on the plate for the note's mark.
        let mark = if note.is_empty() { 0.0 } else { MARK + 4.0 };
        let left = plate_left(spot, rect, text, galley.size().x + mark);
        let corner = egui::pos2(left, text.y - galley.size().y / 2.0);
        let size = galley.size() + egui::vec2(mark, 0.0);
        let plate = egui::Rect::from_min_size(corner, size).expand(3.0);
        painter.rect_filled(plate, 3.0, egui::Color32::from_black_alpha(shade));
        painter.galley(corner, galley, ink);
        let is_open = !note.is_empty() && *open == Some(spot.index);
        if !note.is_empty() {
            let centre = egui::pos2(plate.right() - 3.0 - MARK / 2.0, plate.center().y);
            paint_mark(&painter, centre, ink, is_open);
            let id = ui.scope_id().with(("label note", spot.index));
            let clicked = (ui.interact(plate, id, egui::Sense::click()))
                .on_hover_cursor(egui::CursorIcon::PointingHand)
                .clicked();
            if clicked {
                *open = (!is_open).then_some(spot.index);
            }
        }
        if is_open {
            note_at = Some((plate, note.clone()));
        }
        drawn.push(DrawnLabel {
            text: said,
            point: [point.x, point.y],
            faded: spot.faded,
            plate: plate.into(),
            note,
            open: is_open,
        });
    }
    // Over every label, so no other plate hides it.
    if let Some((plate, note)) = note_at {
        paint_note(&painter, rect, plate, note);
    }
    drawn
}

/// Where a plate `width` wide starts: the text on the side of its end (`text`) away from the
/// point, unless the view's edge would cut it there.
fn plate_left(spot: &LabelSpot, rect: egui::Rect, text: egui::Pos2, width: f32) -> f32 {
    let (before, after) = (text.x - width - 6.0, text.x + 6.0);
    match spot.text.x < spot.point.x {
        true if before < rect.left() => after,
        false if after + width > rect.right() => before,
        true => before,
        false => after,
    }
}

/// The note mark's size (points).
const MARK: f32 = 12.0;

/// A ringed "i" saying the label has a note; filled while the note is shown.
fn paint_mark(painter: &egui::Painter, centre: egui::Pos2, ink: egui::Color32, open: bool) {
    let radius = MARK / 2.0;
    let on = egui::Color32::from_black_alpha(220);
    match open {
        true => painter.circle_filled(centre, radius, ink),
        false => painter.circle_stroke(centre, radius - 0.5, egui::Stroke::new(1.0, ink)),
    };
    let letter = if open { on } else { ink };
    let font = egui::FontId::proportional(10.0);
    painter.text(centre, egui::Align2::CENTER_CENTER, "i", font, letter);
}

/// The note under its label's plate (above it where the view ends first), wrapped, within
/// the view.
fn paint_note(painter: &egui::Painter, rect: egui::Rect, plate: egui::Rect, note: String) {
    let ink = egui::Color32::from_gray(235);
    let wrap = (rect.width() - 16.0).clamp(40.0, 280.0);
    let galley = painter.layout(note, egui::FontId::proportional(13.0), ink, wrap);
    let size = galley.size();
    let left = plate.left().clamp(
        rect.left() + 8.0,
        (rect.right() - 8.0 - size.x).max(rect.left()),
    );
    let below = plate.bottom() + 6.0;
    let top = match below + size.y + 8.0 > rect.bottom() {
        true => (plate.top() - 6.0 - size.y).max(rect.top() + 4.0),
        false => below,
    };
    let corner = egui::pos2(left, top);
    let back = egui::Rect::from_min_size(corner, size).expand(5.0);
    painter.rect_filled(back, 4.0, egui::Color32::from_black_alpha(215));
    painter.galley(corner, galley, ink);
}
