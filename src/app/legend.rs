//! The colour legend drawn over the 3D view: the colour bar, its ticks in mm (and voxel
//! diagonals when known) and what the colours show.

use crate::session::Legend;
use eframe::egui;

/// Paints `legend` along the right edge of `rect`.
pub fn paint(ui: &egui::Ui, rect: egui::Rect, legend: &Legend) {
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    let font = egui::FontId::proportional(13.0);
    let bar_w = 18.0;
    let title = format!("{} ({})", legend.field.name(), legend.field.unit());
    let title_w = painter
        .layout_no_wrap(
            title.clone(),
            egui::FontId::proportional(14.0),
            egui::Color32::WHITE,
        )
        .size()
        .x;
    let label_w = legend
        .ticks
        .iter()
        .map(|t| {
            painter
                .layout_no_wrap(t.label.clone(), font.clone(), visuals.text_color())
                .size()
                .x
        })
        .fold(0.0f32, f32::max);
    let height = (rect.height() * 0.5).clamp(120.0, 320.0);
    let right = rect.right() - 16.0;
    let bar = egui::Rect::from_min_size(
        egui::pos2(right - label_w - 8.0 - bar_w, rect.top() + 48.0),
        egui::vec2(bar_w, height),
    );
    let left = (bar.left() - 10.0).min(right + 8.0 - title_w - 16.0);
    let back = egui::Rect::from_min_max(
        egui::pos2(left, bar.top() - 36.0),
        egui::pos2(right + 8.0, bar.max.y + 12.0),
    );
    painter.rect_filled(back, 6.0, egui::Color32::from_black_alpha(150));
    painter.text(
        egui::pos2(back.left() + 8.0, back.top() + 8.0),
        egui::Align2::LEFT_TOP,
        title,
        egui::FontId::proportional(14.0),
        egui::Color32::WHITE,
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
            egui::pos2(bar.right() + 8.0, y),
            egui::Align2::LEFT_CENTER,
            &t.label,
            font.clone(),
            egui::Color32::WHITE,
        );
    }
}
