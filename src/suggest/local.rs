//! The paper's local search (section 5.3): n searches for n parameters, search k starting at the
//! maximum of parameter k and the minimum of the others. Each step measures the 3^n - 1 grid
//! neighbours of the centre and moves to the lowest S; a search stops at a local minimum; the
//! result is the best of the n minima. Measured points are remembered, so revisits cost nothing
//! and the evaluation count is the number of distinct parameter sets measured.
//!
//! A search from learned starts may step along the axes first ([`LocalSearch::axes_first`]):
//! each step measures the 2n neighbours that differ in one parameter and moves to the lowest;
//! only where none is lower are the diagonal neighbours that trade strength measured (stronger
//! smoothing in one parameter, weaker in another: HC's higher alpha with lower beta, or fewer
//! iterations with lower beta), and the search moves on or stops. A diagonal neighbour that
//! smooths more (or less) in every parameter it changes lies beyond axis steps in the same
//! directions that were not lower, and S changes with the strength of the smoothing, so it is
//! left out; the valleys a search must follow diagonally (on the whole-body CT map's spleen and
//! heart) run along the trades. Only trades in two parameters are measured: each trade in all
//! three needs a run of weights of its own, and where the searches stop hardly ever depends on
//! them. The search measures fewer parameter sets than the paper's, of
//! which the diagonal ones it leaves out cost a new run each. On real surfaces that is what a
//! search spends most on: measuring a set (local error and curvature at every vertex) costs as
//! much as several iterations, while the runs, resumed from kept states, smooth about as many.
//!
//! "Lowest" is by [`Terms::rank`]: S among the sets that do not roughen the mesh, which come
//! before every set that does; among those, the lower roughness. So a search that starts where
//! the filter diverges (HC's corner of alpha 0, beta 0 and the most iterations, on a staircase
//! mesh) walks out of that region instead of ending on a blown-up mesh.

use super::grid::{check_base, lowest};
use super::points::{plan_runs, prefetch, Measured, Run};
use super::space::{GridPoint, ParamSpace};
use super::{Evaluator, Goal, Progress, Rank, SearchMethod, Suggestion, Task, Terms};
use crate::smooth::{Filter, ParamError, Params};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Start the next search (or finish): queue its start and the start's neighbours.
    Start,
    /// The search moved to a measured centre: queue its neighbours.
    AtCentre,
    /// The neighbours are measured: move or stop.
    Decide,
    Done,
}

/// The local search, one smoothing run per [`Task::step`].
pub struct LocalSearch {
    space: ParamSpace,
    base: Params,
    tau: f64,
    starts: Vec<GridPoint>,
    measured: Measured,
    pending: VecDeque<Run>,
    phase: Phase,
    centre: GridPoint,
    paths: Vec<Vec<GridPoint>>,
    total: usize,
    max_volume_change: Option<f64>,
    axes_first: bool,
}

impl LocalSearch {
    /// `base` supplies what the grid does not vary (the displacement bound).
    pub fn new(filter: Filter, base: &Params, tau: f64) -> Result<Self, ParamError> {
        let base = check_base(filter, base)?;
        let space = ParamSpace::of(filter);
        Ok(Self {
            starts: space.corner_starts(&base),
            total: space.all_points(&base).len(),
            space,
            base,
            tau,
            measured: Measured::default(),
            pending: VecDeque::new(),
            phase: Phase::Start,
            centre: GridPoint([0; 3]),
            paths: Vec::new(),
            max_volume_change: None,
            axes_first: false,
        })
    }

    /// Starts its searches at `starts` (parameter sets of this filter, on the grid) instead of
    /// the corners: where similar meshes' searches ended, so that one or two short searches
    /// stand in for the corners' long ones. Sets off the grid are left out; with none left the
    /// corners stay.
    pub fn starting_at(mut self, starts: &[Params]) -> Self {
        let mut points: Vec<GridPoint> = Vec::new();
        for p in starts.iter().filter(|p| p.filter == self.space.filter) {
            let point = self.space.point_of(p);
            if let Some(point) = point.filter(|&q| self.space.is_valid(&self.base, q)) {
                if !points.contains(&point) {
                    points.push(point);
                }
            }
        }
        if !points.is_empty() {
            self.starts = points;
        }
        self
    }

