//! Mouse, touch and wheel input over the view, turned into camera moves.
//!
//! The primary button drags the camera (drag orbits, shift+drag pans, double click resets),
//! the middle button orbits; on a touch screen one finger orbits, two pan and pinch to zoom.
//! Right drags are left to the caller through the view's `Response`.
//! While the caller paints with the primary button (`painting`), a plain primary drag is the
//! caller's too, and Ctrl/⌘ + drag orbits instead.

use eframe::egui;
use glam::Vec2;

use crate::view::OrbitCamera;

/// Zoom per point of wheel travel: one notch (100 points in Chromium) zooms by ~22%.
const ZOOM_PER_SCROLL_POINT: f32 = 0.002;

/// Moves `camera` by this frame's input over the view (the double click is the caller's).
pub fn apply(camera: &mut OrbitCamera, ui: &egui::Ui, response: &egui::Response, painting: bool) {
    let (shift, command) = ui.input(|i| (i.modifiers.shift, i.modifiers.command));
    let primary = response.dragged_by(egui::PointerButton::Primary);
    // Two fingers pan (and pinch, below); the first finger's drag does not orbit meanwhile.
    let fingers = ui
        .input(|i| i.multi_touch())
        .filter(|t| t.num_touches >= 2 && response.rect.contains(t.center_pos));
    if let Some(touch) = fingers {
        let size = response.rect.size();
        let moved = touch.translation_delta;
        camera.pan(moved.x, moved.y, Vec2::new(size.x, size.y));
    } else if primary && shift {
        let delta = response.drag_delta();
        let size = response.rect.size();
        camera.pan(delta.x, delta.y, Vec2::new(size.x, size.y));
        ui.ctx().set_cursor_icon(egui::CursorIcon::Grabbing);
    } else if (primary && (!painting || command))
        || response.dragged_by(egui::PointerButton::Middle)
    {
        let delta = response.drag_delta();
        camera.orbit(delta.x, delta.y);
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
