//! The parameter space of each filter: which parameters, the quality-graph samples and the
//! search grid (ALGORITHMS.md, "Model quality graphs" and "Parameter suggestion").
//!
//! Grids: weights in steps of 0.1 over their range, iterations in steps of 5 over [0, 50].
//! Windowed sinc: passband on the log scale 0.001 ... 1, iterations on
//! [`SINC_ITERATION_GRID`]. Its iteration count is the degree of the filter polynomial, not a
//! prefix of a longer run, so every count costs a run of that length; the grid is dense where the
//! response changes most (VTK notes 10-20 usually suffice) and sparse towards 100. Its 0 means
//! "leave the mesh unchanged", so that tau = 0 can suggest no smoothing for sinc as well.

use crate::smooth::{Filter, Params};
use serde::{Deserialize, Serialize};

/// Windowed sinc's passbands, for the graphs and the search (log scale).
pub const SINC_PASSBANDS: [f64; 10] = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0];

/// Windowed sinc's iteration counts on the search grid (0 = unchanged mesh).
pub const SINC_ITERATION_GRID: [u32; 9] = [0, 5, 10, 15, 20, 30, 50, 70, 100];

/// Largest iteration count of the other filters' grids and graphs.
pub const MAX_ITERATIONS: u32 = 50;
/// The iteration grid's step (Laplace, Taubin and HC).
pub const GRID_ITERATION_STEP: u32 = 5;

/// One smoothing parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Param {
    Lambda,
    Mu,
    Alpha,
    Beta,
    Passband,
    Iterations,
}

impl Param {
    pub fn name(self) -> &'static str {
        match self {
            Param::Lambda => "lambda",
            Param::Mu => "mu",
            Param::Alpha => "alpha",
            Param::Beta => "beta",
            Param::Passband => "passband",
            Param::Iterations => "iterations",
        }
    }

    /// What the value measures, for axis labels.
    pub fn unit(self) -> &'static str {
        match self {
            Param::Lambda | Param::Mu | Param::Alpha | Param::Beta => "weight, no unit",
            Param::Passband => "passband frequency, log scale",
            Param::Iterations => "iterations",
        }
    }

    /// The value in `p`, as the decimal the f32 was written as (0.1, not 0.10000000149).
    pub fn get(self, p: &Params) -> f64 {
        let weight = match self {
            Param::Lambda => p.lambda,
            Param::Mu => p.mu,
            Param::Alpha => p.alpha,
            Param::Beta => p.beta,
            Param::Passband => p.passband,
            Param::Iterations => return p.iterations as f64,
        };
        weight.to_string().parse().unwrap_or(weight as f64)
    }

    pub fn set(self, p: &mut Params, value: f64) {
        match self {
            Param::Lambda => p.lambda = value as f32,
            Param::Mu => p.mu = value as f32,
            Param::Alpha => p.alpha = value as f32,
            Param::Beta => p.beta = value as f32,
            Param::Passband => p.passband = value as f32,
            Param::Iterations => p.iterations = value.round().max(0.0) as u32,
        }
    }
}

/// One parameter's samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    pub param: Param,
    /// Search grid values, ascending.
    pub grid: Vec<f64>,
    /// Quality-graph samples, ascending.
    pub sweep: Vec<f64>,
    /// Larger values smooth more; decides ties towards the weaker smoothing.
    pub larger_is_stronger: bool,
}

/// A point of the search grid: an index into each axis's `grid` (unused trailing entries 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct GridPoint(pub [u8; 3]);

/// The parameters of one filter. The iteration count is always the last axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamSpace {
    pub filter: Filter,
    pub axes: Vec<Axis>,
}

/// `from..=to` in steps of `1/per_unit`, computed from integers so 0.3 is 3/10, not 0.1+0.1+0.1.
fn steps(from: i32, to: i32, per_unit: f64) -> Vec<f64> {
    (from..=to).map(|i| i as f64 / per_unit).collect()
}

fn weight(param: Param, grid: Vec<f64>, sweep: Vec<f64>, larger_is_stronger: bool) -> Axis {
    Axis {
        param,
        grid,
        sweep,
        larger_is_stronger,
    }
}

