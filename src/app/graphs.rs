//! The model quality graphs (paper section 5.2), one column per parameter of the active filter.
//!
//! The paper's users found three curves on one unlabelled axis confusing, so each measure has
//! its own strip with its own labelled axis, in its own unit: smoothness (K/K0), accuracy (mean
//! local error in mm, with half the voxel diagonal as a reference line when the voxel size is
//! known), the size of the volume change (%), and the score S(tau) with its minimum marked. A
//! dashed line marks the current value in every strip; clicking or dragging in any strip sets
//! the parameter. Where the filter diverges (the mesh comes out rougher than the original) the
//! curves break off and red bars mark the samples: those values are never suggested.

use super::layout::GraphColumn;
use crate::session::Session;
use crate::smooth::Params;
use crate::suggest::{Curve, Param};
use eframe::egui;
use egui_plot::{
    HLine, HoverPosition, Line, LineStyle, Plot, PlotPoint, PlotPoints, PlotUi, Points, VLine,
};

const CURVATURE: egui::Color32 = egui::Color32::from_rgb(0x5d, 0xa5, 0xda);
const ERROR: egui::Color32 = egui::Color32::from_rgb(0xfa, 0xa4, 0x3a);
const VOLUME: egui::Color32 = egui::Color32::from_rgb(0x60, 0xbd, 0x68);
const SCORE: egui::Color32 = egui::Color32::from_rgb(0xf1, 0x7c, 0xb0);
const CURRENT: egui::Color32 = egui::Color32::from_gray(230);
const REFERENCE: egui::Color32 = egui::Color32::from_rgb(0xb2, 0x76, 0xb2);
const DIVERGES: egui::Color32 = egui::Color32::from_rgba_premultiplied(0x70, 0x18, 0x18, 0x70);

/// One strip: which measure, how it reads.
struct Strip {
    title: &'static str,
    help: &'static str,
    color: egui::Color32,
    value: fn(&crate::suggest::Sample) -> Option<f64>,
}

const STRIPS: [Strip; 4] = [
    Strip {
        title: "Smoothness K/K0",
        help: "Mean |Gaussian curvature| against the original's. Lower is smoother: 1 is the \
               original, 0.5 has half its bumpiness.",
        color: CURVATURE,
        value: |s| Some(s.terms.curvature_ratio),
    },
    Strip {
        title: "Mean error (mm)",
        help: "Mean distance of the smoothed surface from the original. Lower is more \
               accurate. The dotted line is half a voxel diagonal, when the voxel size is set.",
        color: ERROR,
        value: |s| Some(s.terms.mean_error),
    },
    Strip {
        title: "Volume change |ΔV| (%)",
        help: "Size of the change of the enclosed volume against the original, shrinking and \
               growing alike (the score counts both). Closer to 0 is better.",
        color: VOLUME,
        value: |s| s.terms.volume_change.map(|v| 100.0 * v),
    },
    Strip {
        title: "Score S(τ)",
        help: "The quality score for the current τ: τ·K/K0 + (1-τ)·accuracy. Lower is \
               better; the marked point is its minimum, this parameter's suggestion with the \
               others held.",
        color: SCORE,
        value: |s| Some(s.score),
    },
];

/// Shows the graphs; returns new parameters when the user clicked or dragged in a strip.
/// `layout` gets where each column's strips were drawn.
pub fn show(ui: &mut egui::Ui, session: &Session, layout: &mut Vec<GraphColumn>) -> Option<Params> {
    let Some(graphs) = session.background().graphs() else {
        ui.label("The quality graphs are being computed…");
        return None;
    };
    let stale = !session.background().graphs_current();
    let half_vd = session.case().voxel_diagonal().map(|d| d / 2.0);
    let mut picked = None;
    let columns = graphs.curves.len().max(1);
    ui.columns(columns, |cols| {
        for (ui, curve) in cols.iter_mut().zip(&graphs.curves) {
            let mut drawn = GraphColumn {
                param: curve.param.name(),
                strips: Vec::new(),
            };
            let value = column(ui, curve, half_vd, stale, &mut drawn);
            layout.push(drawn);
            if let Some(value) = value {
                let mut p = *session.case().params();
                curve.param.set(&mut p, value);
                picked = Some(p);
            }
        }
    });
    picked.filter(|p| p.validate().is_ok() && p != session.case().params())
}

/// One parameter's strips; returns the sample value picked. Each strip's plot area goes into
/// `drawn`.
fn column(
    ui: &mut egui::Ui,
    curve: &Curve,
    half_vd: Option<f64>,
    stale: bool,
    drawn: &mut GraphColumn,
) -> Option<f64> {
    let param = curve.param;
    let diverging: Vec<f64> = (curve.samples.iter())
        .filter(|s| s.terms.roughens())
        .map(|s| s.value)
        .collect();
    column_heading(ui, curve, stale, !diverging.is_empty());
    let strip_height = ((ui.available_height() - 30.0) / STRIPS.len() as f32).clamp(56.0, 120.0);
    let link = ui.scope_id().with(("graphs_x", format!("{param:?}")));
    let mut picked = None;
    for (k, strip) in STRIPS.iter().enumerate() {
        let last = k + 1 == STRIPS.len();
        let shown = StripShown {
            curve,
            strip,
            k,
            last,
            diverging: &diverging,
            half_vd,
        };
        let response = strip_plot(param, k, last, strip_height, link)
            .show(ui, |plot_ui| draw_strip(plot_ui, &shown));
        let bounds = response.transform.bounds();
        drawn.strips.push((
            (*response.transform.frame()).into(),
            [bounds.min()[0], bounds.max()[0]],
        ));
        // The measure's name inside its strip, top left: every axis says what it is.
        let rect = response.response.rect;
        ui.painter().text(
            egui::pos2(rect.left() + 46.0, rect.top() + 2.0),
            egui::Align2::LEFT_TOP,
            strip.title,
            egui::FontId::proportional(12.0),
            strip.color,
        );
        response.response.clone().on_hover_text(strip.help);
        if let Some(at) = response.inner {
            picked = nearest(curve, at.x);
        }
    }
    picked
}

