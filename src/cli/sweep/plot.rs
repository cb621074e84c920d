//! The quality graphs as a PNG: one column per parameter; on top smoothness (K/K0) and the
//! score S, below accuracy (mean local error in mm, volume change in %), each quantity on an
//! axis of its own unit so no curve needs a legend to be read.

use crate::suggest::{Curve, Param, QualityGraphs, Sample};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

const FONT: &str = "sans-serif";
const CURVATURE: RGBColor = RGBColor(31, 119, 180);
const SCORE: RGBColor = RGBColor(20, 20, 20);
const ERROR: RGBColor = RGBColor(44, 160, 44);
const VOLUME: RGBColor = RGBColor(230, 120, 0);
const CURRENT: RGBColor = RGBColor(110, 110, 110);
const BEST: RGBColor = RGBColor(214, 39, 40);
/// The samples where the filter diverges (a light red bar across the panel).
const DIVERGES: RGBColor = RGBColor(244, 190, 190);

/// What the figure is of, for its title.
pub struct Figure<'a> {
    pub title: &'a str,
    /// Voxel edge length (mm): draws half the voxel diagonal on the error axis.
    pub voxel_size: Option<f64>,
}

fn register_font() -> Result<(), String> {
    plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT)
        .map_err(|_| "cannot load the plot font".to_string())
}

/// A parameter's axis label: what it is and which way smooths more.
fn axis_label(param: Param) -> &'static str {
    match param {
        Param::Lambda => "λ (lambda): step size; larger smooths more",
        Param::Mu => "μ (mu): inflation step; nearer -λ smooths more",
        Param::Alpha => "α (alpha): pull to the original; larger smooths less",
        Param::Beta => "β (beta): own correction; larger smooths less",
        Param::Passband => "passband (log scale); smaller smooths more",
        Param::Iterations => "iterations",
    }
}

/// A parameter's name for captions.
fn symbol(param: Param) -> &'static str {
    match param {
        Param::Lambda => "λ",
        Param::Mu => "μ",
        Param::Alpha => "α",
        Param::Beta => "β",
        Param::Passband => "passband",
        Param::Iterations => "iterations",
    }
}

/// The caption of a parameter's top panel: its current value and where S is lowest.
fn caption(curve: &Curve) -> String {
    let best = curve
        .suggestion()
        .map_or("-".to_string(), |v| value_text(curve.param, v));
    format!(
        "{}: current {}, lowest S at {best}",
        symbol(curve.param),
        value_text(curve.param, curve.current)
    )
}

/// Passband is drawn on log10; every other parameter as is.
fn x_of(param: Param, value: f64) -> f64 {
    if param == Param::Passband {
        value.log10()
    } else {
        value
    }
}

fn value_text(param: Param, value: f64) -> String {
    match param {
        Param::Iterations => format!("{value:.0}"),
        Param::Passband => format!("{value}"),
        _ => format!("{value:.2}"),
    }
}