fn iterations(grid: Vec<f64>, sweep: Vec<f64>) -> Axis {
    weight(Param::Iterations, grid, sweep, true)
}

impl ParamSpace {
    pub fn of(filter: Filter) -> Self {
        let its = || {
            iterations(
                (0..=MAX_ITERATIONS)
                    .step_by(GRID_ITERATION_STEP as usize)
                    .map(f64::from)
                    .collect(),
                (0..=MAX_ITERATIONS).map(f64::from).collect(),
            )
        };
        let unit_weight = |p, stronger| weight(p, steps(0, 10, 10.0), steps(0, 20, 20.0), stronger);
        let axes = match filter {
            Filter::Laplace => vec![unit_weight(Param::Lambda, true), its()],
            // Taubin: lambda in (0, 1], mu in [-1, 0). With lambda fixed, mu closer to -lambda
            // lowers the passband 1/lambda + 1/mu, i.e. smooths more.
            Filter::Taubin => vec![
                weight(Param::Lambda, steps(1, 10, 10.0), steps(1, 20, 20.0), true),
                weight(Param::Mu, steps(-10, -1, 10.0), steps(-20, -1, 20.0), true),
                its(),
            ],
            // HC: alpha pulls towards the original, beta pushes back by the own correction;
            // both smooth less as they grow (beta = 1 leaves the mesh unchanged).
            Filter::Hc => vec![
                unit_weight(Param::Alpha, false),
                unit_weight(Param::Beta, false),
                its(),
            ],
            Filter::Sinc => vec![
                weight(
                    Param::Passband,
                    SINC_PASSBANDS.to_vec(),
                    SINC_PASSBANDS.to_vec(),
                    false,
                ),
                iterations(
                    SINC_ITERATION_GRID.iter().map(|&i| f64::from(i)).collect(),
                    (1..=100).map(f64::from).collect(),
                ),
            ],
        };
        Self { filter, axes }
    }

    pub fn dims(&self) -> usize {
        self.axes.len()
    }

    /// Index of the iteration axis (the last).
    pub fn iteration_axis(&self) -> usize {
        self.axes.len() - 1
    }

    /// `base` with the grid values of `point`.
    pub fn params_at(&self, base: &Params, point: GridPoint) -> Params {
        let mut p = *base;
        p.filter = self.filter;
        for (k, axis) in self.axes.iter().enumerate() {
            axis.param.set(&mut p, axis.grid[point.0[k] as usize]);
        }
        p
    }

    /// Whether `params` may be smoothed with; sinc's 0 iterations stands for the unchanged mesh.
    pub fn is_valid_params(&self, params: &Params) -> bool {
        if params.filter == Filter::Sinc && params.iterations == 0 {
            let mut one = *params;
            one.iterations = 1;
            return one.validate().is_ok();
        }
        params.validate().is_ok()
    }

    /// Whether `point` is inside the grid and its parameters are valid (Taubin: mu < -lambda).
    pub fn is_valid(&self, base: &Params, point: GridPoint) -> bool {
        let inside = (0..3).all(|k| match self.axes.get(k) {
            Some(axis) => (point.0[k] as usize) < axis.grid.len(),
            None => point.0[k] == 0,
        });
        inside && self.is_valid_params(&self.params_at(base, point))
    }

    /// Every valid grid point, in lexicographic order.
    pub fn all_points(&self, base: &Params) -> Vec<GridPoint> {
        let mut out = vec![GridPoint([0; 3])];
        for (k, axis) in self.axes.iter().enumerate() {
            out = out
                .into_iter()
                .flat_map(|p| {
                    (0..axis.grid.len()).map(move |i| {
                        let mut q = p;
                        q.0[k] = i as u8;
                        q
                    })
                })
                .collect();
        }
        out.retain(|&p| self.is_valid(base, p));
        out
    }

    /// The valid points among the 3^n - 1 grid neighbours of `point`.
    pub fn neighbours(&self, base: &Params, point: GridPoint) -> Vec<GridPoint> {
        let n = self.dims();
        let mut out = Vec::new();
        for code in 0..3usize.pow(n as u32) {
            let mut q = point;
            let mut rest = code;
            let mut inside = true;
            for k in 0..n {
                let shifted = q.0[k] as i32 + (rest % 3) as i32 - 1;
                rest /= 3;
                inside &= shifted >= 0 && (shifted as usize) < self.axes[k].grid.len();
                q.0[k] = shifted.max(0) as u8;
            }
            if inside && q != point && self.is_valid(base, q) {
                out.push(q);
            }
        }
        out
    }