    /// Looks only among the sets that change the volume by at most `limit` (a fraction), when
    /// given: the search walks out of the sets past it towards it.
    pub fn limiting_volume(mut self, limit: Option<f64>) -> Self {
        self.max_volume_change = limit;
        self
    }

    /// Steps along one parameter at a time, measuring the diagonal neighbours that trade
    /// strength only where no step along an axis is lower (see the module's note).
    pub fn axes_first(mut self) -> Self {
        self.axes_first = true;
        self
    }

    /// The neighbours of `p` measured before the search decides where to go.
    fn first_around(&self, p: GridPoint) -> Vec<GridPoint> {
        let mut around = self.space.neighbours(&self.base, p);
        if self.axes_first {
            around.retain(|q| (0..3).filter(|&k| q.0[k] != p.0[k]).count() == 1);
        }
        around
    }

    /// The neighbours of the centre that decide whether it is where the search stops: all of
    /// `around`, or stepping along the axes first, those that trade strength in two parameters
    /// too.
    fn deciding(&self, around: &[GridPoint]) -> Vec<GridPoint> {
        let c = self.centre;
        let decides = |q: &GridPoint| {
            let changed = (0..self.space.dims()).filter(|&k| q.0[k] != c.0[k]).count();
            !self.axes_first || changed == 1 || (changed == 2 && self.space.trades_strength(c, *q))
        };
        around.iter().copied().filter(decides).collect()
    }

    fn goal(&self) -> Goal {
        Goal {
            tau: self.tau,
            max_volume_change: self.max_volume_change,
        }
    }

    fn queue(&mut self, points: &[GridPoint]) {
        let missing = self.measured.missing(points);
        self.pending.extend(plan_runs(&self.space, &missing));
    }

    fn rank(&self, p: GridPoint) -> Option<Rank> {
        self.measured.get(p).map(|t| t.rank(self.goal()))
    }

    /// Advances the state machine until a run is due or the search is over.
    fn advance(&mut self) {
        while self.pending.is_empty() && self.phase != Phase::Done {
            match self.phase {
                Phase::Start => match self.starts.get(self.paths.len()) {
                    Some(&start) => {
                        // The start and its neighbours at once: those of the same weights
                        // then share one run instead of a run each.
                        self.centre = start;
                        self.paths.push(vec![start]);
                        let mut points = vec![start];
                        points.extend(self.first_around(start));
                        self.queue(&points);
                        self.phase = Phase::Decide;
                    }
                    None => self.phase = Phase::Done,
                },
                Phase::AtCentre => {
                    let around = self.first_around(self.centre);
                    self.queue(&around);
                    self.phase = Phase::Decide;
                }
                Phase::Decide => {
                    let around = self.space.neighbours(&self.base, self.centre);
                    let best = lowest(
                        &self.space,
                        self.goal(),
                        around
                            .iter()
                            .filter_map(|&p| self.measured.get(p).map(|t| (p, t))),
                    );
                    let centre = self.rank(self.centre);
                    match best {
                        Some((p, t)) if centre.is_none_or(|c| t.rank(self.goal()) < c) => {
                            self.centre = p;
                            if let Some(path) = self.paths.last_mut() {
                                path.push(p);
                            }
                            self.phase = Phase::AtCentre;
                        }
                        // None lower among those measured: measure the rest, if any, and
                        // decide again.
                        _ => match self.measured.missing(&self.deciding(&around)) {
                            missing if missing.is_empty() => self.phase = Phase::Start,
                            missing => self.queue(&missing),
                        },
                    }
                }
                Phase::Done => {}
            }
        }
    }
}