/// The column's heading (the parameter, its unit, where S is lowest) and its notes: that the
/// curves are being updated, and what red bars mean where the filter diverges.
fn column_heading(ui: &mut egui::Ui, curve: &Curve, stale: bool, diverges: bool) {
    let param = curve.param;
    let unit = param.unit();
    let mut heading = format!(
        "{}{}",
        label(param),
        if unit.is_empty() {
            String::new()
        } else {
            format!(" ({unit})")
        }
    );
    if let Some(best) = curve.suggestion() {
        heading += &format!("   best S at {}", format_value(param, best));
    }
    ui.strong(heading).on_hover_text(format!(
        "Each strip varies {} with the other parameters held at their current values. Click or \
         drag in a strip to set it.",
        label(param)
    ));
    if stale {
        ui.small("Updating for the new values…");
    }
    if diverges {
        ui.small(
            egui::RichText::new("Red: the filter diverges here (rougher than the original)")
                .color(egui::Color32::from_rgb(0xe0, 0x60, 0x60)),
        )
        .on_hover_text(
            "At these values the filter amplifies the mesh's finest ripples instead of damping \
             them, and repeating it blows the mesh up. They are never suggested.",
        );
    }
}

/// Strip `k` of `param`'s column: linked along x with the column's other strips, fixed (a
/// click or drag sets the parameter), the x axis shown on the last strip only.
fn strip_plot(param: Param, k: usize, last: bool, height: f32, link: egui::Id) -> Plot<'static> {
    Plot::new(("graph", format!("{param:?}"), k))
        .height(height)
        .link_axis(link, [true, false])
        .link_cursor(link, [true, false])
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_drag(false)
        .allow_boxed_zoom(false)
        .allow_double_click_reset(false)
        .show_x(true)
        .show_y(true)
        .y_axis_min_width(40.0)
        .show_axes([last, true])
        .x_axis_label(if last { label(param) } else { String::new() })
        .label_formatter(move |hover| {
            let (HoverPosition::NearDataPoint { position, .. }
            | HoverPosition::Elsewhere { position }) = hover;
            Some(format!(
                "{} = {}\n{:.4}",
                label(param),
                format_value(param, position.x),
                position.y
            ))
        })
}

/// What one strip draws.
struct StripShown<'a> {
    curve: &'a Curve,
    strip: &'a Strip,
    k: usize,
    last: bool,
    /// Sample values where the filter diverges.
    diverging: &'a [f64],
    /// Half the voxel diagonal (mm), the accuracy strip's reference, when known.
    half_vd: Option<f64>,
}

/// Draws a strip's curves and marks; the point clicked or dragged at, if any.
fn draw_strip(plot_ui: &mut PlotUi<'_>, shown: &StripShown<'_>) -> Option<PlotPoint> {
    let StripShown {
        curve,
        strip,
        k,
        last,
        diverging,
        half_vd,
    } = *shown;
    let runs = curve.runs(strip.value);
    if runs.is_empty() {
        return None;
    }
    for &x in diverging {
        plot_ui.vline(VLine::new("filter diverges", x).color(DIVERGES).width(5.0));
    }
    for run in &runs {
        plot_ui.line(
            Line::new(strip.title, PlotPoints::from(run.clone()))
                .color(strip.color)
                .width(2.0),
        );
    }
    plot_ui.vline(
        VLine::new("current value", curve.current)
            .color(CURRENT)
            .style(LineStyle::dashed_loose()),
    );
    if let Some(h) = half_vd.filter(|_| k == 1) {
        plot_ui.hline(
            HLine::new("half voxel diagonal", h)
                .color(REFERENCE)
                .style(LineStyle::dotted_dense()),
        );
    }
    if let Some(best) = curve.best.and_then(|i| curve.samples.get(i)) {
        if let Some(v) = (strip.value)(best) {
            plot_ui.points(
                Points::new("lowest S", vec![[best.value, v]])
                    .color(SCORE)
                    .radius(if last { 5.0 } else { 3.5 })
                    .shape(egui_plot::MarkerShape::Diamond),
            );
        }
    }
    let r = plot_ui.response();
    (r.clicked() || r.dragged())
        .then(|| plot_ui.pointer_coordinate())
        .flatten()
}

/// The sample value nearest to `x` (samples are the values the sweep could set).
fn nearest(curve: &Curve, x: f64) -> Option<f64> {
    curve
        .samples
        .iter()
        .map(|s| s.value)
        .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()))
}

fn label(param: Param) -> String {
    match param {
        Param::Lambda => "λ".into(),
        Param::Mu => "μ".into(),
        Param::Alpha => "α".into(),
        Param::Beta => "β".into(),
        Param::Passband => "pass band".into(),
        Param::Iterations => "iterations".into(),
    }
}

fn format_value(param: Param, v: f64) -> String {
    match param {
        Param::Iterations => format!("{v:.0}"),
        Param::Passband => format!("{v:.3}"),
        _ => format!("{v:.2}"),
    }
}
