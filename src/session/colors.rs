//! Colour-coding a result: per-vertex local error, Gaussian curvature or displacement mapped to
//! colours, and the legend that reads them back in mm (and voxel diagonals when known);
//! or the painted smoothing weights (locked blue to free base colour).
//!
//! Ranges are robust (a high percentile, rounded up to a round number) so a few spikes at
//! staircase corners do not wash the map out, and round so the legend's ticks read easily.
//! Distances use a perceptually uniform sequential map (viridis, dark = small); curvature a
//! diverging blue-grey-red map centred on 0 (saddle blue, flat grey, dome red).

use crate::case::Smoothed;

/// What the colours show.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorField {
    /// The local error of each vertex (mm): how far it moved from the original surface.
    LocalError,
    /// The discrete Gaussian curvature `K_G` (1/mm²).
    Curvature,
    /// How far each vertex moved from its original position (mm).
    Displacement,
    /// The painted smoothing weight of each vertex (0 locked, 1 free).
    Weights,
}

impl ColorField {
    pub const ALL: [ColorField; 4] = [
        ColorField::LocalError,
        ColorField::Curvature,
        ColorField::Displacement,
        ColorField::Weights,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ColorField::LocalError => "local error",
            ColorField::Curvature => "Gaussian curvature",
            ColorField::Displacement => "displacement",
            ColorField::Weights => "weights",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            ColorField::Curvature => "1/mm²",
            ColorField::Weights => "0 locked, 1 free",
            _ => "mm",
        }
    }

    fn diverging(self) -> bool {
        self == ColorField::Curvature
    }
}

/// One labelled mark on the legend.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendTick {
    /// Position along the colour bar, 0 (bottom) to 1 (top).
    pub at: f32,
    pub value: f64,
    /// The value with its unit, and in voxel diagonals where that applies and is known.
    pub label: String,
}

/// How to read the colours back.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    pub field: ColorField,
    pub min: f64,
    pub max: f64,
    pub ticks: Vec<LegendTick>,
    /// Colours along the bar, bottom to top, sRGB.
    pub bar: Vec<[u8; 4]>,
}

/// Viridis sampled at 0, 1/8, ..., 1 (sRGB).
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Blue (negative) through grey (0) to red (positive), sRGB.
const COOL_WARM: [[u8; 3]; 5] = [
    [59, 76, 192],
    [141, 176, 254],
    [221, 221, 221],
    [244, 154, 123],
    [180, 4, 38],
];

/// Locked (0) in a cool blue through to free (1) in the view's warm base colour, so painted
/// regions stand out on an otherwise plainly shaded model (sRGB).
const WEIGHT_MAP: [[u8; 3]; 3] = [[33, 102, 172], [130, 160, 190], [219, 204, 179]];

/// The colour at `t` in [0, 1] along a piecewise-linear map.
fn sample(stops: &[[u8; 3]], t: f64) -> [u8; 4] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (stops[i], stops[i + 1]);
    [mix(a[0], b[0]), mix(a[1], b[1]), mix(a[2], b[2]), 255]
}

