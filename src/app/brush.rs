//! The weight brush: with the brush on, a left drag over the view paints per-vertex smoothing
//! weights into the model's structure (lock, weaken or erase under a circle of a radius in mm), a circle
//! shows the brush's footprint under the pointer, and the view shows the weights.
//!
//! Picking and the footprint are [`crate::view`]'s; the weights are the case document's, and
//! what they do the engines'. A fast stroke is filled in with dabs spaced half a brush radius apart on screen.

use super::document::now_ms;
use crate::session::{CaseDocument, Dab};
use crate::view::{brush_footprint, pick_triangle, Hit, OrbitCamera};
use eframe::egui;
use glam::Vec2;

/// What a dab does to the weights under it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrushMode {
    /// Weight 0 at the centre: those vertices do not move.
    Lock,
    /// Lowers the weight at the centre by the strength.
    Weaken,
    /// Back towards 1 (free).
    Erase,
}

/// At most this many dabs per frame when the pointer moved far: keeps a frame short on large
/// meshes (each dab is a pick).
const MAX_DABS_PER_FRAME: usize = 12;

/// Which surface the last pick saw: the model generation and the shown positions' revision
/// (`None`: the original).
pub type SurfaceKey = (u64, Option<u64>);

/// The last pick under the pointer.
struct Hover {
    pointer: egui::Pos2,
    camera: OrbitCamera,
    surface: SurfaceKey,
    hit: Option<Hit>,
}

pub struct Brush {
    /// Left drags paint (and the view shows the weights) while on.
    pub active: bool,
    pub mode: BrushMode,
    /// Weaken: how much the centre's weight drops, 0..1.
    pub strength: f32,
    pub radius_mm: f32,
    /// How long the latest pick took (ms).
    pub pick_ms: Option<f64>,
    hover: Option<Hover>,
    /// Where the current stroke's last dab was.
    last_dab: Option<egui::Pos2>,
}

impl Default for Brush {
    fn default() -> Self {
        Self {
            active: false,
            mode: BrushMode::Lock,
            strength: 0.5,
            radius_mm: 5.0,
            pick_ms: None,
            hover: None,
            last_dab: None,
        }
    }
}

impl Brush {
    /// The brush's controls in the Smoothing panel.
    pub fn panel(&mut self, ui: &mut egui::Ui, case: &mut CaseDocument) {
        ui.horizontal(|ui| {
            ui.toggle_value(&mut self.active, "Weight brush")
                .on_hover_text(
                    "P: left drag paints where smoothing may act; Ctrl/⌘ + left drag or the \
                     middle button orbits meanwhile",
                );
            let painted = case.weights().is_some();
            if ui
                .add_enabled(painted, egui::Button::new("Clear"))
                .on_hover_text("Every vertex free again")
                .clicked()
            {
                case.clear_weights();
            }
        });
        if !self.active && case.weights().is_none() {
            return;
        }
        ui.horizontal(|ui| {
            for (mode, label, help) in [
                (
                    BrushMode::Lock,
                    "Lock",
                    "Weight 0: these vertices do not move",
                ),
                (
                    BrushMode::Weaken,
                    "Weaken",
                    "Lower the weight by the strength",
                ),
                (BrushMode::Erase, "Erase", "Back to weight 1 (free)"),
            ] {
                ui.selectable_value(&mut self.mode, mode, label)
                    .on_hover_text(help);
            }
        });
        if self.mode == BrushMode::Weaken {
            ui.horizontal(|ui| {
                ui.label("strength");
                ui.add(egui::Slider::new(&mut self.strength, 0.05..=1.0).max_decimals(2));
            });
        }
        ui.horizontal(|ui| {
            ui.label("radius");
            ui.add(
                egui::Slider::new(&mut self.radius_mm, 0.5..=50.0)
                    .logarithmic(true)
                    .max_decimals(1)
                    .suffix(" mm"),
            );
        });
        if let Some(w) = crate::session::WeightsSummary::of(case.weights()) {
            ui.small(format!(
                "{} vertices painted, {} locked (lowest weight {:.2})",
                w.painted, w.locked, w.min
            ));
        }
        if self.active {
            ui.small("The view shows the weights while the brush is on.");
        }
    }

    /// This frame's input over the view: picks under the pointer, paints while the left button
    /// is down (without Shift or Ctrl/⌘, which move the camera), and draws the brush's circle.
    /// `surface` names the positions the view shows (picks are made on them).
    pub fn interact(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        camera: &OrbitCamera,
        case: &mut CaseDocument,
        surface: SurfaceKey,
    ) {
        if !self.active {
            self.hover = None;
            self.last_dab = None;
            return;
        }
        let rect = response.rect;
        let size = Vec2::new(rect.width(), rect.height());
        let (pointer, painting) = stroke_input(ui, response, self.last_dab.is_some());

        let mut footprints = Vec::new();
        {
            let Some(model) = case.model() else {
                return;
            };
            let positions = match surface.1 {
                Some(_) => case
                    .last_result()
                    .map_or(&model.mesh().positions, |r| &r.positions),
                None => &model.mesh().positions,
            };
            let triangles = &model.mesh().triangles;
            let mut pick_ms = None;
            let mut pick = |at: egui::Pos2| {
                let ray =
                    camera.ray_through(Vec2::new(at.x - rect.left(), at.y - rect.top()), size)?;
                let start = now_ms();
                let hit = pick_triangle(positions, triangles, &ray);
                pick_ms = Some(now_ms() - start);
                hit
            };
            let Some(pointer) = pointer else {
                self.hover = None;
                self.last_dab = None;
                return;
            };
            let hover_hit = self.hover_at(pointer, camera, surface, &mut pick);

            if painting {
                let screen_radius = hover_hit.map_or(20.0, |h| {
                    self.radius_mm * camera.points_per_unit_at(h.point, size)
                });
                let spacing = (0.5 * screen_radius).max(2.0);
                let radius = self.radius_mm;
                let topology = model.topology();
                let under =
                    |hit: &Hit| brush_footprint(positions, triangles, topology, hit, radius);
                footprints = self.stroke_to((pointer, hover_hit), spacing, &mut pick, under);
            } else {
                self.last_dab = None;
            }
            if pick_ms.is_some() {
                self.pick_ms = pick_ms;
            }
        }
        for footprint in footprints {
            match self.mode {
                BrushMode::Lock => case.dab_weights(&footprint, Dab::Paint(0.0)),
                BrushMode::Weaken => case.dab_weights(&footprint, Dab::Paint(1.0 - self.strength)),
                BrushMode::Erase => case.dab_weights(&footprint, Dab::Erase),
            };
        }
        self.draw_circle(ui, camera, rect, size);
    }

