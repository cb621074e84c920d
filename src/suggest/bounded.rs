//! The grid minimum for one tau, measuring the local error only where it can matter.
//!
//! The score's terms other than the mean error E cost half a measure pass and need no drifting
//! reference along the run; with E = 0 they give a lower bound of S(tau) (S grows with E). So
//! every grid point is first measured without E ([`Evaluator::measure_bounds`]); then, lowest
//! bound first, the points whose bound does not exceed the best score measured so far are
//! measured fully, a run of one weight setting at a time, until every other bound lies above
//! it. A point left out has a bound, hence a score, above that of a measured one, so the result
//! is the full grid's minimum, ties and all ([`super::GridSearch`] measures everything).
//! Scores are compared by [`Terms::rank`]; both passes measure the roughness, so a bound never
//! ranks above its set's full measure.
//!
//! An evaluator whose answers are all exact (the default) makes the first pass the whole grid
//! search and the second empty.

use super::grid::{lowest, plan_grid};
use super::points::{plan_runs, prefetch, Measured, Run};
use super::space::{GridPoint, ParamSpace};
use super::{Evaluator, Goal, Progress, Rank, SearchMethod, Suggestion, Task, Terms};
use crate::smooth::{Filter, ParamError, Params};
use std::collections::BTreeMap;

/// The grid minimum of S(tau), one smoothing run per [`Task::step`].
pub struct GridMinimum {
    space: ParamSpace,
    base: Params,
    tau: f64,
    /// Every run of the grid, for the first pass.
    runs: Vec<Run>,
    /// Runs of the first pass done.
    next: usize,
    /// Points measured without the local error (score bounds from below).
    bounds: BTreeMap<GridPoint, Terms>,
    /// Points measured fully.
    exact: Measured,
    /// The run of the second pass under way (kept while the evaluator has not answered).
    pending: Option<Run>,
    finished: bool,
    total: usize,
    max_volume_change: Option<f64>,
}

impl GridMinimum {
    /// `base` supplies what the grid does not vary (the displacement bound).
    pub fn new(filter: Filter, base: &Params, tau: f64) -> Result<Self, ParamError> {
        let (space, base, runs, total) = plan_grid(filter, base)?;
        Ok(Self {
            runs,
            total,
            space,
            base,
            tau,
            next: 0,
            bounds: BTreeMap::new(),
            exact: Measured::default(),
            pending: None,
            finished: false,
            max_volume_change: None,
        })
    }

    /// Looks only among the sets that change the volume by at most `limit` (a fraction), when
    /// given. Bounds measure the volume exactly, so they still rule out what they ruled out.
    pub fn limiting_volume(mut self, limit: Option<f64>) -> Self {
        self.max_volume_change = limit;
        self
    }

    fn goal(&self) -> Goal {
        Goal {
            tau: self.tau,
            max_volume_change: self.max_volume_change,
        }
    }

    /// The points still in question, lowest bound first (ties: the weaker smoothing): those
    /// measured only by bound whose bound does not exceed the best full score.
    fn open_points(&self) -> Vec<GridPoint> {
        let best =
            lowest(&self.space, self.goal(), self.exact.iter()).map(|(_, t)| t.rank(self.goal()));
        let mut open: Vec<(GridPoint, Rank)> = self
            .bounds
            .iter()
            .map(|(&p, t)| (p, t.rank(self.goal())))
            .filter(|&(_, r)| best.is_none_or(|b| r <= b))
            .collect();
        open.sort_by(|(pa, ra), (pb, rb)| {
            ra.cmp(rb).then_with(|| {
                self.space
                    .weakness_key(*pa)
                    .cmp(&self.space.weakness_key(*pb))
            })
        });
        open.into_iter().map(|(p, _)| p).collect()
    }

    /// The next full run: the open points that share the lowest open point's weights.
    fn next_full_run(&self) -> Option<Run> {
        let open = self.open_points();
        let &first = open.first()?;
        let row: Vec<GridPoint> = open
            .into_iter()
            .filter(|p| self.space.same_weights(*p, first))
            .collect();
        plan_runs(&self.space, &row)
            .into_iter()
            .find(|r| r.points.contains(&first))
    }

    fn first_pass(&mut self, evaluator: &mut dyn Evaluator) {
        let later = self.runs.iter().skip(self.next + 1);
        prefetch(evaluator, &self.space, &self.base, later);
        let Some(run) = self.runs.get(self.next) else {
            return;
        };
        let Some((params, at)) = run.request(&self.space, &self.base) else {
            self.next += 1;
            return;
        };
        let Some(answers) = evaluator.measure_bounds(&params, &at) else {
            return;
        };
        for (&p, (t, exact)) in run.points.iter().zip(answers) {
            if exact {
                self.exact.insert(p, t);
            } else {
                self.bounds.insert(p, t);
            }
        }
        self.next += 1;
    }

    /// Measures the pending run fully (planned by [`Task::step`]).
    fn second_pass(&mut self, evaluator: &mut dyn Evaluator) {
        let Some(run) = &self.pending else {
            return;
        };
        if self.exact.measure(&self.space, &self.base, evaluator, run) {
            for p in &run.points {
                self.bounds.remove(p);
            }
            self.pending = None;
        }
    }
}

