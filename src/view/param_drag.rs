//! Window/level-style parameter dragging: while a mouse button is held over the view, its
//! horizontal travel drives one smoothing parameter and its vertical travel another, the way
//! radiology viewers drive window and level.
//!
//! A parameter's whole range (its quality-graph range, [`crate::suggest::ParamSpace`]) spans
//! [`POINTS_PER_RANGE`] points of travel; windowed sinc's passband moves on a log scale, as its
//! graphs and search do. Right and up increase. Values are rounded to what the panel shows and
//! kept valid (Taubin: mu < -lambda).

use glam::Vec2;

use crate::smooth::{Filter, Params};
use crate::suggest::{Param, ParamSpace};

/// Travel (points) across a parameter's whole range.
pub const POINTS_PER_RANGE: f32 = 400.0;

/// The parameters a drag can drive for `filter` (the filter's own, then iterations).
pub fn drag_choices(filter: Filter) -> Vec<Param> {
    ParamSpace::of(filter)
        .axes
        .iter()
        .map(|a| a.param)
        .collect()
}

/// The default pair for `filter`, `[horizontal, vertical]`: its main weight across, iterations
/// up (Laplace λ, Taubin λ, HC β, sinc passband).
pub fn default_drag_axes(filter: Filter) -> [Param; 2] {
    let across = match filter {
        Filter::Laplace | Filter::Taubin => Param::Lambda,
        Filter::Hc => Param::Beta,
        Filter::Sinc => Param::Passband,
    };
    [across, Param::Iterations]
}

/// The range a drag moves `param` of `filter` over: `(low, high, log scale)`.
pub fn drag_range(filter: Filter, param: Param) -> Option<(f64, f64, bool)> {
    let space = ParamSpace::of(filter);
    let axis = space.axes.iter().find(|a| a.param == param)?;
    let (low, high) = (*axis.sweep.first()?, *axis.sweep.last()?);
    Some((low, high, param == Param::Passband))
}

/// `value` rounded to what the panel shows: whole iterations, weights to 0.01, the passband to
/// three significant digits.
fn rounded(param: Param, value: f64) -> f64 {
    match param {
        Param::Iterations => value.round(),
        Param::Passband => {
            let scale = 10f64.powf(2.0 - value.abs().log10().floor());
            (value * scale).round() / scale
        }
        _ => (value * 100.0).round() / 100.0,
    }
}

/// `start` with `axes[0]` moved by the horizontal and `axes[1]` by the vertical travel of
/// `delta` (points, y down as on screen: dragging up increases). The same parameter on both
/// axes takes both movements. A result that is still invalid keeps `start`.
pub fn dragged_params(start: &Params, axes: [Param; 2], delta: Vec2) -> Params {
    let mut p = *start;
    for (param, travel) in [(axes[0], delta.x), (axes[1], -delta.y)] {
        let Some((low, high, log)) = drag_range(start.filter, param) else {
            continue;
        };
        let t = (travel / POINTS_PER_RANGE) as f64;
        let current = param.get(&p);
        let value = if log && low > 0.0 {
            (current.max(low).ln() + t * (high / low).ln()).exp()
        } else {
            current + t * (high - low)
        };
        param.set(&mut p, rounded(param, value.clamp(low, high)));
    }
    if p.filter == Filter::Taubin && p.mu >= -p.lambda {
        // Keep the pair valid by holding back the parameter that was dragged.
        let gap = 0.01;
        if axes.contains(&Param::Mu) && !axes.contains(&Param::Lambda) {
            p.mu = rounded(Param::Mu, f64::from(-p.lambda) - gap) as f32;
        } else {
            p.lambda = rounded(Param::Lambda, f64::from(-p.mu) - gap) as f32;
        }
    }
    if p.validate().is_ok() {
        p
    } else {
        *start
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_and_up_increase_and_the_whole_range_takes_400_points() {
        let start = Params::defaults(Filter::Laplace);
        let axes = default_drag_axes(Filter::Laplace);
        assert_eq!(axes, [Param::Lambda, Param::Iterations]);
        let p = dragged_params(&start, axes, Vec2::new(40.0, -80.0));
        assert_eq!(p.lambda, 0.6);
        assert_eq!(p.iterations, 20);
        let p = dragged_params(&start, axes, Vec2::new(-40.0, 80.0));
        assert_eq!((p.lambda, p.iterations), (0.4, 0));
        // Clamped at the ends of the range.
        let p = dragged_params(&start, axes, Vec2::new(5000.0, -5000.0));
        assert_eq!((p.lambda, p.iterations), (1.0, 50));
        assert_eq!(dragged_params(&start, axes, Vec2::ZERO), start);
    }

    #[test]
    fn taubin_keeps_mu_below_minus_lambda() {
        let start = Params::defaults(Filter::Taubin);
        // λ 0.5, μ -0.53: dragging λ up stops just short of -μ.
        let p = dragged_params(
            &start,
            [Param::Lambda, Param::Iterations],
            Vec2::new(300.0, 0.0),
        );
        assert_eq!(p.lambda, 0.52);
        assert!(p.validate().is_ok());
        // Dragging μ towards 0 stops just below -λ.
        let p = dragged_params(
            &start,
            [Param::Mu, Param::Iterations],
            Vec2::new(300.0, 0.0),
        );
        assert_eq!(p.mu, -0.51);
        assert!(p.validate().is_ok());
        // Both on one drag: λ is held back.
        let p = dragged_params(&start, [Param::Mu, Param::Lambda], Vec2::new(300.0, -300.0));
        assert!(p.validate().is_ok() && p.mu < -p.lambda, "{p:?}");
    }

    #[test]
    fn the_passband_moves_on_a_log_scale_and_sinc_keeps_one_iteration() {
        let start = Params::defaults(Filter::Sinc);
        let axes = default_drag_axes(Filter::Sinc);
        // 0.001..1 is three decades over 400 points: 133 points per decade.
        let p = dragged_params(&start, axes, Vec2::new(-400.0 / 3.0, 0.0));
        assert_eq!(p.passband, 0.01);
        let p = dragged_params(&start, axes, Vec2::new(400.0 / 3.0, 0.0));
        assert_eq!(p.passband, 1.0);
        let p = dragged_params(&start, axes, Vec2::new(0.0, 5000.0));
        assert_eq!(p.iterations, 1);
        let p = dragged_params(&start, axes, Vec2::new(0.0, -5000.0));
        assert_eq!(p.iterations, 100);
    }

    #[test]
    fn every_filter_offers_its_parameters_and_defaults_among_them() {
        for filter in Filter::ALL {
            let choices = drag_choices(filter);
            assert_eq!(choices.last(), Some(&Param::Iterations));
            for a in default_drag_axes(filter) {
                assert!(choices.contains(&a), "{filter}: {a:?}");
                assert!(drag_range(filter, a).is_some());
            }
            // Any drag of any pair gives valid parameters.
            for &x in &choices {
                for &y in &choices {
                    for d in [Vec2::new(123.0, -77.0), Vec2::new(-900.0, 900.0)] {
                        let p = dragged_params(&Params::defaults(filter), [x, y], d);
                        assert!(p.validate().is_ok(), "{filter} {x:?} {y:?} {d}: {p:?}");
                    }
                }
            }
        }
        assert_eq!(drag_range(Filter::Laplace, Param::Mu), None);
    }
}