impl Task for LocalSearch {
    type Output = LocalOutcome;

    fn step(&mut self, evaluator: &mut dyn Evaluator) -> bool {
        self.advance();
        let later = self.pending.iter().skip(1);
        prefetch(evaluator, &self.space, &self.base, later);
        if let Some(run) = self.pending.front() {
            if self
                .measured
                .measure(&self.space, &self.base, evaluator, run)
            {
                self.pending.pop_front();
                self.advance();
            }
        }
        self.phase == Phase::Done
    }

    fn progress(&self) -> Progress {
        Progress {
            done: self.measured.len(),
            total: self.total,
        }
    }

    fn into_output(self) -> Option<LocalOutcome> {
        if self.phase != Phase::Done {
            return None;
        }
        let minima: Vec<(GridPoint, Terms)> = self
            .paths
            .iter()
            .filter_map(|path| path.last())
            .filter_map(|&p| self.measured.get(p).map(|t| (p, t)))
            .collect();
        let (point, terms) = lowest(&self.space, self.goal(), minima.iter().copied())?;
        let evaluations = self.measured.len();
        let suggestion = Suggestion {
            filter: self.space.filter,
            params: self.space.params_at(&self.base, point),
            tau: self.tau,
            score: terms.score(self.tau),
            terms,
            evaluations,
            search: SearchMethod::Local,
        };
        Some(LocalOutcome {
            suggestion,
            minima: minima.iter().map(|&(p, _)| p).collect(),
            paths: self.paths,
        })
    }
}

/// The local search's result and how it got there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalOutcome {
    pub suggestion: Suggestion,
    /// The local minimum each search stopped at, in start order.
    pub minima: Vec<GridPoint>,
    /// Each search's centres from start to minimum.
    pub paths: Vec<Vec<GridPoint>>,
}

#[cfg(test)]
mod tests {
    use super::super::synthetic::{bowl, smoothing_model, two_basins, FnEvaluator, Slow};
    use super::super::GridSearch;
    use super::*;
    use crate::suggest::run;

    fn local(filter: Filter, tau: f64, ev: &mut dyn Evaluator) -> LocalOutcome {
        let task = LocalSearch::new(filter, &Params::defaults(filter), tau).unwrap();
        run(task, ev, &mut |_| true).unwrap()
    }

    #[test]
    fn an_evaluator_that_answers_later_gets_the_same_search() {
        for filter in Filter::ALL {
            let now = local(filter, 0.4, &mut FnEvaluator::new(smoothing_model(filter)));
            let later = local(
                filter,
                0.4,
                &mut Slow::new(FnEvaluator::new(smoothing_model(filter)), 2),
            );
            assert_eq!(now, later, "{filter:?}");
        }
    }

    #[test]
    fn descends_into_a_bowl_from_every_corner() {
        for (filter, at) in [
            (Filter::Laplace, [3, 4, 0]),
            (Filter::Hc, [7, 2, 9]),
            (Filter::Taubin, [2, 5, 6]),
            (Filter::Sinc, [6, 3, 0]),
        ] {
            let space = ParamSpace::of(filter);
            let centre = GridPoint(at);
            let mut ev = FnEvaluator::new(bowl(&space, centre));
            let out = local(filter, 0.5, &mut ev);
            assert_eq!(out.minima, vec![centre; space.dims()], "{filter}");
            assert_eq!(space.point_of(&out.suggestion.params), Some(centre));
            assert_eq!(out.suggestion.search, SearchMethod::Local);
            // Every step moves to a strictly better neighbour.
            for path in &out.paths {
                for w in path.windows(2) {
                    assert!(space
                        .neighbours(&Params::defaults(filter), w[0])
                        .contains(&w[1]));
                }
            }
            // Revisits are not counted twice; the grid would measure every point.
            assert_eq!(out.suggestion.evaluations, ev.seen.len());
            assert!(out.suggestion.evaluations < space.all_points(&Params::defaults(filter)).len());
        }
    }

