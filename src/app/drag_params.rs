//! Window/level-style parameter dragging over the view: holding the right button, horizontal
//! travel drives one smoothing parameter and vertical travel another (chosen per filter in the
//! Smoothing panel), through the case document, so the mesh and the measures follow while dragging;
//! the values are drawn beside the cursor. The mapping is [`crate::view::dragged_params`].

use crate::session::CaseDocument;
use crate::smooth::{Filter, Params};
use crate::suggest::Param;
use crate::view::{default_drag_axes, drag_choices, dragged_params};
use eframe::egui;
use glam::Vec2;

/// The button that drags parameters.
const BUTTON: egui::PointerButton = egui::PointerButton::Secondary;

pub struct DragParams {
    /// `[horizontal, vertical]` per filter (in `Filter::ALL` order).
    axes: [[Param; 2]; 4],
    /// The parameters when the button went down, and where, while it is held.
    start: Option<(Params, egui::Pos2)>,
}

impl Default for DragParams {
    fn default() -> Self {
        Self {
            axes: Filter::ALL.map(default_drag_axes),
            start: None,
        }
    }
}

fn slot(filter: Filter) -> usize {
    Filter::ALL
        .iter()
        .position(|&f| f == filter)
        .unwrap_or_default()
}

/// A parameter's symbol, as the sliders name it.
fn label(param: Param) -> &'static str {
    match param {
        Param::Lambda => "λ",
        Param::Mu => "μ",
        Param::Alpha => "α",
        Param::Beta => "β",
        Param::Passband => "pass band",
        Param::Iterations => "iterations",
    }
}

fn value_text(param: Param, p: &Params) -> String {
    match param {
        Param::Iterations => p.iterations.to_string(),
        Param::Passband => format!("{}", param.get(p)),
        _ => format!("{:.2}", param.get(p)),
    }
}

impl DragParams {
    /// The two combo boxes that choose what a right drag drives for `filter`.
    pub fn panel(&mut self, ui: &mut egui::Ui, filter: Filter) {
        let choices = drag_choices(filter);
        let axes = &mut self.axes[slot(filter)];
        ui.label("Right drag over the view drives:").on_hover_text(
            "Hold the right button over the view: left/right drives the first parameter, \
             down/up the second (the whole range over about 400 points)",
        );
        ui.horizontal(|ui| {
            for (k, arrow) in ["↔", "↕"].into_iter().enumerate() {
                ui.label(arrow);
                egui::ComboBox::from_id_salt(("drag_axis", k))
                    .width(80.0)
                    .selected_text(label(axes[k]))
                    .show_ui(ui, |ui| {
                        for &c in &choices {
                            ui.selectable_value(&mut axes[k], c, label(c));
                        }
                    });
            }
        });
    }

    /// This frame's right-button input over the view: sets the parameters through the case
    /// document (the travel from where the button went down, so the frame it is released in counts
    /// too) and draws their values beside the cursor while the button is held.
    pub fn interact(&mut self, ui: &egui::Ui, response: &egui::Response, case: &mut CaseDocument) {
        let (pressed, held, origin, pointer) = ui.input(|i| {
            (
                i.pointer.button_pressed(BUTTON),
                i.pointer.button_down(BUTTON),
                i.pointer.press_origin(),
                i.pointer.latest_pos(),
            )
        });
        if pressed && response.is_pointer_button_down_on() {
            self.start = origin.map(|o| (*case.params(), o));
        }
        let (Some((start, origin)), Some(pointer)) = (self.start, pointer) else {
            self.start = None;
            return;
        };
        if start.filter != case.filter() {
            // The filter changed under the drag (a key): carry on from its values.
            self.start = Some((*case.params(), pointer));
            return;
        }
        let axes = self.axes[slot(start.filter)];
        let delta = pointer - origin;
        let p = dragged_params(&start, axes, Vec2::new(delta.x, delta.y));
        if p != *case.params() {
            // dragged_params keeps the parameters valid.
            let _ = case.set_params(p);
        }
        if !held {
            self.start = None;
            return;
        }
        let p = case.params();
        let text = if axes[0] == axes[1] {
            format!("{} {}", label(axes[0]), value_text(axes[0], p))
        } else {
            format!(
                "↔ {} {}\n↕ {} {}",
                label(axes[0]),
                value_text(axes[0], p),
                label(axes[1]),
                value_text(axes[1], p)
            )
        };
        let painter = ui.painter_at(response.rect);
        let galley =
            painter.layout_no_wrap(text, egui::FontId::proportional(15.0), egui::Color32::WHITE);
        let at = pointer + egui::vec2(18.0, 12.0);
        painter.rect_filled(
            egui::Rect::from_min_size(at, galley.size()).expand(5.0),
            4.0,
            egui::Color32::from_black_alpha(180),
        );
        painter.galley(at, galley, egui::Color32::WHITE);
        ui.ctx().set_cursor_icon(egui::CursorIcon::AllScroll);
    }
}