/// The smallest of 1, 2, 2.5, 5 times a power of ten that is >= `v` (> 0).
fn round_up(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&c| c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// Tick intervals for a span [`round_up`] gave, so every tick is a round number too.
fn divisions(span: f64) -> usize {
    let mantissa = span / 10f64.powf(span.log10().floor());
    match mantissa {
        m if (m - 2.0).abs() < 1e-9 => 4,
        m if (m - 4.0).abs() < 1e-9 => 4,
        _ => 5,
    }
}

/// The `q` quantile (0..1) of `values`' magnitudes.
fn quantile_abs(values: &[f32], q: f64) -> f64 {
    let mut m: Vec<f32> = values
        .iter()
        .map(|v| v.abs())
        .filter(|v| v.is_finite())
        .collect();
    if m.is_empty() {
        return 0.0;
    }
    let k = ((m.len() - 1) as f64 * q).round() as usize;
    let (_, v, _) = m.select_nth_unstable_by(k, f32::total_cmp);
    *v as f64
}

fn format_value(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else if a >= 0.01 {
        format!("{v:.3}")
    } else {
        format!("{v:.1e}")
    }
}

/// Colours distances (the local error of several results) on one viridis scale from 0 to a
/// round value above the 99th percentile of all of them, so results can be compared by eye;
/// returns the colours of each set and the scale's top (mm).
pub fn shared_error_colors(sets: &[&[f32]]) -> (Vec<Vec<[u8; 4]>>, f64) {
    let max = sets
        .iter()
        .map(|v| quantile_abs(v, 0.99))
        .fold(0.0, f64::max);
    let max = round_up(max);
    let colors = sets
        .iter()
        .map(|v| {
            v.iter()
                .map(|&x| sample(&VIRIDIS, x as f64 / max))
                .collect()
        })
        .collect();
    (colors, max)
}

/// Colours every vertex of `result` by `field`; `original` holds the original positions and
/// `voxel_diagonal` (mm), when known, adds voxel-diagonal labels to distance legends.
pub fn colorize(
    field: ColorField,
    original: &[[f32; 3]],
    result: &Smoothed,
    voxel_diagonal: Option<f64>,
) -> (Vec<[u8; 4]>, Legend) {
    let displacement: Vec<f32>;
    let (local_error, curvature) = result.vertex_measures().unwrap_or_default();
    let values: &[f32] = match field {
        ColorField::LocalError => local_error,
        ColorField::Curvature => curvature,
        // The result does not hold the weights: see `weight_colors`.
        ColorField::Weights => return weight_colors(None, original.len()),
        ColorField::Displacement => {
            displacement = original
                .iter()
                .zip(&result.positions)
                .map(|(p, q)| {
                    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
                })
                .collect();
            &displacement
        }
    };
    let (stops, min, max): (&[[u8; 3]], f64, f64) = if field.diverging() {
        let c = round_up(quantile_abs(values, 0.95));
        (&COOL_WARM, -c, c)
    } else {
        (&VIRIDIS, 0.0, round_up(quantile_abs(values, 0.99)))
    };
    let t = |v: f64| (v - min) / (max - min);
    let colors = values.iter().map(|&v| sample(stops, t(v as f64))).collect();
    let legend = legend(field, stops, min, max, divisions(max - min), voxel_diagonal);
    (colors, legend)
}

/// Colours `n` vertices by their painted `weights` (`None`: all free).
pub fn weight_colors(weights: Option<&[f32]>, n: usize) -> (Vec<[u8; 4]>, Legend) {
    let colors = match weights {
        Some(w) => w.iter().map(|&w| sample(&WEIGHT_MAP, w as f64)).collect(),
        None => vec![sample(&WEIGHT_MAP, 1.0); n],
    };
    let legend = legend(ColorField::Weights, &WEIGHT_MAP, 0.0, 1.0, 4, None);
    (colors, legend)
}

fn legend(
    field: ColorField,
    stops: &[[u8; 3]],
    min: f64,
    max: f64,
    divisions: usize,
    voxel_diagonal: Option<f64>,
) -> Legend {
    let ticks = (0..=divisions)
        .map(|k| {
            let at = k as f64 / divisions as f64;
            let value = min + at * (max - min);
            let mut label = format_value(value);
            if field != ColorField::Weights {
                label += &format!(" {}", field.unit());
            }
            if let (Some(d), false) = (voxel_diagonal, field.diverging()) {
                label += &format!(" ({} vd)", format_value(value / d));
            }
            LegendTick {
                at: at as f32,
                value,
                label,
            }
        })
        .collect();
    let bar = (0..64).map(|k| sample(stops, k as f64 / 63.0)).collect();
    Legend {
        field,
        min,
        max,
        ticks,
        bar,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_numbers_bound_from_above() {
        assert_eq!(round_up(0.7), 1.0);
        assert_eq!(round_up(1.0), 1.0);
        assert_eq!(round_up(1.3), 2.0);
        assert_eq!(round_up(2.2), 2.5);
        assert_eq!(round_up(3.0), 5.0);
        assert_eq!(round_up(0.031), 0.05);
        assert_eq!(round_up(0.0), 1.0);
    }

    #[test]
    fn ticks_fall_on_round_numbers() {
        for (span, n) in [
            (1.0, 5),
            (2.0, 4),
            (2.5, 5),
            (5.0, 5),
            (0.25, 5),
            (4.0, 4),
            (10.0, 5),
        ] {
            assert_eq!(divisions(span), n, "{span}");
            let step = span / n as f64;
            let digits = (step * 1e4).round() / 1e4;
            assert!((step - digits).abs() < 1e-12, "{span}: step {step}");
        }
    }

    #[test]
    fn maps_end_at_their_stops_and_clamp() {
        assert_eq!(sample(&VIRIDIS, 0.0), [68, 1, 84, 255]);
        assert_eq!(sample(&VIRIDIS, 1.0), [253, 231, 37, 255]);
        assert_eq!(sample(&VIRIDIS, 7.0), [253, 231, 37, 255]);
        assert_eq!(sample(&VIRIDIS, f64::NAN), [68, 1, 84, 255]);
        assert_eq!(sample(&COOL_WARM, 0.5), [221, 221, 221, 255]);
    }

    #[test]
    fn quantile_ignores_sign_and_nan() {
        let v = [1.0, -4.0, f32::NAN, 2.0, 3.0];
        assert_eq!(quantile_abs(&v, 1.0), 4.0);
        assert_eq!(quantile_abs(&v, 0.0), 1.0);
        assert_eq!(quantile_abs(&[], 0.5), 0.0);
    }
}
