//! The Structure list: which structure of an open segmentation the smoothing acts on.

use eframe::egui;

/// The segmentation's structures, when the model is one of them: which one the smoothing acts
/// on. Returns the structure picked in this frame.
pub fn show(ui: &mut egui::Ui, session: &crate::session::Session) -> Option<usize> {
    let structures = session.structures()?;
    let mut picked = None;
    ui.heading("Structure");
    let swatch = |ui: &mut egui::Ui, c: [f32; 3]| {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
        let [r, g, b] = c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
        ui.painter()
            .rect_filled(rect, 2.0, egui::Color32::from_rgb(r, g, b));
    };
    let current = structures.current();
    ui.horizontal(|ui| {
        swatch(ui, current.color);
        egui::ComboBox::from_id_salt("structure")
            .selected_text(&current.name)
            .show_ui(ui, |ui| {
                for (i, s) in structures.list.iter().enumerate() {
                    ui.horizontal(|ui| {
                        swatch(ui, s.color);
                        let text = format!("{} ({} voxels)", s.name, s.voxels);
                        if ui.selectable_label(i == structures.current, text).clicked()
                            && i != structures.current
                        {
                            picked = Some(i);
                        }
                    });
                }
            });
    })
    .response
    .on_hover_text(format!(
        "{} structures in {}; label {}, {} voxels",
        structures.list.len(),
        structures.file,
        current.label,
        current.voxels
    ));
    ui.separator();
    picked
}