fn x_range(curve: &Curve) -> (f64, f64) {
    let xs = curve.samples.iter().map(|s| x_of(curve.param, s.value));
    let current = x_of(curve.param, curve.current);
    let (lo, hi) = xs.fold((current, current), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let pad = ((hi - lo) * 0.02).max(1e-3);
    (lo - pad, hi + pad)
}

fn upper(values: impl Iterator<Item = f64>, at_least: f64) -> f64 {
    values.filter(|v| v.is_finite()).fold(at_least, f64::max) * 1.08
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type Chart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

fn err(e: impl std::fmt::Display) -> String {
    format!("cannot draw the graphs: {e}")
}

/// How a key entry is drawn.
enum Mark {
    Line(RGBColor, u32),
    Dashed(RGBColor),
    Dot(RGBColor),
}

/// Draws `graphs` into the PNG at `path`.
pub fn draw(graphs: &QualityGraphs, figure: &Figure, path: &std::path::Path) -> Result<(), String> {
    register_font()?;
    let columns = graphs.curves.len().max(1);
    let width = 560 * columns as u32;
    let root = BitMapBackend::new(path, (width, 960)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (header, body) = root.split_vertically(150);
    header
        .draw(&Text::new(
            figure.title.to_string(),
            (18, 10),
            (FONT, 28).into_font().color(&BLACK),
        ))
        .map_err(err)?;
    let note = format!(
        "Each column varies one parameter, the others held at their current values. \
         Score S = τ·K/K0 + (1-τ)·½·(E/(E+1) + |ΔV|/V0), τ = {}: lower is better.",
        graphs.tau
    );
    header
        .draw(&Text::new(
            note,
            (18, 48),
            (FONT, 18).into_font().color(&SCORE),
        ))
        .map_err(err)?;
    let mut key = vec![
        (
            Mark::Line(SCORE, 3),
            format!("S, score at τ = {}", graphs.tau),
        ),
        (Mark::Dot(BEST), "lowest S".to_string()),
        (
            Mark::Line(CURVATURE, 2),
            "K/K0, curvature left (1 = unsmoothed)".to_string(),
        ),
        (Mark::Dashed(CURRENT), "current value".to_string()),
        (Mark::Line(ERROR, 2), "E, mean local error (mm)".to_string()),
        (
            Mark::Line(VOLUME, 2),
            "|ΔV|/V0, volume change (%)".to_string(),
        ),
    ];
    if figure.voxel_size.is_some() {
        key.push((Mark::Dashed(ERROR), "half voxel diagonal".to_string()));
    }
    let diverges = graphs
        .curves
        .iter()
        .any(|c| c.samples.iter().any(|s| s.terms.roughens()));
    if diverges {
        key.push((
            Mark::Line(DIVERGES, 8),
            "filter diverges: rougher than the original, never suggested".to_string(),
        ));
    }
    draw_key(&header, &key, 18, 88)?;
    let cells = body.split_evenly((2, columns));
    for (k, curve) in graphs.curves.iter().enumerate() {
        smoothness_panel(&cells[k], curve)?;
        accuracy_panel(&cells[columns + k], curve, figure.voxel_size)?;
    }
    root.present().map_err(err)
}

/// One row of key entries, left to right.
fn draw_key(area: &Area, key: &[(Mark, String)], x0: i32, y0: i32) -> Result<(), String> {
    let style = (FONT, 17).into_font().color(&BLACK);
    let width = area.dim_in_pixel().0 as i32;
    let (mut x, mut y) = (x0, y0);
    for (mark, label) in key {
        let (w, _) = area.estimate_text_size(label, &style).map_err(err)?;
        let w = 36 + w as i32 + 30;
        if x > x0 && x + w > width {
            // Wrap to a second row.
            x = x0;
            y += 28;
        }
        match *mark {
            Mark::Line(c, w) => area
                .draw(&PathElement::new(
                    vec![(x, y), (x + 28, y)],
                    c.stroke_width(w),
                ))
                .map_err(err)?,
            Mark::Dashed(c) => area
                .draw(&DashedPathElement::new(
                    vec![(x, y), (x + 28, y)],
                    6,
                    4,
                    c.stroke_width(2),
                ))
                .map_err(err)?,
            Mark::Dot(c) => area
                .draw(&Circle::new((x + 14, y), 6, c.filled()))
                .map_err(err)?,
        }
        area.draw(&Text::new(label.clone(), (x + 36, y - 10), style.clone()))
            .map_err(err)?;
        x += w;
    }
    Ok(())
}

/// The markers both panels share: bars where the filter diverges, the current value (dashed)
/// and the lowest S (thin red).
fn markers(chart: &mut Chart, curve: &Curve, y_top: f64) -> Result<(), String> {
    for s in curve.samples.iter().filter(|s| s.terms.roughens()) {
        vertical(
            chart,
            x_of(curve.param, s.value),
            y_top,
            DIVERGES.stroke_width(8),
        )?;
    }
    let x = x_of(curve.param, curve.current);
    chart
        .draw_series(std::iter::once(DashedPathElement::new(
            vec![(x, 0.0), (x, y_top)],
            8,
            6,
            CURRENT.stroke_width(2),
        )))
        .map_err(err)?;
    if let Some(best) = curve.best.map(|i| curve.samples[i]) {
        vertical(
            chart,
            x_of(curve.param, best.value),
            y_top,
            BEST.mix(0.5).stroke_width(1),
        )?;
    }
    Ok(())
}

/// A solid vertical line at `x` from 0 to `y_top`.
fn vertical(chart: &mut Chart, x: f64, y_top: f64, style: ShapeStyle) -> Result<(), String> {
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(x, 0.0), (x, y_top)],
            style,
        )))
        .map_err(err)?;
    Ok(())
}

fn line(
    chart: &mut Chart,
    curve: &Curve,
    value: impl Fn(&Sample) -> Option<f64>,
    style: ShapeStyle,
) -> Result<(), String> {
    for run in curve.runs(value) {
        let points = run.into_iter().map(|[x, y]| (x_of(curve.param, x), y));
        chart
            .draw_series(LineSeries::new(points, style))
            .map_err(err)?;
    }
    Ok(())
}