    /// Whether `q` makes the smoothing stronger than `c` in one parameter and weaker in another.
    pub fn trades_strength(&self, c: GridPoint, q: GridPoint) -> bool {
        let (mut stronger, mut weaker) = (false, false);
        for (k, axis) in self.axes.iter().enumerate() {
            if q.0[k] != c.0[k] {
                if (q.0[k] > c.0[k]) == axis.larger_is_stronger {
                    stronger = true;
                } else {
                    weaker = true;
                }
            }
        }
        stronger && weaker
    }

    /// Whether `a` and `b` differ in their iteration count at most.
    pub fn same_weights(&self, a: GridPoint, b: GridPoint) -> bool {
        let it = self.iteration_axis();
        (0..3).all(|k| k == it || a.0[k] == b.0[k])
    }

    /// Sort key putting the weaker smoothing first: fewer iterations, then each weight in its
    /// weaker direction.
    pub fn weakness_key(&self, point: GridPoint) -> [u8; 3] {
        let it = self.iteration_axis();
        let mut key = [0u8; 3];
        key[0] = point.0[it];
        for (k, axis) in self.axes[..it].iter().enumerate() {
            let i = point.0[k];
            key[k + 1] = if axis.larger_is_stronger {
                i
            } else {
                (axis.grid.len() - 1) as u8 - i
            };
        }
        key
    }

    /// The local search's starting points: search k at the maximum of parameter k and the minimum
    /// of the others. Where that corner is invalid (Taubin), parameter k steps down until valid.
    pub fn corner_starts(&self, base: &Params) -> Vec<GridPoint> {
        (0..self.dims())
            .filter_map(|k| {
                (0..self.axes[k].grid.len()).rev().find_map(|i| {
                    let mut p = GridPoint([0; 3]);
                    p.0[k] = i as u8;
                    self.is_valid(base, p).then_some(p)
                })
            })
            .collect()
    }

    /// The values of this filter's parameters in `params`, in axis order.
    pub fn values(&self, params: &Params) -> Vec<(Param, f64)> {
        self.axes
            .iter()
            .map(|a| (a.param, a.param.get(params)))
            .collect()
    }

