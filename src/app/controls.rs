//! The side panel's controls: the filter with a slider and a number field per parameter, the
//! displacement bound (in mm, or voxel diagonals when the voxel size is known), the measures of the current result, and what the colours show.
//!
//! The panels edit the case document alone. Every edit goes to it as a whole parameter set;
//! it refuses invalid sets (e.g. Taubin's mu >= -lambda) and the message shows under the controls until fixed.

use super::backend::EngineTimings;
use crate::session::{CaseDocument, ColorField};
use crate::smooth::{Filter, Params};
use eframe::egui;

/// What the controls keep between frames.
#[derive(Default)]
pub struct Controls {
    /// Why the last edit was refused.
    refused: Option<String>,
    /// The displacement bound is entered in voxel diagonals (when the voxel size is known).
    bound_in_voxels: bool,
}

/// A user-facing name for each filter.
pub fn filter_label(f: Filter) -> &'static str {
    match f {
        Filter::Laplace => "Laplace",
        Filter::Taubin => "Taubin λ/μ",
        Filter::Hc => "Laplace + HC",
        Filter::Sinc => "Windowed sinc",
    }
}

fn slider(
    ui: &mut egui::Ui,
    label: &str,
    help: &str,
    value: &mut f32,
    range: std::ops::RangeInclusive<f32>,
) {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(help);
        ui.add(
            egui::Slider::new(value, range)
                .max_decimals(3)
                .clamping(egui::SliderClamping::Always),
        )
        .on_hover_text(help);
    });
}

/// The sliders of the active filter's own parameters.
fn filter_sliders(ui: &mut egui::Ui, p: &mut Params) {
    match p.filter {
        Filter::Laplace => slider(
            ui,
            "λ",
            "Step towards the neighbours' mean per iteration",
            &mut p.lambda,
            0.0..=1.0,
        ),
        Filter::Taubin => {
            slider(
                ui,
                "λ",
                "Shrinking step per iteration",
                &mut p.lambda,
                0.01..=1.0,
            );
            slider(
                ui,
                "μ",
                "Inflating step per iteration; needs μ < −λ",
                &mut p.mu,
                -1.0..=-0.01,
            );
        }
        Filter::Hc => {
            slider(
                ui,
                "α",
                "Pull back towards the original positions",
                &mut p.alpha,
                0.0..=1.0,
            );
            slider(
                ui,
                "β",
                "Pull back towards the previous iteration",
                &mut p.beta,
                0.0..=1.0,
            );
        }
        Filter::Sinc => {
            ui.horizontal(|ui| {
                let help = "Pass band: lower removes more detail";
                ui.label("pass band").on_hover_text(help);
                ui.add(
                    egui::Slider::new(&mut p.passband, 0.001..=1.999)
                        .logarithmic(true)
                        .max_decimals(4),
                )
                .on_hover_text(help);
            });
        }
    }
}

impl Controls {
    /// The filter and its parameters.
    pub fn filter(&mut self, ui: &mut egui::Ui, case: &mut CaseDocument) {
        let mut p: Params = *case.params();
        ui.horizontal_wrapped(|ui| {
            for f in Filter::ALL {
                if ui
                    .selectable_label(case.filter() == f, filter_label(f))
                    .clicked()
                {
                    case.set_filter(f);
                    p = *case.params();
                }
            }
        });
        ui.add_space(4.0);
        filter_sliders(ui, &mut p);
        let max_it = if p.filter == Filter::Sinc { 100 } else { 50 };
        let min_it = if p.filter == Filter::Sinc { 1 } else { 0 };
        ui.horizontal(|ui| {
            ui.label("iterations");
            ui.add(egui::Slider::new(&mut p.iterations, min_it..=max_it));
        });
        let voxel = case.voxel_diagonal().map(|d| d as f32);
        ui.horizontal(|ui| {
            let mut bounded = p.max_displacement.is_some();
            ui.checkbox(&mut bounded, "max displacement")
                .on_hover_text("No vertex moves further than this from its original position");
            match (bounded, p.max_displacement) {
                // Half a voxel diagonal is the natural bound (ALGORITHMS.md) where it is known.
                (true, None) => p.max_displacement = Some(voxel.map_or(1.0, |v| 0.5 * v)),
                (false, Some(_)) => p.max_displacement = None,
                _ => {}
            }
            if let Some(d) = &mut p.max_displacement {
                self.bound_field(ui, d, voxel);
            }
        });
        if ui.small_button("Defaults").clicked() {
            p = Params::defaults(p.filter);
        }
        if p != *case.params() {
            self.refused = case.set_params(p).err();
        }
        if let Some(why) = &self.refused {
            ui.colored_label(ui.visuals().warn_fg_color, why);
        }
    }
}