impl Task for GridMinimum {
    type Output = Suggestion;

    fn step(&mut self, evaluator: &mut dyn Evaluator) -> bool {
        if self.next < self.runs.len() {
            self.first_pass(evaluator);
        } else if !self.finished {
            self.second_pass(evaluator);
        }
        if self.next >= self.runs.len() && !self.finished && self.pending.is_none() {
            // Plan the next full run now, so the step that leaves nothing open reports the
            // search finished.
            self.pending = self.next_full_run();
            self.finished = self.pending.is_none();
        }
        self.finished
    }

    /// Both passes: every point once bounded (or measured), then once measured or ruled out.
    fn progress(&self) -> Progress {
        let seen = self.bounds.len() + self.exact.len();
        let open = match self.next < self.runs.len() {
            true => self.bounds.len(),
            false => self.open_points().len(),
        };
        let settled = seen - open;
        Progress {
            done: seen + settled,
            total: 2 * self.total,
        }
    }

    fn into_output(self) -> Option<Suggestion> {
        if !self.finished {
            return None;
        }
        let (point, terms) = lowest(&self.space, self.goal(), self.exact.iter())?;
        Some(Suggestion {
            filter: self.space.filter,
            params: self.space.params_at(&self.base, point),
            tau: self.tau,
            score: terms.score(self.tau),
            terms,
            // Every point was smoothed and scored, if only by its bound.
            evaluations: self.total,
            search: SearchMethod::Grid,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::synthetic::{bowl, smoothing_model, Bounding, FnEvaluator, Slow};
    use super::super::{run, GridSearch};
    use super::*;

    fn minimum(filter: Filter, tau: f64, ev: &mut dyn Evaluator) -> Suggestion {
        let task = GridMinimum::new(filter, &Params::defaults(filter), tau).unwrap();
        run(task, ev, &mut |p| {
            assert!(p.done <= p.total, "{p:?}");
            true
        })
        .unwrap()
    }

    fn full_grid(filter: Filter, tau: f64, ev: &mut dyn Evaluator) -> Suggestion {
        let task = GridSearch::new(filter, &Params::defaults(filter)).unwrap();
        run(task, ev, &mut |_| true).unwrap().best(tau).unwrap()
    }

    #[test]
    fn finds_the_full_grid_minimum_measuring_fewer_points_fully() {
        for filter in Filter::ALL {
            let space = ParamSpace::of(filter);
            let grid_size = space.all_points(&Params::defaults(filter)).len();
            let mut full = 0;
            for i in 0..=10 {
                let tau = i as f64 / 10.0;
                let want = full_grid(filter, tau, &mut FnEvaluator::new(smoothing_model(filter)));
                let mut ev = Bounding::new(FnEvaluator::new(smoothing_model(filter)));
                let got = minimum(filter, tau, &mut ev);
                assert_eq!(got, want, "{filter} tau {tau}");
                full += ev.full;
            }
            assert!(
                full < 11 * grid_size / 2,
                "{filter}: {full} full measures over 11 taus of a grid of {grid_size}"
            );
        }
    }

    #[test]
    fn ties_and_exact_evaluators_give_the_full_grid_answer() {
        // Every lambda ties along the iteration count: the weakest must win, as in the grid.
        let flat = |p: &Params| Terms {
            curvature_ratio: 1.0 + ((p.iterations as f64) - 20.0).powi(2),
            mean_error: 0.01 * p.lambda as f64,
            volume_change: Some(0.0),
            roughness_ratio: 0.5,
        };
        let want = full_grid(Filter::Laplace, 0.5, &mut FnEvaluator::new(flat));
        let mut ev = Bounding::new(FnEvaluator::new(flat));
        assert_eq!(minimum(Filter::Laplace, 0.5, &mut ev), want);
        // An evaluator without bounds: the first pass is the grid, the second has nothing left.
        for (filter, at) in [(Filter::Hc, [7, 2, 9]), (Filter::Sinc, [6, 3, 0])] {
            let space = ParamSpace::of(filter);
            let want = full_grid(
                filter,
                0.5,
                &mut FnEvaluator::new(bowl(&space, GridPoint(at))),
            );
            let mut ev = FnEvaluator::new(bowl(&space, GridPoint(at)));
            assert_eq!(minimum(filter, 0.5, &mut ev), want);
            assert_eq!(
                ev.runs,
                plan_runs(&space, &space.all_points(&Params::defaults(filter))).len()
            );
        }
    }

    #[test]
    fn an_evaluator_that_answers_later_gets_the_same_minimum() {
        for filter in Filter::ALL {
            let want = minimum(
                filter,
                0.5,
                &mut Bounding::new(FnEvaluator::new(smoothing_model(filter))),
            );
            let mut slow = Slow::new(Bounding::new(FnEvaluator::new(smoothing_model(filter))), 2);
            assert_eq!(minimum(filter, 0.5, &mut slow), want, "{filter}");
        }
    }
}