    #[test]
    fn three_parameter_search_costs_a_third_of_the_grid_or_less() {
        let space = ParamSpace::of(Filter::Hc);
        let mut ev = FnEvaluator::new(bowl(&space, GridPoint([4, 6, 5])));
        let out = local(Filter::Hc, 0.5, &mut ev);
        assert!(
            3 * out.suggestion.evaluations <= 1331,
            "{}",
            out.suggestion.evaluations
        );
    }

    #[test]
    fn a_search_started_near_the_minimum_finds_it_for_a_fraction_of_the_corners_cost() {
        let space = ParamSpace::of(Filter::Hc);
        let base = Params::defaults(Filter::Hc);
        let centre = GridPoint([4, 6, 5]);
        let from_corners = local(Filter::Hc, 0.5, &mut FnEvaluator::new(bowl(&space, centre)));
        let near = space.params_at(&base, GridPoint([5, 6, 4]));
        // Another filter's set and one off the grid are no starts; the near one is.
        let off_grid = Params {
            alpha: 0.123,
            ..base
        };
        let starts = [Params::defaults(Filter::Taubin), off_grid, near];
        let task = LocalSearch::new(Filter::Hc, &base, 0.5)
            .unwrap()
            .starting_at(&starts);
        let mut ev = FnEvaluator::new(bowl(&space, centre));
        let out = run(task, &mut ev, &mut |_| true).unwrap();
        assert_eq!(out.minima, vec![centre]);
        assert_eq!(out.paths[0][0], GridPoint([5, 6, 4]));
        let (warm, cold) = (
            out.suggestion.evaluations,
            from_corners.suggestion.evaluations,
        );
        assert!(
            3 * warm <= cold,
            "{warm} sets from near, {cold} from the corners"
        );
        // With no start that fits, the corners stay.
        let task = LocalSearch::new(Filter::Hc, &base, 0.5)
            .unwrap()
            .starting_at(&[off_grid]);
        let out = run(
            task,
            &mut FnEvaluator::new(bowl(&space, centre)),
            &mut |_| true,
        )
        .unwrap();
        assert_eq!(out.paths.len(), space.dims());
    }

    /// A valley along a diagonal that trades strength (HC's higher alpha with lower beta): from
    /// a point beside the minimum no step along one axis is lower, only the diagonal one.
    fn diagonal_valley(space: &ParamSpace, centre: GridPoint) -> impl FnMut(&Params) -> Terms {
        let space = space.clone();
        move |p| {
            let at = space.point_of(p).expect("on the grid");
            let d = |k: usize| f64::from(at.0[k]) - f64::from(centre.0[k]);
            let f = 10.0 * (d(0) + d(1)).powi(2) + (d(0) - d(1)).powi(2) + d(2).powi(2);
            Terms {
                curvature_ratio: 1.0 + 0.01 * f,
                mean_error: 0.0,
                volume_change: Some(0.0),
                roughness_ratio: 0.5,
            }
        }
    }