impl Controls {
    /// The displacement bound `d` (mm), entered in mm or, when the voxel diagonal `voxel`
    /// (mm) is known and chosen, in voxel diagonals.
    fn bound_field(&mut self, ui: &mut egui::Ui, d: &mut f32, voxel: Option<f32>) {
        match voxel.filter(|_| self.bound_in_voxels) {
            Some(v) => {
                let mut in_voxels = *d / v;
                let field = egui::DragValue::new(&mut in_voxels)
                    .speed(0.01)
                    .range(0.0..=1000.0 / v)
                    .max_decimals(3)
                    .suffix(" vd");
                if ui.add(field).changed() {
                    *d = in_voxels * v;
                }
                ui.weak(format!("= {:.3} mm", *d));
            }
            None => {
                ui.add(
                    egui::DragValue::new(d)
                        .speed(0.01)
                        .range(0.0..=1000.0)
                        .suffix(" mm"),
                );
            }
        }
        if voxel.is_some() {
            ui.selectable_value(&mut self.bound_in_voxels, false, "mm");
            ui.selectable_value(&mut self.bound_in_voxels, true, "vd")
                .on_hover_text("In voxel diagonals of the voxel size below");
        }
    }
}

fn percent(v: f64) -> String {
    format!("{:+.2} %", v * 100.0)
}

/// The measures of the latest result, as a table.
pub fn measures(ui: &mut egui::Ui, case: &CaseDocument, timings: Option<EngineTimings>) {
    let Some(result) = case.last_result() else {
        ui.label("Not smoothed yet.");
        return;
    };
    let m = &result.metrics;
    let vd = case.voxel_diagonal();
    let mm = |v: f64| match vd {
        Some(d) => format!("{v:.3} mm ({:.2} vd)", v / d),
        None => format!("{v:.3} mm"),
    };
    egui::Grid::new("measures")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            let mut row = |label: &str, help: &str, value: String| {
                ui.label(label).on_hover_text(help);
                ui.monospace(value);
                ui.end_row();
            };
            row(
                "Volume change",
                "Change of the enclosed volume against the original",
                m.volume_change
                    .map_or("undefined (open mesh)".into(), percent),
            );
            row(
                "Curvature K/K0",
                "Mean |Gaussian curvature| against the original's: lower is smoother",
                format!("{:.4}", m.score_terms().curvature_ratio),
            );
            row(
                "Mean error",
                "Mean local distance of the vertices from the original surface",
                mm(m.mean_error),
            );
            row(
                "Max error",
                "Largest local distance from the original surface",
                mm(m.max_error),
            );
            row(
                "Score S",
                "Paper's quality score for tau = 0.5: lower is better",
                format!("{:.4}", m.score),
            );
        });
    if case.result().is_none() {
        ui.small("Updating…");
    } else if let Some(t) = timings {
        ui.small(t.describe());
    }
}

/// What the colours show (None: plain shading), and the voxel size for voxel-diagonal units.
pub fn coloring(ui: &mut egui::Ui, field: &mut Option<ColorField>, case: &mut CaseDocument) {
    ui.horizontal_wrapped(|ui| {
        ui.selectable_value(field, None, "Shading");
        for f in ColorField::ALL {
            ui.selectable_value(field, Some(f), f.name());
        }
    });
    let mut known = case.voxel_size().is_some();
    let mut size = case.voxel_size().unwrap_or([1.0; 3]);
    ui.horizontal(|ui| {
        ui.checkbox(&mut known, "voxel size").on_hover_text(
            "The segmentation's voxel spacing: distances then also read in voxel diagonals (vd)",
        );
        if known {
            for s in &mut size {
                ui.add(
                    egui::DragValue::new(s)
                        .speed(0.01)
                        .range(0.01..=100.0)
                        .max_decimals(3),
                );
            }
            ui.label("mm");
        }
    });
    let wanted = known.then_some(size);
    if wanted != case.voxel_size() {
        // The drag values' range keeps the sizes valid.
        let _ = case.set_voxel_size(wanted);
    }
}
