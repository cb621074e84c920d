//! The colour legend beside the 3D view: the colour bar, its ticks in mm (and voxel diagonals
//! when known) and what the colours show. It takes a strip of its own at the view's right edge,
//! so no framing or turn of the model ever puts the model under it.

use crate::session::Legend;
use eframe::egui;

const BAR_WIDTH: f32 = 18.0;
/// Between the strip's edges and what it holds.
const MARGIN: f32 = 12.0;
/// Between the bar and its tick labels.
const LABEL_GAP: f32 = 8.0;
/// The bar's top, below the two title lines.
const BAR_TOP: f32 = 56.0;

fn title_font() -> egui::FontId {
    egui::FontId::proportional(14.0)
}

fn tick_font() -> egui::FontId {
    egui::FontId::proportional(13.0)
}

/// The legend's two title lines: what the colours show, and its unit.
fn title_lines(legend: &Legend) -> [String; 2] {
    [
        legend.field.name().to_string(),
        format!("({})", legend.field.unit()),
    ]
}

fn text_width(ui: &egui::Ui, text: &str, font: egui::FontId) -> f32 {
    ui.painter()
        .layout_no_wrap(text.to_string(), font, egui::Color32::WHITE)
        .size()
        .x
}

fn widest_label(ui: &egui::Ui, legend: &Legend) -> f32 {
    legend
        .ticks
        .iter()
        .map(|t| text_width(ui, &t.label, tick_font()))
        .fold(0.0, f32::max)
}

/// The width of the strip `legend` needs (points).
pub fn width(ui: &egui::Ui, legend: &Legend) -> f32 {
    let title = title_lines(legend)
        .iter()
        .map(|line| text_width(ui, line, title_font()))
        .fold(0.0, f32::max);
    let bar_and_labels = BAR_WIDTH + LABEL_GAP + widest_label(ui, legend);
    title.max(bar_and_labels) + 2.0 * MARGIN
}

/// Paints `legend` into `strip` (as wide as [`width`] says), on `background`.
pub fn paint(ui: &egui::Ui, strip: egui::Rect, legend: &Legend, background: egui::Color32) {
    let painter = ui.painter_at(strip);
    painter.rect_filled(strip, 0.0, background);
    let left = strip.left() + MARGIN;
    for (k, line) in title_lines(legend).into_iter().enumerate() {
        painter.text(
            egui::pos2(left, strip.top() + MARGIN + 18.0 * k as f32),
            egui::Align2::LEFT_TOP,
            line,
            title_font(),
            egui::Color32::WHITE,
        );
    }
    let height = (strip.height() * 0.5).clamp(120.0, 320.0);
    let bar = egui::Rect::from_min_size(
        egui::pos2(left, strip.top() + BAR_TOP),
        egui::vec2(BAR_WIDTH, height),
    );
    let n = legend.bar.len().max(1);
    for (k, c) in legend.bar.iter().enumerate() {
        // Bottom to top.
        let y1 = bar.bottom() - bar.height() * k as f32 / n as f32;
        let y0 = bar.bottom() - bar.height() * (k + 1) as f32 / n as f32;
        painter.rect_filled(
            egui::Rect::from_x_y_ranges(bar.x_range(), y0..=y1),
            0.0,
            egui::Color32::from_rgb(c[0], c[1], c[2]),
        );
    }
    painter.rect_stroke(
        bar,
        0.0,
        egui::Stroke::new(1.0, egui::Color32::from_gray(200)),
        egui::StrokeKind::Outside,
    );
    for t in &legend.ticks {
        let y = bar.bottom() - bar.height() * t.at;
        painter.line_segment(
            [egui::pos2(bar.right(), y), egui::pos2(bar.right() + 5.0, y)],
            egui::Stroke::new(1.0, egui::Color32::WHITE),
        );
        painter.text(
            egui::pos2(bar.right() + LABEL_GAP, y),
            egui::Align2::LEFT_CENTER,
            &t.label,
            tick_font(),
            egui::Color32::WHITE,
        );
    }
}