    #[test]
    fn stepping_along_the_axes_first_stops_where_no_neighbour_is_lower() {
        let space = ParamSpace::of(Filter::Hc);
        let base = Params::defaults(Filter::Hc);
        let centre = GridPoint([4, 6, 5]);
        let beside = space.params_at(&base, GridPoint([5, 5, 5]));
        let search = |axes_first: bool, ev: &mut dyn Evaluator| {
            let task = LocalSearch::new(Filter::Hc, &base, 0.5).unwrap();
            let task = task.starting_at(&[beside]);
            let task = if axes_first { task.axes_first() } else { task };
            run(task, ev, &mut |_| true).unwrap()
        };
        let mut ev = FnEvaluator::new(diagonal_valley(&space, centre));
        let out = search(true, &mut ev);
        assert_eq!(out.minima, vec![centre], "the diagonal step was taken");
        assert_eq!(out.paths[0], vec![GridPoint([5, 5, 5]), centre]);
        // Before stopping: every neighbour along an axis or trading strength in two
        // parameters; no other, but for those the start's axis steps measured.
        let changed = |a: GridPoint, b: GridPoint| (0..3).filter(|&k| a.0[k] != b.0[k]).count();
        let start = out.paths[0][0];
        for q in space.neighbours(&base, centre) {
            let p = space.params_at(&base, q);
            let n = changed(centre, q);
            let decides = n == 1 || (n == 2 && space.trades_strength(centre, q));
            let earlier =
                q == start || space.neighbours(&base, start).contains(&q) && changed(start, q) == 1;
            assert_eq!(ev.seen.contains(&p), decides || earlier, "{q:?}");
        }
        let mut every = FnEvaluator::new(diagonal_valley(&space, centre));
        assert_eq!(search(false, &mut every).minima, out.minima);
        // In a bowl, from near the minimum or far from it, fewer sets are measured.
        for start in [[5, 6, 5], [5, 7, 6], [6, 8, 5], [8, 9, 9]] {
            let walk = |axes_first: bool| {
                let mut ev = FnEvaluator::new(bowl(&space, centre));
                let task = LocalSearch::new(Filter::Hc, &base, 0.5).unwrap();
                let task = task.starting_at(&[space.params_at(&base, GridPoint(start))]);
                let task = if axes_first { task.axes_first() } else { task };
                let out = run(task, &mut ev, &mut |_| true).unwrap();
                (out.minima, out.suggestion.evaluations)
            };
            let (axes, all) = (walk(true), walk(false));
            assert_eq!((&axes.0, &all.0), (&vec![centre], &vec![centre]));
            assert!(axes.1 < all.1, "from {start:?}: {axes:?} against {all:?}");
        }
    }

    #[test]
    fn the_second_corner_finds_what_the_first_misses() {
        // Global minimum near lambda = max, iterations = min; a shallower basin near the other
        // corner traps the search that starts there.
        let space = ParamSpace::of(Filter::Laplace);
        let global = GridPoint([8, 2, 0]);
        let trap = GridPoint([2, 8, 0]);
        let mut ev = FnEvaluator::new(two_basins(&space, global, 0.0, trap, 0.1));
        let out = local(Filter::Laplace, 0.5, &mut ev);
        assert_eq!(out.minima, vec![global, trap]);
        assert_eq!(space.point_of(&out.suggestion.params), Some(global));
    }

    #[test]
    fn can_miss_the_global_minimum_and_says_so_honestly() {
        // Both corners lie in the shallow basin: the local search ends there, the grid does not.
        let space = ParamSpace::of(Filter::Laplace);
        let global = GridPoint([9, 9, 0]);
        let trap = GridPoint([3, 3, 0]);
        let f = || two_basins(&space, global, 0.0, trap, 0.05);
        let out = local(Filter::Laplace, 0.5, &mut FnEvaluator::new(f()));
        assert_eq!(out.minima, vec![trap, trap]);
        let g = run(
            GridSearch::new(Filter::Laplace, &Params::defaults(Filter::Laplace)).unwrap(),
            &mut FnEvaluator::new(f()),
            &mut |_| true,
        )
        .unwrap();
        let best = g.best(0.5).unwrap();
        assert_eq!(space.point_of(&best.params), Some(global));
        assert!(out.suggestion.score > best.score);
    }

