//! The viewer's panel (`?mode=viewer`), for a student reading a case: its title and
//! description, its structures by group to show, hide, isolate and make transparent, and the
//! selected one's name, description, provenance and quality record, with its local error on
//! demand; structures are named in the reader's language where the case has a name in it.
//! Nothing here edits the anatomy.

use eframe::egui;

use super::layout::{PanelLayout, StructureRow};
use super::structure_list::{
    filter_field, grouped_rows, measures, show_box, solo_button, StructureAction,
};
use crate::case::{names, CaseStructure};
use crate::io::StructureCodes;
use crate::session::{Session, StructureChange};

/// Shows the panel to a reader of `languages` (most wanted first); `error_colours` is whether
/// the selected structure is coloured by how far it moved from the segmentation. `layout` gets
/// where the rows were drawn.
pub fn show(
    ui: &mut egui::Ui,
    (session, languages): (&Session, &[String]),
    layout: &mut PanelLayout,
    (filter, error_colours): (&mut String, &mut bool),
) -> Vec<StructureAction> {
    layout.structures.clear();
    layout.structure_name = None;
    layout.structure_filter = None;
    let mut actions = Vec::new();
    let Some(current) = session.case().current_structure() else {
        return actions;
    };
    let list = session.case().as_case().structures.as_slice();
    let title = session.case().as_case().title.as_str();
    ui.heading(if title.is_empty() {
        session.case().case_file()
    } else {
        title
    });
    if !session.case().as_case().description.is_empty() {
        ui.label(session.case().as_case().description.as_str());
    }
    ui.separator();
    ui.horizontal(|ui| {
        ui.strong("Structures");
        if list.iter().any(|s| !s.visible) && ui.small_button("Show all").clicked() {
            for (i, _) in list.iter().enumerate().filter(|(_, s)| !s.visible) {
                let change = StructureChange {
                    visible: Some(true),
                    ..Default::default()
                };
                actions.push(StructureAction::Change(i, change));
            }
        }
    });
    filter_field(ui, filter, list.len(), layout);
    egui::ScrollArea::vertical()
        .max_height(ui.available_height() * 0.5)
        .id_salt("case structures")
        .show(ui, |ui| {
            grouped_rows(ui, list, filter, |ui, i, s| {
                let shown = names::pick(&s.name, &s.names, languages);
                let drawn = row(ui, (i, s, shown), i == current, &mut actions);
                layout.structures.push(drawn);
            });
        });
    ui.separator();
    if let Some(s) = list.get(current) {
        let shown = names::pick(&s.name, &s.names, languages);
        record(ui, session, (s, shown), current, error_colours);
    }
    actions
}

/// One structure: show box, its colour, show alone, its opacity, its `shown` name to select.
fn row(
    ui: &mut egui::Ui,
    (i, s, shown): (usize, &CaseStructure, &str),
    selected: bool,
    actions: &mut Vec<StructureAction>,
) -> StructureRow {
    ui.horizontal(|ui| {
        let visibility = show_box(ui, (i, s), actions);
        let [r, g, b, _] = s.color.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let (swatch, _) = ui.allocate_exact_size(egui::vec2(14.0, 14.0), egui::Sense::hover());
        ui.painter()
            .rect_filled(swatch, 3.0, egui::Color32::from_rgb(r, g, b));
        let solo = solo_button(ui, i, actions);
        let mut opacity = s.color[3];
        let slider = egui::Slider::new(&mut opacity, 0.0..=1.0).show_value(false);
        if ui
            .add_sized([60.0, 14.0], slider)
            .on_hover_text("Opacity")
            .changed()
        {
            let change = StructureChange {
                opacity: Some(opacity),
                ..Default::default()
            };
            actions.push(StructureAction::Change(i, change));
        }
        let name = ui.selectable_label(selected, shown);
        if name.clicked() && !selected {
            actions.push(StructureAction::Select(i));
        }
        StructureRow {
            index: i,
            visible: visibility.rect.into(),
            solo: solo.rect.into(),
            name: name.rect.into(),
        }
    })
    .inner
}

/// The selected structure: what it is, where it came from, how it was smoothed and how far its
/// surface lies from the segmentation.
fn record(
    ui: &mut egui::Ui,
    session: &Session,
    (s, shown): (&CaseStructure, &str),
    index: usize,
    error_colours: &mut bool,
) {
    ui.heading(shown);
    if let Some(others) = other_names(s, shown) {
        ui.small(others)
            .on_hover_text("Its names in the case's other languages");
    }
    if let Some(group) = &s.group {
        ui.label(format!("in {group}"));
    }
    if !s.description.is_empty() {
        ui.label(&s.description);
    }
    if let Some(codes) = &s.codes {
        ui.small(codes_line(codes)).on_hover_text(
            "What the structure is in standard codes (coding scheme, code, meaning), as a \
             learning platform or a DICOM segmentation names it",
        );
    }
    let mut about = format!(
        "{} vertices, {} triangles",
        s.original.vertex_count(),
        s.original.triangle_count()
    );
    if let Some(source) = &s.source {
        about = format!("from {source}; {about}");
    }
    if let Some(v) = s.voxel_size {
        about = format!("{about}; voxels {:.2} × {:.2} × {:.2} mm", v[0], v[1], v[2]);
    }
    ui.small(about);
    let [how, what] = measures(s, session, index);
    if session.case().shown_as_read(index) {
        ui.label(format!("No smoothing record: {what}"));
    } else {
        ui.label(format!("Smoothed with {how}"));
        ui.label(what);
    }
    ui.checkbox(error_colours, "Colour by how far it moved")
        .on_hover_text(
            "The local error: the distance from each point of the smooth surface to the \
             segmentation's surface",
        );
}

/// The structure's names other than the `shown` one: its own, then each by language tag.
fn other_names(s: &CaseStructure, shown: &str) -> Option<String> {
    let own = (s.name != shown).then(|| s.name.clone());
    let others = (s.names.iter())
        .filter(|(_, n)| n.as_str() != shown)
        .map(|(tag, n)| format!("{tag}: {n}"));
    let all: Vec<String> = own.into_iter().chain(others).collect();
    (!all.is_empty()).then(|| format!("Also: {}", all.join("; ")))
}

/// "SNOMED CT 64033007 Kidney, 24028007 Right (Anatomical Structure)".
fn codes_line(codes: &StructureCodes) -> String {
    let scheme = |s: &str| match s {
        "SCT" => "SNOMED CT".to_string(),
        other => other.to_string(),
    };
    let mut line = format!(
        "{} {} {}",
        scheme(&codes.kind.scheme),
        codes.kind.value,
        codes.kind.meaning
    );
    if let Some(m) = &codes.modifier {
        line = format!("{line}, {} {}", m.value, m.meaning);
    }
    format!("{line} ({})", codes.category.meaning)
}