fn smoothness_panel(area: &Area, curve: &Curve) -> Result<(), String> {
    let (x0, x1) = x_range(curve);
    let param = curve.param;
    let y1 = upper(
        curve
            .samples
            .iter()
            .flat_map(|s| [s.terms.curvature_ratio, s.score]),
        1.0,
    );
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        // Same plot width as the accuracy panel below, which has a right axis.
        .margin_right(12 + 66)
        .caption(caption(curve), (FONT, 20))
        .x_label_area_size(48)
        .y_label_area_size(66)
        .build_cartesian_2d(x0..x1, 0.0..y1)
        .map_err(err)?;
    let x_fmt = move |x: &f64| x_tick(param, *x);
    chart
        .configure_mesh()
        .light_line_style(WHITE.mix(0.0))
        .x_desc(axis_label(param))
        .y_desc("K/K0 and S (1 = unsmoothed)")
        .x_label_formatter(&x_fmt)
        .x_labels(x_label_count(param))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(err)?;
    // The original's level, K/K0 = 1.
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(x0, 1.0), (x1, 1.0)],
            CURVATURE.mix(0.3).stroke_width(1),
        )))
        .map_err(err)?;
    markers(&mut chart, curve, y1)?;
    line(
        &mut chart,
        curve,
        |s| Some(s.terms.curvature_ratio),
        CURVATURE.stroke_width(2),
    )?;
    line(&mut chart, curve, |s| Some(s.score), SCORE.stroke_width(3))?;
    if let Some(best) = curve.best.map(|i| curve.samples[i]) {
        chart
            .draw_series(std::iter::once(Circle::new(
                (x_of(param, best.value), best.score),
                7,
                BEST.filled(),
            )))
            .map_err(err)?;
    }
    Ok(())
}

/// The accuracy panel's top error (mm) and volume change (%), and whether there is a volume.
fn accuracy_ranges(curve: &Curve, half_diagonal: Option<f64>) -> (f64, f64, bool) {
    let e1 = upper(
        (curve.samples.iter())
            .map(|s| s.terms.mean_error)
            .chain(half_diagonal.map(|h| 1.06 * h)),
        0.01,
    );
    let has_volume = (curve.samples.iter()).any(|s| s.terms.volume_change.is_some());
    // Headroom above the volume curve keeps it below the reference line's label.
    let volumes = (curve.samples.iter()).filter_map(|s| s.terms.volume_change.map(|v| 100.0 * v));
    (e1, 1.2 * upper(volumes, 0.1), has_volume)
}

fn accuracy_panel(area: &Area, curve: &Curve, voxel_size: Option<f64>) -> Result<(), String> {
    let (x0, x1) = x_range(curve);
    let param = curve.param;
    let half_diagonal = voxel_size.map(|v| 0.5 * v * 3f64.sqrt());
    let (e1, v1, has_volume) = accuracy_ranges(curve, half_diagonal);
    let what = if has_volume {
        format!("{}: accuracy", symbol(param))
    } else {
        format!("{}: accuracy (open mesh, no volume)", symbol(param))
    };
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .caption(what, (FONT, 20))
        .x_label_area_size(48)
        .y_label_area_size(66)
        .right_y_label_area_size(66)
        .build_cartesian_2d(x0..x1, 0.0..e1)
        .map_err(err)?
        .set_secondary_coord(x0..x1, 0.0..v1);
    let x_fmt = move |x: &f64| x_tick(param, *x);
    chart
        .configure_mesh()
        .light_line_style(WHITE.mix(0.0))
        .x_desc(axis_label(param))
        .y_desc("E, mean local error (mm)")
        .x_label_formatter(&x_fmt)
        .x_labels(x_label_count(param))
        .y_label_formatter(&|y| format!("{y:.2}"))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(err)?;
    if has_volume {
        chart
            .configure_secondary_axes()
            .y_desc("|ΔV|/V0, volume change (%)")
            .y_label_formatter(&|y| format!("{y:.2}"))
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(err)?;
        let volumes: Vec<(f64, f64)> = curve
            .samples
            .iter()
            .filter_map(|s| Some((x_of(param, s.value), 100.0 * s.terms.volume_change?)))
            .collect();
        chart
            .draw_secondary_series(LineSeries::new(volumes, VOLUME.stroke_width(2)))
            .map_err(err)?;
    }
    if let Some(h) = half_diagonal {
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                vec![(x0, h), (x1, h)],
                6,
                4,
                ERROR.stroke_width(2),
            )))
            .map_err(err)?;
        let label = (FONT, 15)
            .into_font()
            .color(&ERROR)
            .pos(Pos::new(HPos::Right, VPos::Bottom));
        chart
            .draw_series(std::iter::once(Text::new(
                format!("half voxel diagonal {h:.2} mm"),
                (x1 - 0.02 * (x1 - x0), h + 0.01 * e1),
                label,
            )))
            .map_err(err)?;
    }
    markers(&mut chart, curve, e1)?;
    line(
        &mut chart,
        curve,
        |s| Some(s.terms.mean_error),
        ERROR.stroke_width(2),
    )
}

/// Passband gets one tick per decade; the rest plotters' default density.
fn x_label_count(param: Param) -> usize {
    if param == Param::Passband {
        4
    } else {
        10
    }
}

fn x_tick(param: Param, x: f64) -> String {
    match param {
        Param::Passband => {
            let v = 10f64.powf(x);
            format!("{}", (v * 1e4).round() / 1e4)
        }
        Param::Iterations => format!("{x:.0}"),
        _ => format!("{x:.2}"),
    }
}
