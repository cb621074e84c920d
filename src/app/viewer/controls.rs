//! Mouse, touch and wheel input over the view, turned into camera moves.
//!
//! Only the primary button is used (drag orbits, shift+drag pans, double click resets): right
//! and middle drags are left to the caller through the view's `Response`.

use eframe::egui;
use glam::Vec2;

use crate::view::OrbitCamera;

/// Zoom per point of wheel travel: one notch (100 points in Chromium) zooms by ~22%.
const ZOOM_PER_SCROLL_POINT: f32 = 0.002;

/// Moves `camera` by this frame's input over the view (the double click is the caller's).
pub fn apply(camera: &mut OrbitCamera, ui: &egui::Ui, response: &egui::Response) {
    if response.dragged_by(egui::PointerButton::Primary) {
        let delta = response.drag_delta();
        if ui.input(|i| i.modifiers.shift) {
            let size = response.rect.size();
            camera.pan(delta.x, delta.y, Vec2::new(size.x, size.y));
        } else {
            camera.orbit(delta.x, delta.y);
        }
        ui.ctx().set_cursor_icon(egui::CursorIcon::Grabbing);
    }
    if response.contains_pointer() {
        // Wheel up (positive) zooms in; pinch and ctrl+wheel arrive as a zoom factor.
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        let factor = pinch * (scroll * ZOOM_PER_SCROLL_POINT).exp();
        if factor != 1.0 {
            camera.zoom(factor);
        }
    }
}
