//! Full grid search: measure every grid point, take the lowest S (ties: the weaker smoothing).
//!
//! For cumulative filters each weight setting is one run to the largest iteration count,
//! measured at every grid count on the way (11 parameter sets per run).

use super::points::{plan_runs, prefetch, Measured, Run};
use super::space::{GridPoint, ParamSpace};
use super::{Evaluator, Goal, Progress, SearchMethod, Suggestion, Task, Terms};
use crate::smooth::{Filter, ParamError, Params};
use serde::{Deserialize, Serialize};

/// The grid point of the lowest [`Terms::rank`] at `tau` (the lowest S(tau) among the sets that
/// do not roughen the mesh); ties go to the weaker smoothing.
pub(crate) fn lowest(
    space: &ParamSpace,
    goal: impl Into<Goal>,
    candidates: impl IntoIterator<Item = (GridPoint, Terms)>,
) -> Option<(GridPoint, Terms)> {
    let goal = goal.into();
    candidates.into_iter().min_by(|(pa, ta), (pb, tb)| {
        ta.rank(goal)
            .cmp(&tb.rank(goal))
            .then_with(|| space.weakness_key(*pa).cmp(&space.weakness_key(*pb)))
    })
}

/// Checks what the grid does not override: the displacement bound.
pub(crate) fn check_base(filter: Filter, base: &Params) -> Result<Params, ParamError> {
    let mut probe = Params::defaults(filter);
    probe.max_displacement = base.max_displacement;
    probe.validate()?;
    let mut base = *base;
    base.filter = filter;
    Ok(base)
}

/// The grid of `filter` around `base` (checked): its space, the base, every run that measures
/// it, and how many points it has.
pub(crate) fn plan_grid(
    filter: Filter,
    base: &Params,
) -> Result<(ParamSpace, Params, Vec<Run>, usize), ParamError> {
    let base = check_base(filter, base)?;
    let space = ParamSpace::of(filter);
    let points = space.all_points(&base);
    let runs = plan_runs(&space, &points);
    Ok((space, base, runs, points.len()))
}

/// Measures the whole grid of one filter, one run per [`Task::step`].
pub struct GridSearch {
    space: ParamSpace,
    base: Params,
    runs: Vec<Run>,
    next: usize,
    measured: Measured,
    total: usize,
}

impl GridSearch {
    /// `base` supplies what the grid does not vary (the displacement bound).
    pub fn new(filter: Filter, base: &Params) -> Result<Self, ParamError> {
        let (space, base, runs, total) = plan_grid(filter, base)?;
        Ok(Self {
            runs,
            total,
            space,
            base,
            next: 0,
            measured: Measured::default(),
        })
    }
}

impl Task for GridSearch {
    type Output = EvaluatedGrid;

    fn step(&mut self, evaluator: &mut dyn Evaluator) -> bool {
        let later = self.runs.iter().skip(self.next + 1);
        prefetch(evaluator, &self.space, &self.base, later);
        if let Some(run) = self.runs.get(self.next) {
            if self
                .measured
                .measure(&self.space, &self.base, evaluator, run)
            {
                self.next += 1;
            }
        }
        self.next >= self.runs.len()
    }

    fn progress(&self) -> Progress {
        Progress {
            done: self.measured.len(),
            total: self.total,
        }
    }

    fn into_output(self) -> Option<EvaluatedGrid> {
        (self.next >= self.runs.len()).then(|| EvaluatedGrid {
            points: self.measured.iter().collect(),
            space: self.space,
            base: self.base,
        })
    }
}

/// The terms of every grid point; the suggestion for any tau without smoothing again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvaluatedGrid {
    pub space: ParamSpace,
    pub base: Params,
    pub points: Vec<(GridPoint, Terms)>,
}

impl EvaluatedGrid {
    pub fn evaluations(&self) -> usize {
        self.points.len()
    }

