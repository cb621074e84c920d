//! The Structure list: every structure of the open case, by group, with its colour, opacity and
//! visibility (the box shows or hides it, S shows it alone); the one selected is the model the
//! smoothing, the graphs, the brush and the suggestions act on, and it can be renamed and
//! grouped. Files added join the case.

use eframe::egui;

use super::layout::{PanelLayout, StructureRow};
use crate::case::{names, CaseStructure};
use crate::metrics::Metrics;
use crate::session::{Session, StructureChange};

/// What the author did in the list this frame.
pub enum StructureAction {
    Select(usize),
    Change(usize, StructureChange),
    Solo(usize),
    /// The case's title and description as edited.
    CaseText(String, String),
    /// Choose files whose structures join the case.
    Add,
    /// Choose the image under the case's surfaces, windowed by the preset.
    AddImage(crate::case::WindowPreset),
    /// Take the image from under the surfaces.
    RemoveImage,
    /// Check the structures against each other (what lies inside what, what crosses).
    Check,
    /// Write the case glTF with these options (its size shows before it is saved).
    ExportCase(crate::export::CaseGltfOptions),
    CancelExport,
    /// Save the case glTF written.
    SaveCase,
    /// "Suggest all" at the Suggest panel's tau, or cancel it.
    SuggestAll,
    CancelSuggestAll,
}

/// The list's state between frames: the name and group being edited, the case's title and
/// description.
#[derive(Default)]
pub struct StructureList {
    editing: Option<Editing>,
    /// The title and description being edited, and the session's when they were taken (the
    /// API may change those: then the fields show the new ones).
    case_text: ((String, String), (String, String)),
    /// Shows only the structures whose name or group contains it.
    filter: String,
    export: super::case_export_view::ExportChoice,
}

/// The model's name, group and description as edited, and what the session had when they
/// were taken: a new model, or a change made elsewhere (the API), shows the session's again.
struct Editing {
    /// The session's model and the structure it is.
    key: (u64, usize),
    /// Name, group, description and the names in other languages as one line.
    taken: [String; 4],
    text: [String; 4],
    /// Why the names line as typed was not taken.
    names_error: Option<String>,
}

fn to_bytes(c: [f32; 4]) -> [u8; 4] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

