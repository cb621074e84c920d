//! The case glTF's export under the Structure list: whether to simplify and how far, then the
//! file written a structure at a time, its size and triangles shown before it is saved.

use eframe::egui;

use super::structure_list::StructureAction;
use crate::case::WindowPreset;
use crate::export::{CaseGltfOptions, Simplification};
use crate::session::Session;

/// The author's choice of export between frames.
pub struct ExportChoice {
    simplify: bool,
    /// The simplified surface's largest distance from the smoothed one, in each structure's
    /// voxel diagonals.
    voxel_diagonals: f64,
    /// The window an image chosen next is read with.
    preset: WindowPreset,
}

impl Default for ExportChoice {
    fn default() -> Self {
        Self {
            simplify: false,
            voxel_diagonals: 0.1,
            preset: WindowPreset::CtSoftTissue,
        }
    }
}

impl ExportChoice {
    /// The case glTF's options as chosen: compressed, with the local error.
    pub fn options(&self) -> CaseGltfOptions {
        CaseGltfOptions {
            local_error: true,
            simplify: (self.simplify)
                .then_some(Simplification::VoxelDiagonals(self.voxel_diagonals)),
            ..CaseGltfOptions::default()
        }
    }

    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        actions: &mut Vec<StructureAction>,
    ) {
        self.image_row(ui, session, actions);
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.simplify, "Simplify within")
                .on_hover_text("Fewer triangles for the download: each surface stays closed, within this many of its voxel diagonals of the smoothed one");
            ui.add_enabled(
                self.simplify,
                egui::DragValue::new(&mut self.voxel_diagonals)
                    .range(0.01..=1.0)
                    .speed(0.005)
                    .max_decimals(2),
            );
            ui.label("voxel diagonals");
        });
        ui.horizontal(|ui| {
            if let Some(p) = session.case_export().progress() {
                let bar = egui::ProgressBar::new(p.structures_done as f32 / p.structures.max(1) as f32)
                    .desired_width(160.0)
                    .text(format!(
                        "Writing {} of {}: {}",
                        p.structures_done,
                        p.structures,
                        megabytes(p.bytes)
                    ));
                ui.add(bar);
                if ui.button("Cancel").clicked() {
                    actions.push(StructureAction::CancelExport);
                }
                return;
            }
            if ui
                .button("Write case (GLB)")
                .on_hover_text("Every structure as shown, smoothed ones with their originals and records, in metres with Y up, compressed; its size shows before it is saved")
                .clicked()
            {
                actions.push(StructureAction::ExportCase(self.options()));
            }
            if let Some(w) = session.case_export().written() {
                let how = match w.options.simplify {
                    Some(Simplification::VoxelDiagonals(d)) => format!("simplified within {d} voxel diagonals: "),
                    Some(Simplification::TriangleBudget(n)) => format!("simplified to about {n} triangles: "),
                    None => String::new(),
                };
                ui.label(format!("Written, {how}{}, {} triangles", megabytes(w.bytes.len()), w.triangles));
                if ui.button("Save").clicked() {
                    actions.push(StructureAction::SaveCase);
                }
            }
        });
        if let Some(e) = session.case_export().error() {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Not written: {e}"));
        }
    }

    /// The image under the surfaces: the one the case carries, with what it adds to the case
    /// glTF; else the window and the button to choose one.
    fn image_row(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        actions: &mut Vec<StructureAction>,
    ) {
        ui.horizontal_wrapped(|ui| match session.case().as_case().image.as_ref() {
            Some(image) => {
                let [i, j, k] = image.dims;
                let size = megabytes(image.voxels.len());
                ui.label(format!("Image {}: {i} x {j} x {k}, {}, {size}", image.source, image.preset))
                    .on_hover_text("Shown on the clipping plane and carried in the case glTF (this many bytes of it)");
                if ui.small_button("Remove").clicked() {
                    actions.push(StructureAction::RemoveImage);
                }
            }
            None => {
                egui::ComboBox::from_id_salt("image window")
                    .selected_text(self.preset.name())
                    .show_ui(ui, |ui| {
                        for preset in WindowPreset::ALL {
                            ui.selectable_value(&mut self.preset, preset, preset.name());
                        }
                    });
                if ui
                    .button("Add image...")
                    .on_hover_text("The CT or MRI the segmentation was drawn on (NIfTI, NRRD, MGH/MGZ, or every slice file of a DICOM series chosen together; on the segmentation's voxel grid), windowed to grey levels: shown on the clipping plane and carried in the case glTF")
                    .clicked()
                {
                    actions.push(StructureAction::AddImage(self.preset));
                }
            }
        });
    }
}

fn megabytes(bytes: usize) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}
