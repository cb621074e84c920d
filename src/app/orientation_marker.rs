//! The orientation marker in the view's top-right corner: the patient's axes as the camera
//! sees them, each end lettered (R/L, A/P, S/I), so a reader always knows which side is which.

use eframe::egui;

use crate::view::OrbitCamera;

/// The marker's radius in points.
const RADIUS: f32 = 26.0;

/// Grey, not the usual red, green and blue: the letters tell the axes apart, and no colour
/// of the marker can be taken for a structure's or a measure's.
const NEAR: egui::Color32 = egui::Color32::from_gray(225);
const FAR: egui::Color32 = egui::Color32::from_gray(130);

/// Paints the marker in `view`'s top-right corner for `camera`.
pub fn paint(ui: &egui::Ui, view: egui::Rect, camera: &OrbitCamera) {
    if view.width() < 6.0 * RADIUS || view.height() < 6.0 * RADIUS {
        return;
    }
    let centre = egui::pos2(view.right() - RADIUS - 16.0, view.top() + RADIUS + 16.0);
    let (right, up) = camera.screen_axes();
    let toward_eye = camera.direction();
    let painter = ui.painter_at(view);
    painter.circle_filled(centre, RADIUS + 12.0, egui::Color32::from_black_alpha(90));
    let font = egui::FontId::proportional(12.0);
    // RAS: +x the patient's right, +y anterior, +z superior. Farther ends first, so the
    // nearer ones are drawn over them.
    let mut ends: Vec<(f32, usize, glam::Vec3, &str)> = Vec::new();
    for (k, (plus, minus)) in [("R", "L"), ("A", "P"), ("S", "I")].into_iter().enumerate() {
        let axis = glam::Vec3::AXES[k];
        ends.push((axis.dot(toward_eye), k, axis, plus));
        ends.push((-axis.dot(toward_eye), k, -axis, minus));
    }
    ends.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (depth, k, axis, letter) in ends {
        let tip = centre + egui::vec2(axis.dot(right), -axis.dot(up)) * RADIUS;
        let color = if depth >= 0.0 { NEAR } else { FAR };
        let positive = letter == ["R", "A", "S"][k];
        let width = if positive { 2.5 } else { 1.2 };
        painter.line_segment([centre, tip], egui::Stroke::new(width, color));
        let label = centre + (tip - centre) * 1.32;
        painter.text(
            label,
            egui::Align2::CENTER_CENTER,
            letter,
            font.clone(),
            color,
        );
    }
}