    /// The grid point of `params`, if its values lie on the grid.
    pub fn point_of(&self, params: &Params) -> Option<GridPoint> {
        let mut p = GridPoint([0; 3]);
        for (k, axis) in self.axes.iter().enumerate() {
            let v = axis.param.get(params);
            let i = axis.grid.iter().position(|&g| (g - v).abs() < 1e-6)?;
            p.0[k] = i as u8;
        }
        Some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diagonal_trades_strength_when_it_smooths_more_in_one_parameter_and_less_in_another() {
        // HC: higher alpha or beta smooths less, more iterations more.
        let space = ParamSpace::of(Filter::Hc);
        let c = GridPoint([4, 4, 4]);
        for (q, trades) in [
            ([5, 3, 4], true),
            ([3, 5, 4], true),
            ([4, 5, 5], true),
            ([5, 4, 3], false),
            ([5, 5, 4], false),
            ([3, 3, 5], false),
            ([5, 4, 4], false),
        ] {
            assert_eq!(space.trades_strength(c, GridPoint(q)), trades, "{q:?}");
        }
        // Taubin: higher lambda, or mu closer to -lambda, smooths more.
        let taubin = ParamSpace::of(Filter::Taubin);
        assert!(taubin.trades_strength(c, GridPoint([5, 3, 4])));
        assert!(!taubin.trades_strength(c, GridPoint([5, 5, 4])));
    }

    #[test]
    fn grid_sizes_follow_the_spec() {
        let base = |f| Params::defaults(f);
        let count = |f| ParamSpace::of(f).all_points(&base(f)).len();
        assert_eq!(count(Filter::Laplace), 11 * 11);
        // Taubin keeps mu < -lambda: 9 + 8 + ... + 1 pairs.
        assert_eq!(count(Filter::Taubin), 45 * 11);
        assert_eq!(count(Filter::Hc), 11 * 11 * 11);
        assert_eq!(count(Filter::Sinc), 10 * SINC_ITERATION_GRID.len());
        let lap = ParamSpace::of(Filter::Laplace);
        assert_eq!(lap.axes[0].sweep.len(), 21);
        assert_eq!(lap.axes[0].grid[3], 0.3);
        assert_eq!(lap.axes[1].sweep.len(), 51);
        assert_eq!(ParamSpace::of(Filter::Sinc).axes[1].sweep.len(), 100);
    }

    #[test]
    fn every_grid_point_is_a_valid_parameter_set() {
        for f in Filter::ALL {
            let space = ParamSpace::of(f);
            for p in space.all_points(&Params::defaults(f)) {
                let params = space.params_at(&Params::defaults(f), p);
                if !(f == Filter::Sinc && params.iterations == 0) {
                    params.validate().unwrap();
                }
                assert_eq!(space.point_of(&params), Some(p));
            }
        }
    }

    #[test]
    fn neighbours_are_the_valid_3n_minus_1() {
        let hc = ParamSpace::of(Filter::Hc);
        let base = Params::defaults(Filter::Hc);
        assert_eq!(hc.neighbours(&base, GridPoint([5, 5, 5])).len(), 26);
        assert_eq!(hc.neighbours(&base, GridPoint([0, 0, 0])).len(), 7);
        let lap = ParamSpace::of(Filter::Laplace);
        assert_eq!(lap.neighbours(&base, GridPoint([10, 10, 0])).len(), 3);
        // Taubin lambda 0.5 (index 4), mu -0.6 (index 4): mu -0.5 is not below -lambda.
        let taubin = ParamSpace::of(Filter::Taubin);
        let tb = Params::defaults(Filter::Taubin);
        let n = taubin.neighbours(&tb, GridPoint([4, 4, 5]));
        assert!(n.iter().all(|&q| taubin.is_valid(&tb, q)));
        assert!(n.len() < 26);
        assert!(!n.contains(&GridPoint([4, 5, 5])));
    }

    #[test]
    fn corners_start_at_the_maximum_of_one_parameter() {
        let lap = ParamSpace::of(Filter::Laplace);
        let base = Params::defaults(Filter::Laplace);
        assert_eq!(
            lap.corner_starts(&base),
            vec![GridPoint([10, 0, 0]), GridPoint([0, 10, 0])]
        );
        let taubin = ParamSpace::of(Filter::Taubin);
        let starts = taubin.corner_starts(&Params::defaults(Filter::Taubin));
        // lambda 1.0 has no mu < -1: start at lambda 0.9, mu -1.0; mu's start is -0.2 (lambda 0.1).
        assert_eq!(
            starts,
            vec![
                GridPoint([8, 0, 0]),
                GridPoint([0, 8, 0]),
                GridPoint([0, 0, 10])
            ]
        );
    }

    #[test]
    fn weaker_smoothing_sorts_first() {
        let hc = ParamSpace::of(Filter::Hc);
        // Fewer iterations first; then larger alpha (weaker).
        assert!(hc.weakness_key(GridPoint([0, 0, 0])) < hc.weakness_key(GridPoint([0, 0, 1])));
        assert!(hc.weakness_key(GridPoint([9, 0, 1])) < hc.weakness_key(GridPoint([8, 0, 1])));
        let lap = ParamSpace::of(Filter::Laplace);
        assert!(lap.weakness_key(GridPoint([1, 2, 0])) < lap.weakness_key(GridPoint([2, 2, 0])));
    }

    #[test]
    fn sinc_zero_iterations_stands_for_no_smoothing() {
        let sinc = ParamSpace::of(Filter::Sinc);
        let base = Params::defaults(Filter::Sinc);
        assert!(sinc.is_valid(&base, GridPoint([3, 0, 0])));
        assert_eq!(sinc.params_at(&base, GridPoint([3, 0, 0])).iterations, 0);
        assert!(!sinc.is_valid(&base, GridPoint([3, 9, 0])));
        assert!(!sinc.is_valid(&base, GridPoint([3, 1, 1])));
    }
}
