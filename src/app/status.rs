//! What the page says about work under way: the status bar's progress (a file read or opened,
//! the CPU engine's run) and the messages over the 3D view's top-left corner.

use super::document::Document;
use super::file_input::Reading;
use eframe::egui;

/// The status bar's progress: the file opening, else the file being read, else the CPU
/// engine's run; a spinner for work on the page without a measure of progress.
pub fn progress(ui: &mut egui::Ui, doc: &Document, reading: &[Reading]) {
    let bar = |ui: &mut egui::Ui, fraction: f32, width: f32, text: String| {
        ui.add(
            egui::ProgressBar::new(fraction)
                .desired_width(width)
                .text(text),
        );
    };
    if let Some(l) = doc.session().loading() {
        let text = format!("opening: {} ({}/{})", l.doing, l.stage + 1, l.total);
        bar(ui, l.fraction, 220.0, text);
    } else if let Some(fraction) = reading.first().and_then(|r| r.fraction()) {
        bar(
            ui,
            fraction,
            220.0,
            format!("reading {:.0}%", 100.0 * fraction),
        );
    } else if doc.busy() && reading.is_empty() && doc.working_elsewhere() {
        // A spinner asks for every frame it can get; the worker's reply wakes the page.
        ui.label("smoothing…");
    } else if doc.busy() || !reading.is_empty() {
        ui.spinner();
    }
}

/// The messages over the view: an error (`extra_error` when the session has none), files
/// being read and opened, and whether the original is shown.
pub fn view_messages(
    ui: &egui::Ui,
    doc: &Document,
    extra_error: Option<&str>,
    reading: &[Reading],
    showing_original: bool,
) -> Vec<(String, egui::Color32)> {
    let mut lines = Vec::new();
    if let Some(error) = doc.session().error().or(extra_error) {
        lines.push((error.to_string(), ui.visuals().error_fg_color));
    }
    for r in reading {
        lines.push((format!("{}…", r.describe()), egui::Color32::WHITE));
    }
    if let Some(l) = doc.session().loading() {
        let text = format!("Opening {}: {}…", l.name, l.doing);
        lines.push((text, egui::Color32::WHITE));
    }
    if showing_original {
        let text = "Showing the original mesh (B to go back)".to_string();
        lines.push((text, egui::Color32::WHITE));
    }
    lines
}

/// Paints `lines` over `rect`'s top-left corner, each on a dark backing.
pub fn paint_messages(ui: &egui::Ui, rect: egui::Rect, lines: Vec<(String, egui::Color32)>) {
    let painter = ui.painter_at(rect);
    let mut y = rect.top() + 10.0;
    for (text, color) in lines {
        let galley = painter.layout(
            text,
            egui::FontId::proportional(15.0),
            color,
            rect.width() * 0.6,
        );
        let at = egui::pos2(rect.left() + 12.0, y);
        painter.rect_filled(
            egui::Rect::from_min_size(at, galley.size()).expand(6.0),
            4.0,
            egui::Color32::from_black_alpha(170),
        );
        y += galley.size().y + 16.0;
        painter.galley(at, galley, color);
    }
}
