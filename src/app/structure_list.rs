//! The Structure list: every structure of an open segmentation with its colour, opacity and
//! visibility (the eye shows or hides it, S shows it alone); the one selected is the model the
//! smoothing, the graphs, the brush and the suggestions act on, and it can be renamed.

use eframe::egui;

use crate::session::{Session, StructureChange};

/// What the author did in the list this frame.
pub enum StructureAction {
    Select(usize),
    Change(usize, StructureChange),
    Solo(usize),
    /// The case's title and description as edited.
    CaseText(String, String),
    ExportCase,
    /// "Suggest all" at the Suggest panel's tau, or cancel it.
    SuggestAll,
    CancelSuggestAll,
}

/// The list's state between frames: the name being edited, the case's title and description.
#[derive(Default)]
pub struct StructureList {
    editing: Option<(usize, String)>,
    /// The title and description being edited, and the session's when they were taken (the
    /// API may change those: then the fields show the new ones).
    case_text: ((String, String), (String, String)),
}

fn to_bytes(c: [f32; 4]) -> [u8; 4] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

impl StructureList {
    /// Shows the list when the model is a structure of a segmentation.
    pub fn show(&mut self, ui: &mut egui::Ui, session: &Session) -> Vec<StructureAction> {
        let mut actions = Vec::new();
        let (Some(structures), looks) = (session.structures(), session.structure_looks()) else {
            return actions;
        };
        ui.heading("Structures");
        egui::ScrollArea::vertical()
            .max_height(220.0)
            .id_salt("structure list")
            .show(ui, |ui| {
                for (i, (s, look)) in structures.list.iter().zip(looks).enumerate() {
                    ui.horizontal(|ui| {
                        let mut visible = look.visible;
                        if ui
                            .checkbox(&mut visible, "")
                            .on_hover_text("Show or hide")
                            .changed()
                        {
                            let change = StructureChange {
                                visible: Some(visible),
                                ..Default::default()
                            };
                            actions.push(StructureAction::Change(i, change));
                        }
                        let mut rgba = to_bytes(look.color);
                        let button = ui.color_edit_button_srgba_unmultiplied(&mut rgba);
                        if button.changed() {
                            let c = rgba.map(|v| f32::from(v) / 255.0);
                            let change = StructureChange {
                                color: Some([c[0], c[1], c[2]]),
                                opacity: Some(c[3]),
                                ..Default::default()
                            };
                            actions.push(StructureAction::Change(i, change));
                        }
                        if ui.small_button("S").on_hover_text("Show alone").clicked() {
                            actions.push(StructureAction::Solo(i));
                        }
                        let selected = i == structures.current;
                        let label =
                            ui.selectable_label(selected, &look.name)
                                .on_hover_text(format!(
                                    "label {}, {} voxels, {} vertices, {} triangles",
                                    s.label,
                                    s.voxels,
                                    s.mesh.vertex_count(),
                                    s.mesh.triangle_count()
                                ));
                        if label.clicked() && !selected {
                            actions.push(StructureAction::Select(i));
                        }
                    });
                }
            });
        let current = structures.current;
        if let Some(look) = looks.get(current) {
            let name = match &mut self.editing {
                Some((i, name)) if *i == current => name,
                editing => &mut editing.insert((current, look.name.clone())).1,
            };
            ui.horizontal(|ui| {
                ui.label("Name");
                let edit = ui.text_edit_singleline(name);
                if edit.lost_focus() && name.trim() != look.name {
                    let change = StructureChange {
                        name: Some(name.clone()),
                        ..Default::default()
                    };
                    actions.push(StructureAction::Change(current, change));
                }
            });
        }
        self.case_fields(ui, session, &mut actions);
        ui.separator();
        actions
    }

    /// The case's title and description, and its export.
    fn case_fields(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        actions: &mut Vec<StructureAction>,
    ) {
        let stored = (
            session.case_title().to_string(),
            session.case_description().to_string(),
        );
        if self.case_text.1 != stored {
            self.case_text = (stored.clone(), stored);
        }
        let (title, description) = &mut self.case_text.0;
        ui.horizontal(|ui| {
            ui.label("Case");
            let edit = ui.add(egui::TextEdit::singleline(title).hint_text("title"));
            if edit.lost_focus() {
                actions.push(StructureAction::CaseText(
                    title.clone(),
                    description.clone(),
                ));
            }
        });
        let edit = ui.add(
            egui::TextEdit::multiline(description)
                .hint_text("description")
                .desired_rows(2),
        );
        if edit.lost_focus() {
            actions.push(StructureAction::CaseText(
                title.clone(),
                description.clone(),
            ));
        }
        ui.horizontal(|ui| match session.suggest_all_progress() {
            Some((done, total)) => {
                let bar = egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                    .desired_width(160.0)
                    .text(format!("Suggest all: {done} of {total}"));
                ui.add(bar);
                if ui.button("Cancel").clicked() {
                    actions.push(StructureAction::CancelSuggestAll);
                }
            }
            None => {
                let tip = "The suggestion at the Suggest panel's τ for every structure, each with \
                           its own filter and bound, then smoothed with it";
                if ui.button("Suggest all").on_hover_text(tip).clicked() {
                    actions.push(StructureAction::SuggestAll);
                }
            }
        });
        if ui
            .button("Export case (GLB)")
            .on_hover_text("Every structure as shown, smoothed ones with their originals and records, in metres with Y up")
            .clicked()
        {
            actions.push(StructureAction::ExportCase);
        }
    }
}