    /// What lies under the pointer, picked again only when the pointer, the camera or the
    /// surface moved since.
    fn hover_at(
        &mut self,
        pointer: egui::Pos2,
        camera: &OrbitCamera,
        surface: SurfaceKey,
        pick: &mut impl FnMut(egui::Pos2) -> Option<Hit>,
    ) -> Option<Hit> {
        let fresh = self
            .hover
            .as_ref()
            .is_none_or(|h| h.pointer != pointer || h.camera != *camera || h.surface != surface);
        if fresh {
            let hit = pick(pointer);
            self.hover = Some(Hover {
                pointer,
                camera: *camera,
                surface,
                hit,
            });
        }
        self.hover.as_ref().and_then(|h| h.hit)
    }

    /// The stroke's dabs from the last one to the pointer (its hit known, `hover`), each
    /// picked on the surface and taken as the footprint `under` gives.
    fn stroke_to(
        &mut self,
        (pointer, hover): (egui::Pos2, Option<Hit>),
        spacing: f32,
        pick: &mut impl FnMut(egui::Pos2) -> Option<Hit>,
        under: impl Fn(&Hit) -> Vec<(u32, f32)>,
    ) -> Vec<Vec<(u32, f32)>> {
        let mut footprints = Vec::new();
        for at in dab_points(self.last_dab, pointer, spacing) {
            let hit = if at == pointer { hover } else { pick(at) };
            footprints.extend(hit.as_ref().map(&under));
            self.last_dab = Some(at);
        }
        footprints
    }

    /// The brush's footprint under the pointer: a circle of the brush's radius at the hit's
    /// depth, in the mode's colour.
    fn draw_circle(&self, ui: &egui::Ui, camera: &OrbitCamera, rect: egui::Rect, size: Vec2) {
        let Some(Hover {
            pointer,
            hit: Some(hit),
            ..
        }) = &self.hover
        else {
            return;
        };
        let radius = self.radius_mm * camera.points_per_unit_at(hit.point, size);
        if !(radius.is_finite() && radius > 0.5) {
            return;
        }
        let color = match self.mode {
            BrushMode::Lock => egui::Color32::from_rgb(90, 160, 255),
            BrushMode::Weaken => egui::Color32::from_rgb(170, 200, 240),
            BrushMode::Erase => egui::Color32::WHITE,
        };
        let painter = ui.painter_at(rect);
        painter.circle_stroke(
            *pointer,
            radius,
            egui::Stroke::new(3.0, egui::Color32::from_black_alpha(140)),
        );
        painter.circle_stroke(*pointer, radius, egui::Stroke::new(1.5, color));
        // The fully painted inner half of the falloff.
        painter.circle_stroke(
            *pointer,
            0.5 * radius,
            egui::Stroke::new(1.0, color.gamma_multiply(0.6)),
        );
        ui.ctx().set_cursor_icon(egui::CursorIcon::Crosshair);
    }
}

/// Where the pointer is over the view (or was, in the frame its button went up), and whether
/// it paints: the left button down on the view without Shift or Ctrl/⌘ (which move the camera).
/// A stroke (`stroking`) also takes the travel of the frame its button is released in.
fn stroke_input(
    ui: &egui::Ui,
    response: &egui::Response,
    stroking: bool,
) -> (Option<egui::Pos2>, bool) {
    let (down, released, moving_camera, latest) = ui.input(|i| {
        (
            i.pointer.primary_down(),
            i.pointer.primary_released(),
            i.modifiers.shift || i.modifiers.command,
            i.pointer.latest_pos(),
        )
    });
    let pointer = response.hover_pos().or(latest.filter(|_| down || released));
    let painting = !moving_camera
        && ((down && response.is_pointer_button_down_on()) || (released && stroking));
    (pointer, painting)
}

/// The dabs of a stroke from the last one to `pointer`, `spacing` points apart (the pointer
/// alone for a stroke's first); at most [`MAX_DABS_PER_FRAME`].
fn dab_points(last: Option<egui::Pos2>, pointer: egui::Pos2, spacing: f32) -> Vec<egui::Pos2> {
    let Some(last) = last else {
        return vec![pointer];
    };
    let steps = ((pointer - last).length() / spacing).floor() as usize;
    let steps = steps.min(MAX_DABS_PER_FRAME);
    (1..=steps)
        .map(|k| last + (pointer - last) * (k as f32 / steps as f32))
        .collect()
}