impl StructureList {
    /// Shows the open case's structures, ungrouped ones first, then each group's; `layout`
    /// gets where the rows and the Name field were drawn.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        layout: &mut PanelLayout,
    ) -> Vec<StructureAction> {
        layout.structures.clear();
        layout.structure_name = None;
        layout.structure_filter = None;
        let mut actions = Vec::new();
        let Some(current) = session.case().current_structure() else {
            return actions;
        };
        let list = session.case().as_case().structures.as_slice();
        ui.horizontal(|ui| {
            ui.heading("Structures");
            let tip = "Open more files (meshes, a label map, a case glTF) into this case";
            if ui.button("Add files…").on_hover_text(tip).clicked() {
                actions.push(StructureAction::Add);
            }
        });
        filter_field(ui, &mut self.filter, list.len(), layout);
        let flagged = session.background().flagged_structures();
        egui::ScrollArea::vertical()
            .max_height(220.0)
            .id_salt("structure list")
            .show(ui, |ui| {
                grouped_rows(ui, list, &self.filter, |ui, i, s| {
                    let flag = flagged.contains(&i);
                    let measures = measures(s, session, i);
                    let state = (i == current, flag);
                    let drawn = row(ui, (i, s, &measures), state, &mut actions);
                    layout.structures.push(drawn);
                });
            });
        if let Some(s) = list.get(current) {
            self.selected_fields(ui, session, (current, s), layout, &mut actions);
        }
        self.case_fields(ui, session, &mut actions);
        ui.separator();
        actions
    }

    /// The selected structure's name, group and description to edit, and how it is smoothed.
    fn selected_fields(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        (current, s): (usize, &CaseStructure),
        layout: &mut PanelLayout,
        actions: &mut Vec<StructureAction>,
    ) {
        let key = (session.case().model_id(), current);
        let group = s.group.clone().unwrap_or_default();
        let names_line = names::to_line(&s.names);
        let stored = [s.name.clone(), group, s.description.clone(), names_line];
        let editing = match &mut self.editing {
            Some(e) if e.key == key && e.taken == stored => e,
            editing => editing.insert(Editing {
                key,
                taken: stored.clone(),
                text: stored,
                names_error: None,
            }),
        };
        let [name, group, description, names_line] = &mut editing.text;
        ui.horizontal(|ui| {
            ui.label("Name");
            let edit = ui.add(egui::TextEdit::singleline(name).desired_width(110.0));
            layout.structure_name = Some(edit.rect.into());
            if edit.lost_focus() && name.trim() != s.name {
                let change = StructureChange {
                    name: Some(name.clone()),
                    ..Default::default()
                };
                actions.push(StructureAction::Change(current, change));
            }
            ui.label("Group");
            let edit = ui.add(
                egui::TextEdit::singleline(group)
                    .hint_text("none")
                    .desired_width(80.0),
            );
            if edit.lost_focus() && Some(group.trim()) != s.group.as_deref() {
                let change = StructureChange {
                    group: Some(Some(group.clone())),
                    ..Default::default()
                };
                actions.push(StructureAction::Change(current, change));
            }
        });
        let edit = ui.add(
            egui::TextEdit::multiline(description)
                .hint_text("description for readers")
                .desired_rows(2)
                .desired_width(f32::INFINITY),
        );
        if edit.lost_focus() && description.trim() != s.description {
            let change = StructureChange {
                description: Some(description.clone()),
                ..Default::default()
            };
            actions.push(StructureAction::Change(current, change));
        }
        let error = &mut editing.names_error;
        names_field(ui, (current, s), (names_line, error), actions);
        let [how, what] = measures(s, session, current);
        ui.small(how);
        ui.small(what);
    }

    /// The case's title and description, and its export.
    fn case_fields(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        actions: &mut Vec<StructureAction>,
    ) {
        let stored = (
            session.case().as_case().title.to_string(),
            session.case().as_case().description.to_string(),
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
        let background = session.background();
        let progress = background.suggest_all_progress();
        let now = super::document::now_ms();
        ui.horizontal(|ui| match progress {
            Some((done, total)) => {
                let work = background.suggest_all_work_done().unwrap_or(0.0);
                let left = (background.suggest_all_seconds_left(now))
                    .map_or(String::new(), |s| format!(" · {} left", about(s)));
                let bar = egui::ProgressBar::new(work as f32)
                    .desired_width((ui.available_width() - 70.0).max(120.0))
                    .text(format!("{done} of {total}{left}"));
                ui.add(bar).on_hover_text(
                    "Suggest all: the structures done, and the time left at the pace so far",
                );
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
        self.export.show(ui, session, actions);
        ui.horizontal(|ui| {
            if session.background().checking() {
                // No spinner: it would draw frames for as long as a worker checks.
                ui.label("checking…");
            } else if ui
                .button("Check structures")
                .on_hover_text("Does each structure that lay inside another still lie inside it, and do surfaces that did not cross now cross?")
                .clicked()
            {
                actions.push(StructureAction::Check);
            }
        });
        checks_report(ui, session);
    }
}

/// The last checks' lines, warnings in the warning colour.
fn checks_report(ui: &mut egui::Ui, session: &Session) {
    let Some(report) = session.background().checks_report() else {
        return;
    };
    if let Some(error) = report["error"].as_str() {
        ui.colored_label(
            ui.visuals().error_fg_color,
            format!("Checks failed: {error}"),
        );
        return;
    }
    for line in report["text"].as_str().unwrap_or_default().lines() {
        match line.strip_prefix("warning: ") {
            Some(warning) => ui.colored_label(ui.visuals().warn_fg_color, format!("⚠ {warning}")),
            None => ui.small(line),
        };
    }
    if report["current"] == false {
        ui.small("(the case changed since: check again)");
    } else if session.background().marks_key().is_some() {
        ui.small("Where: marked in magenta in the view, seen through what lies in front.");
    }
}

/// A structure's smoothing and its measures as shown, a line each: the filter and parameters;
/// the volume change and the local error, mean and maximum (mm, and in voxel diagonals where
/// the voxel size is known).
pub fn measures(s: &CaseStructure, session: &Session, i: usize) -> [String; 2] {
    if session.case().shown_as_read(i) {
        return [
            "no smoothing record".into(),
            "shown as the file holds it".into(),
        ];
    }
    let params = s.params;
    let how = format!("{}: {}", params.filter.name(), params.describe());
    let what = match session.case().structure_metrics(i) {
        Some(m) => measured(m, s.voxel_diagonal()),
        None if i == session.case().current_structure().unwrap_or(usize::MAX) => {
            "smoothing…".into()
        }
        None => "not smoothed".into(),
    };
    [how, what]
}

fn measured(m: &Metrics, diagonal: Option<f64>) -> String {
    let volume = m.volume_change.map_or("volume –".into(), |v| {
        format!("volume {:+.2}%", 100.0 * v)
    });
    let error = |mm: f64| match diagonal {
        Some(d) if d > 0.0 => format!("{mm:.3} mm ({:.2} vd)", mm / d),
        _ => format!("{mm:.3} mm"),
    };
    format!(
        "{volume}, error mean {}, max {}",
        error(m.mean_error),
        error(m.max_error)
    )
}

/// More structures than this and the list offers a filter by name.
const FILTER_FROM: usize = 8;

/// The filter field over a list of `count` structures, when it has enough to need one;
/// `layout` gets where it was drawn.
pub fn filter_field(
    ui: &mut egui::Ui,
    filter: &mut String,
    count: usize,
    layout: &mut PanelLayout,
) {
    layout.structure_filter = None;
    if count <= FILTER_FROM && filter.is_empty() {
        return;
    }
    ui.horizontal(|ui| {
        let field = ui.add(
            egui::TextEdit::singleline(filter)
                .hint_text("filter by name or group")
                .desired_width(160.0),
        );
        layout.structure_filter = Some(field.rect.into());
        if !filter.is_empty() && ui.small_button("×").on_hover_text("Clear").clicked() {
            filter.clear();
        }
    });
}

/// The structures of `list` that `filter` keeps, ungrouped ones first, then each group under a
/// header that folds (open while a filter is set); `row` draws one.
pub fn grouped_rows(
    ui: &mut egui::Ui,
    list: &[CaseStructure],
    filter: &str,
    mut row: impl FnMut(&mut egui::Ui, usize, &CaseStructure),
) {
    for (group, rows) in crate::case::listed(list, filter) {
        let mut draw = |ui: &mut egui::Ui| {
            for &i in &rows {
                row(ui, i, &list[i]);
            }
        };
        match group {
            None => draw(ui),
            Some(name) => {
                let title = format!("{name} ({})", rows.len());
                egui::CollapsingHeader::new(egui::RichText::new(title).strong())
                    .id_salt(("group", name))
                    .default_open(true)
                    .open((!filter.trim().is_empty()).then_some(true))
                    .show(ui, draw);
            }
        }
    }
}

/// The structure's names in other languages as one line to edit (`de: Leber; fr: Foie`), and
/// why the line typed was not taken.
fn names_field(
    ui: &mut egui::Ui,
    (current, s): (usize, &CaseStructure),
    (line, error): (&mut String, &mut Option<String>),
    actions: &mut Vec<StructureAction>,
) {
    ui.horizontal(|ui| {
        ui.label("Other languages");
        let edit = egui::TextEdit::singleline(line)
            .hint_text("de: Leber; fr: Foie")
            .desired_width(f32::INFINITY);
        let edit = ui.add(edit).on_hover_text(
            "The structure's name in the languages a student may read, each as a language tag \
             (de, fr, pt-BR), a colon and the name; the viewer shows the student's",
        );
        if edit.lost_focus() {
            *error = None;
            match names::from_line(line) {
                Ok(typed) if typed != s.names => {
                    let change = StructureChange {
                        names: Some(typed),
                        ..Default::default()
                    };
                    actions.push(StructureAction::Change(current, change));
                }
                Ok(_) => {}
                Err(e) => *error = Some(e),
            }
        }
    });
    if let Some(e) = error {
        ui.colored_label(ui.visuals().error_fg_color, e.as_str());
    }
}

/// The box that shows or hides structure `i` (`s`).
pub fn show_box(
    ui: &mut egui::Ui,
    (i, s): (usize, &CaseStructure),
    actions: &mut Vec<StructureAction>,
) -> egui::Response {
    let mut visible = s.visible;
    let visibility = ui.checkbox(&mut visible, "").on_hover_text("Show or hide");
    if visibility.changed() {
        let change = StructureChange {
            visible: Some(visible),
            ..Default::default()
        };
        actions.push(StructureAction::Change(i, change));
    }
    visibility
}

/// The button that shows structure `i` alone (again: every structure).
pub fn solo_button(
    ui: &mut egui::Ui,
    i: usize,
    actions: &mut Vec<StructureAction>,
) -> egui::Response {
    let solo = ui
        .small_button("S")
        .on_hover_text("Show alone (again: show all)");
    if solo.clicked() {
        actions.push(StructureAction::Solo(i));
    }
    solo
}

/// One structure's row: visibility, colour with opacity, show alone, its name to select (its
/// measures on hover), its volume change, and a warning sign when the last checks flagged it.
fn row(
    ui: &mut egui::Ui,
    (i, s, [how, what]): (usize, &CaseStructure, &[String; 2]),
    (selected, flagged): (bool, bool),
    actions: &mut Vec<StructureAction>,
) -> StructureRow {
    ui.horizontal(|ui| {
        let visibility = show_box(ui, (i, s), actions);
        let mut rgba = to_bytes(s.color);
        if ui.color_edit_button_srgba_unmultiplied(&mut rgba).changed() {
            let c = rgba.map(|v| f32::from(v) / 255.0);
            let change = StructureChange {
                color: Some([c[0], c[1], c[2]]),
                opacity: Some(c[3]),
                ..Default::default()
            };
            actions.push(StructureAction::Change(i, change));
        }
        let solo = solo_button(ui, i, actions);
        let mut about = format!(
            "{} vertices, {} triangles",
            s.original.vertex_count(),
            s.original.triangle_count()
        );
        if let (Some(label), Some(voxels)) = (s.label, s.voxels) {
            about = format!("label {label}, {voxels} voxels, {about}");
        }
        if let Some(source) = &s.source {
            about = format!("{about}\nfrom {source}");
        }
        let about = format!("{about}\n{how}\n{what}");
        let label = ui.selectable_label(selected, &s.name).on_hover_text(about);
        if label.clicked() && !selected {
            actions.push(StructureAction::Select(i));
        }
        if let Some(change) = what
            .strip_prefix("volume ")
            .and_then(|w| w.split(',').next())
        {
            ui.weak(change)
                .on_hover_text("Volume change against the segmentation");
        }
        if flagged {
            ui.colored_label(ui.visuals().warn_fg_color, "⚠")
                .on_hover_text("The last checks warn of this structure: see below the list");
        }
        StructureRow {
            index: i,
            visible: visibility.rect.into(),
            solo: solo.rect.into(),
            name: label.rect.into(),
        }
    })
    .inner
}

/// A time still to come, as a person says it: "about 40 s", "about 3 min".
fn about(seconds: f64) -> String {
    if seconds < 90.0 {
        format!("about {:.0} s", (seconds / 5.0).ceil().max(1.0) * 5.0)
    } else {
        format!("about {:.0} min", (seconds / 60.0).round())
    }
}
