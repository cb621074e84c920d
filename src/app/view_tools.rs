//! The view's own tools, over its bottom-left corner: the standard views (A P L R S I), the
//! clipping plane (axial, coronal or sagittal, where along the scene, which side is kept; or
//! the case's image in its three planes, each moved through the image by its own slider) and
//! the slide from the segmentation to the smoothed surfaces. The
//! view takes them up from the document, where the API sets them too.

use eframe::egui;

use super::document::ViewAsks;
use super::layout::PageRect;
use crate::view::{Clip, ClipAxis, Planes, StandardView};

/// Draws the tools along the bottom of `view` and records what was asked in `asks`: one row,
/// or two on a narrow view (a phone), three there while the image's planes are shown. With the
/// case's image, the image's three planes are one more choice. Returns where the planes'
/// sliders were drawn (sagittal, coronal, axial), while they are shown.
pub fn show(
    ui: &mut egui::Ui,
    view: egui::Rect,
    asks: &mut ViewAsks,
    has_image: bool,
) -> Vec<PageRect> {
    let narrow = view.width() < 560.0;
    let rows = match (narrow, asks.planes.is_some()) {
        (false, _) => 1.0,
        (true, false) => 2.0,
        (true, true) => 3.0,
    };
    let height = 28.0 * rows + 2.0;
    let bar = egui::Rect::from_min_max(
        egui::pos2(view.left() + 6.0, view.bottom() - height),
        egui::pos2(view.right() - 6.0, view.bottom()),
    );
    let row = egui::Layout::left_to_right(egui::Align::Center);
    let mut sliders = Vec::new();
    if narrow {
        let builder = egui::UiBuilder::new()
            .max_rect(bar)
            .layout(egui::Layout::top_down(egui::Align::Min));
        ui.scope_builder(builder, |ui| {
            ui.horizontal(|ui| {
                sides(ui, asks);
                ui.separator();
                clip(ui, asks, has_image);
            });
            if let Some(planes) = &mut asks.planes {
                ui.horizontal(|ui| sliders = plane_sliders(ui, planes));
            }
            ui.horizontal(|ui| slide(ui, asks));
        });
    } else {
        ui.scope_builder(egui::UiBuilder::new().max_rect(bar).layout(row), |ui| {
            sides(ui, asks);
            ui.separator();
            clip(ui, asks, has_image);
            if let Some(planes) = &mut asks.planes {
                sliders = plane_sliders(ui, planes);
            }
            ui.separator();
            slide(ui, asks);
        });
    }
    sliders
}

/// A P L R S I: look from that side of the patient.
fn sides(ui: &mut egui::Ui, asks: &mut ViewAsks) {
    ui.label("View");
    for side in StandardView::ALL {
        let tip = format!("Look from the patient's {side:?} side").to_lowercase();
        if ui.small_button(side.letter()).on_hover_text(tip).clicked() {
            asks.look_from = Some(side);
        }
    }
}

/// What the plane menu shows: nothing, a clip along an axis, or the image's three planes.
#[derive(Clone, Copy, PartialEq)]
enum Shown {
    Nothing,
    Clip(ClipAxis),
    Planes,
}

/// The clipping plane: its axis (or none, or the image's three planes), where it lies, which
/// side is kept.
fn clip(ui: &mut egui::Ui, asks: &mut ViewAsks, has_image: bool) {
    let mut shown = match (asks.planes, asks.clip) {
        (Some(_), _) => Shown::Planes,
        (None, Some(c)) => Shown::Clip(c.axis),
        (None, None) => Shown::Nothing,
    };
    let name = |s: Shown| match s {
        Shown::Nothing => "no clip",
        Shown::Clip(axis) => axis.name(),
        Shown::Planes => "3 planes",
    };
    egui::ComboBox::from_id_salt("clip axis")
        .width(82.0)
        .selected_text(name(shown))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut shown, Shown::Nothing, "no clip");
            for a in ClipAxis::ALL {
                ui.selectable_value(&mut shown, Shown::Clip(a), a.name());
            }
            if has_image {
                ui.selectable_value(&mut shown, Shown::Planes, "3 planes")
                    .on_hover_text("The image's axial, coronal and sagittal planes together");
            }
        })
        .response
        .on_hover_text("A plane that cuts every structure, to see what lies inside");
    asks.planes = match shown {
        Shown::Planes => Some(asks.planes.unwrap_or_default()),
        _ => None,
    };
    asks.clip = match (shown, asks.clip) {
        (Shown::Nothing | Shown::Planes, _) => None,
        (Shown::Clip(a), Some(c)) => Some(Clip { axis: a, ..c }),
        (Shown::Clip(a), None) => Some(Clip {
            axis: a,
            at: 0.5,
            flip: false,
        }),
    };
    if let Some(clip) = &mut asks.clip {
        ui.add(egui::Slider::new(&mut clip.at, 0.0..=1.0).show_value(false))
            .on_hover_text("Where the plane lies across the scene");
        ui.toggle_value(&mut clip.flip, "flip")
            .on_hover_text("Keep the other side");
    }
}

/// Where each of the image's planes lies across the scene: S, C and A, as a radiology viewer
/// scrolls through its slices.
fn plane_sliders(ui: &mut egui::Ui, planes: &mut Planes) -> Vec<PageRect> {
    ui.spacing_mut().slider_width = 56.0;
    let each = [
        (
            "S",
            "The sagittal plane, from the patient's right to left",
            &mut planes.sagittal,
        ),
        (
            "C",
            "The coronal plane, from back to front",
            &mut planes.coronal,
        ),
        ("A", "The axial plane, from feet to head", &mut planes.axial),
    ];
    (each.into_iter())
        .map(|(letter, tip, at)| {
            ui.label(letter);
            let slider = ui.add(egui::Slider::new(at, 0.0..=1.0).show_value(false));
            slider.on_hover_text(tip).rect.into()
        })
        .collect()
}

/// The slide from the segmentation to the smoothed surfaces.
fn slide(ui: &mut egui::Ui, asks: &mut ViewAsks) {
    ui.label("segmentation");
    let mut smoothed = 1.0 - asks.toward_segmentation;
    let slide = egui::Slider::new(&mut smoothed, 0.0..=1.0).show_value(false);
    if ui
        .add(slide)
        .on_hover_text("Slide every structure back to the segmentation it was made from")
        .changed()
    {
        asks.toward_segmentation = 1.0 - smoothed;
    }
    ui.label("smoothed");
}
