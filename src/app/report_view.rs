//! The validation report as a table, with the warnings under it.

use crate::mesh::MeshReport;
use crate::session::Model;
use eframe::egui;

pub fn show(ui: &mut egui::Ui, model: &Model) {
    let r = &model.report;
    ui.heading(&model.name);
    ui.add_space(4.0);
    egui::Grid::new("mesh_report")
        .num_columns(2)
        .striped(true)
        .spacing([24.0, 4.0])
        .show(ui, |ui| {
            for (label, value) in rows(r) {
                ui.label(label);
                ui.monospace(value);
                ui.end_row();
            }
        });
    ui.add_space(8.0);
    if model.warnings.is_empty() {
        ui.label("No problems found: the mesh is closed, manifold and in one piece.");
    } else {
        ui.label(egui::RichText::new("Warnings").strong());
        for warning in &model.warnings {
            ui.colored_label(ui.visuals().warn_fg_color, format!("• {warning}"));
        }
    }
}

/// The report's fields as `(label, value)` rows, in the order of `meshsmooth info`.
fn rows(r: &MeshReport) -> Vec<(&'static str, String)> {
    let yes_no = |b: bool| if b { "yes" } else { "no" }.to_string();
    let point = |p: [f32; 3]| format!("({:.2}, {:.2}, {:.2})", p[0], p[1], p[2]);
    vec![
        ("Vertices", r.vertices.to_string()),
        ("Faces", r.faces.to_string()),
        ("Unreferenced vertices", r.unreferenced_vertices.to_string()),
        ("Degenerate faces", r.degenerate_faces.to_string()),
        ("Duplicate faces", r.duplicate_faces.to_string()),
        ("Boundary edges", r.boundary_edges.to_string()),
        ("Non-manifold edges", r.nonmanifold_edges.to_string()),
        ("Non-manifold vertices", r.nonmanifold_vertices.to_string()),
        ("Components", r.components.to_string()),
        ("Euler characteristic", r.euler.to_string()),
        (
            "Genus",
            r.genus
                .map_or("undefined (open or non-manifold)".into(), |g| g.to_string()),
        ),
        ("Closed", yes_no(r.closed)),
        (
            "Volume",
            r.volume
                .map_or("undefined (open mesh)".into(), |v| format!("{v:.1} mm³")),
        ),
        ("Bounding box min", point(r.bbox_min)),
        ("Bounding box max", point(r.bbox_max)),
    ]
}