    /// The grid minimum of S(tau); `None` only for an empty grid.
    pub fn best(&self, tau: f64) -> Option<Suggestion> {
        let (point, terms) = lowest(&self.space, tau, self.points.iter().copied())?;
        Some(Suggestion {
            filter: self.space.filter,
            params: self.space.params_at(&self.base, point),
            tau,
            score: terms.score(tau),
            terms,
            evaluations: self.evaluations(),
            search: SearchMethod::Grid,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::synthetic::{bowl, smoothing_model, FnEvaluator, Slow};
    use super::*;
    use crate::suggest::run;

    fn grid(filter: Filter, ev: &mut dyn Evaluator) -> EvaluatedGrid {
        let task = GridSearch::new(filter, &Params::defaults(filter)).unwrap();
        run(task, ev, &mut |_| true).unwrap()
    }

    #[test]
    fn an_evaluator_that_answers_later_gets_the_same_grid() {
        for filter in Filter::ALL {
            let now = grid(filter, &mut FnEvaluator::new(smoothing_model(filter)));
            let mut slow = Slow::new(FnEvaluator::new(smoothing_model(filter)), 1);
            assert_eq!(grid(filter, &mut slow), now, "{filter:?}");
        }
    }

    #[test]
    fn finds_the_bowl_minimum() {
        for (filter, at) in [
            (Filter::Laplace, [3, 4, 0]),
            (Filter::Hc, [7, 2, 9]),
            (Filter::Taubin, [2, 5, 6]),
            (Filter::Sinc, [6, 3, 0]),
        ] {
            let space = ParamSpace::of(filter);
            let centre = GridPoint(at);
            let mut ev = FnEvaluator::new(bowl(&space, centre));
            let g = grid(filter, &mut ev);
            let best = g.best(0.5).unwrap();
            assert_eq!(space.point_of(&best.params), Some(centre), "{filter}");
            assert_eq!(best.evaluations, space.all_points(&g.base).len());
            assert_eq!(best.search, SearchMethod::Grid);
        }
    }

    #[test]
    fn iterations_are_measured_along_one_run_per_weight_setting() {
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Hc));
        let g = grid(Filter::Hc, &mut ev);
        assert_eq!(g.evaluations(), 1331);
        assert_eq!(ev.runs, 121);
        assert_eq!(ev.iterations_run, 121 * 50);
        // Windowed sinc restarts for every count.
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Sinc));
        let g = grid(Filter::Sinc, &mut ev);
        assert_eq!(ev.runs, g.evaluations());
    }

    #[test]
    fn tau_zero_suggests_no_smoothing_for_every_filter() {
        for filter in Filter::ALL {
            let mut ev = FnEvaluator::new(smoothing_model(filter));
            let best = grid(filter, &mut ev).best(0.0).unwrap();
            assert!(best.leaves_mesh_unchanged(), "{filter}: {:?}", best.params);
            assert_eq!(best.score, 0.0);
        }
    }

    #[test]
    fn ties_go_to_the_weaker_smoothing() {
        // Only the iteration count matters here: every lambda ties, the smallest must win.
        let space = ParamSpace::of(Filter::Laplace);
        let mut ev = FnEvaluator::new(|p: &Params| Terms {
            curvature_ratio: 1.0 + ((p.iterations as f64) - 20.0).powi(2),
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.5,
        });
        let best = grid(Filter::Laplace, &mut ev).best(0.5).unwrap();
        assert_eq!(space.point_of(&best.params), Some(GridPoint([0, 4, 0])));
        // HC: larger alpha and beta are weaker.
        let hc = ParamSpace::of(Filter::Hc);
        let mut ev = FnEvaluator::new(|p: &Params| Terms {
            curvature_ratio: 1.0 + ((p.iterations as f64) - 10.0).powi(2),
            mean_error: 0.0,
            volume_change: None,
            roughness_ratio: 0.5,
        });
        let best = grid(Filter::Hc, &mut ev).best(0.5).unwrap();
        assert_eq!(hc.point_of(&best.params), Some(GridPoint([10, 10, 2])));
    }

    #[test]
    fn tradeoff_moves_monotonically_with_tau() {
        for filter in Filter::ALL {
            let mut ev = FnEvaluator::new(smoothing_model(filter));
            let g = grid(filter, &mut ev);
            let mut last = f64::INFINITY;
            for i in 0..=10 {
                let t = g.best(i as f64 / 10.0).unwrap().terms;
                let d = t.curvature_ratio - t.accuracy();
                assert!(d <= last + 1e-12, "{filter} tau {i}/10: {d} > {last}");
                last = d;
            }
            assert!(!g.best(1.0).unwrap().leaves_mesh_unchanged());
        }
    }

    #[test]
    fn displacement_bound_is_passed_through_and_checked() {
        let mut base = Params::defaults(Filter::Laplace);
        base.max_displacement = Some(0.87);
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Laplace));
        let task = GridSearch::new(Filter::Laplace, &base).unwrap();
        let g = run(task, &mut ev, &mut |_| true).unwrap();
        assert!(ev.seen.iter().all(|p| p.max_displacement == Some(0.87)));
        assert_eq!(g.best(0.5).unwrap().params.max_displacement, Some(0.87));
        base.max_displacement = Some(-1.0);
        assert!(GridSearch::new(Filter::Laplace, &base).is_err());
    }

    #[test]
    fn cancelling_stops_between_runs() {
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Laplace));
        let task = GridSearch::new(Filter::Laplace, &Params::defaults(Filter::Laplace)).unwrap();
        let mut calls = 0;
        let r = run(task, &mut ev, &mut |p| {
            calls += 1;
            assert!(p.done <= p.total);
            calls < 3
        });
        assert!(r.is_err());
        assert_eq!(ev.runs, 3);
    }
}