    #[test]
    fn a_search_that_starts_where_the_filter_diverges_walks_out() {
        // S falls towards HC's corner of weak weights and many iterations, but there the filter
        // roughens the mesh, more the deeper in: the lowest S of the sets that smooth lies on
        // the region's edge, and every search must end on a set that smooths.
        let corner = GridPoint([0, 0, 10]);
        let diverges = |g: [u8; 3]| g[0] + g[1] < 4 && g[2] > 5;
        let landscape = move |p: &Params| {
            let space = ParamSpace::of(Filter::Hc);
            let g = space.point_of(p).unwrap().0;
            if diverges(g) {
                let depth = (4 - g[0] - g[1]) + (g[2] - 5);
                Terms::roughened(1.0 + f64::from(depth))
            } else {
                bowl(&space, corner)(p)
            }
        };
        let out = local(Filter::Hc, 0.5, &mut FnEvaluator::new(landscape));
        let best = run(
            GridSearch::new(Filter::Hc, &Params::defaults(Filter::Hc)).unwrap(),
            &mut FnEvaluator::new(landscape),
            &mut |_| true,
        )
        .unwrap()
        .best(0.5)
        .unwrap();
        assert!(!best.terms.roughens() && best.score.is_finite());
        assert_eq!(out.suggestion.params, best.params);
        let third = &out.paths[2];
        assert_eq!(third[0], corner);
        let end = *third.last().unwrap();
        assert!(
            !diverges(end.0),
            "it ended at {end:?}, where the filter diverges"
        );
        assert!(third.len() > 2, "it walked: {third:?}");
    }

    #[test]
    fn a_start_shares_its_run_with_its_neighbours() {
        // HC's last search starts with every weight at its lowest and iterations at the most;
        // the minimum lies at the first search's start, so nothing before has measured those
        // weights. Their first run measures iterations 45 and 50 together.
        struct Requests(Vec<(Params, Vec<u32>)>);
        impl Evaluator for Requests {
            fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
                self.0.push((*params, at.to_vec()));
                let space = ParamSpace::of(Filter::Hc);
                let mut f = bowl(&space, GridPoint([10, 0, 0]));
                Some(
                    at.iter()
                        .map(|&k| {
                            f(&Params {
                                iterations: k,
                                ..*params
                            })
                        })
                        .collect(),
                )
            }
        }
        let mut ev = Requests(Vec::new());
        let out = local(Filter::Hc, 0.5, &mut ev);
        assert_eq!(out.paths[2][0], GridPoint([0, 0, 10]));
        let corner =
            ev.0.iter()
                .find(|(p, _)| p.alpha == 0.0 && p.beta == 0.0)
                .map(|(_, at)| at);
        assert_eq!(corner, Some(&vec![45, 50]));
    }

    #[test]
    fn neighbours_of_the_same_weights_share_a_run() {
        let space = ParamSpace::of(Filter::Laplace);
        let mut ev = FnEvaluator::new(bowl(&space, GridPoint([5, 5, 0])));
        let out = local(Filter::Laplace, 0.5, &mut ev);
        assert!(ev.runs < out.suggestion.evaluations);
    }

    #[test]
    fn tau_zero_suggests_no_smoothing() {
        for filter in Filter::ALL {
            let mut ev = FnEvaluator::new(smoothing_model(filter));
            let out = local(filter, 0.0, &mut ev);
            assert!(out.suggestion.leaves_mesh_unchanged(), "{filter}");
        }
    }

    #[test]
    fn agrees_with_the_grid_on_a_smooth_response() {
        for filter in Filter::ALL {
            for tau in [0.2, 0.5, 0.8] {
                let g = run(
                    GridSearch::new(filter, &Params::defaults(filter)).unwrap(),
                    &mut FnEvaluator::new(smoothing_model(filter)),
                    &mut |_| true,
                )
                .unwrap()
                .best(tau)
                .unwrap();
                let l = local(filter, tau, &mut FnEvaluator::new(smoothing_model(filter)));
                // The model's optimum is a valley; local search may stop at a different point
                // of it, but never much worse.
                assert!(
                    l.suggestion.score <= g.score + 0.02,
                    "{filter} tau {tau}: {} vs {}",
                    l.suggestion.score,
                    g.score
                );
                assert!(l.suggestion.evaluations < g.evaluations);
            }
        }
    }
}
