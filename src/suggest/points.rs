//! Measured grid points, and the planning that measures several iteration counts of the same
//! weights in one smoothing run (iterations are cumulative for all filters but windowed sinc).

use super::space::{GridPoint, ParamSpace};
use super::{is_cumulative, Evaluator, Request, Terms};
use crate::smooth::Params;
use std::collections::BTreeMap;

/// Grid points that one smoothing run measures: same weights, ascending iteration counts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Run {
    pub points: Vec<GridPoint>,
}

impl Run {
    /// The evaluator request that measures this run's points.
    pub fn request(&self, space: &ParamSpace, base: &Params) -> Option<Request> {
        let &first = self.points.first()?;
        let at = self
            .points
            .iter()
            .map(|&p| space.params_at(base, p).iterations)
            .collect();
        Some((space.params_at(base, first), at))
    }
}

/// Tells `evaluator` the requests of `runs` when it wants to know them.
pub(crate) fn prefetch<'r>(
    evaluator: &mut dyn Evaluator,
    space: &ParamSpace,
    base: &Params,
    runs: impl IntoIterator<Item = &'r Run>,
) {
    if evaluator.wants_prefetch() {
        let requests: Vec<Request> = runs
            .into_iter()
            .filter_map(|r| r.request(space, base))
            .collect();
        evaluator.prefetch(&requests);
    }
}

/// Groups `points` into runs: one per weight setting for cumulative filters, one per point for
/// windowed sinc. Duplicates are dropped; the order is deterministic.
pub(crate) fn plan_runs(space: &ParamSpace, points: &[GridPoint]) -> Vec<Run> {
    let it = space.iteration_axis();
    let mut by_weights: BTreeMap<GridPoint, Vec<GridPoint>> = BTreeMap::new();
    for &p in points {
        let mut weights = p;
        weights.0[it] = 0;
        by_weights.entry(weights).or_default().push(p);
    }
    let mut runs = Vec::new();
    for (_, mut group) in by_weights {
        group.sort_by_key(|p| p.0[it]);
        group.dedup();
        if is_cumulative(space.filter) {
            runs.push(Run { points: group });
        } else {
            runs.extend(group.into_iter().map(|p| Run { points: vec![p] }));
        }
    }
    runs
}

/// The terms of every grid point measured so far; its size is the evaluation count.
#[derive(Clone, Debug, Default)]
pub(crate) struct Measured {
    terms: BTreeMap<GridPoint, Terms>,
}

impl Measured {
    pub fn get(&self, p: GridPoint) -> Option<Terms> {
        self.terms.get(&p).copied()
    }

    pub fn len(&self) -> usize {
        self.terms.len()
    }

    pub fn iter(&self) -> impl Iterator<Item = (GridPoint, Terms)> + '_ {
        self.terms.iter().map(|(&p, &t)| (p, t))
    }

    pub fn insert(&mut self, p: GridPoint, terms: Terms) {
        self.terms.insert(p, terms);
    }

    /// The points of `points` not measured yet.
    pub fn missing(&self, points: &[GridPoint]) -> Vec<GridPoint> {
        points
            .iter()
            .copied()
            .filter(|p| !self.terms.contains_key(p))
            .collect()
    }

    /// Smooths once and records the terms of every point of `run`; `false` when the evaluator
    /// has not finished the run yet (nothing recorded).
    pub fn measure(
        &mut self,
        space: &ParamSpace,
        base: &Params,
        evaluator: &mut dyn Evaluator,
        run: &Run,
    ) -> bool {
        let Some((params, at)) = run.request(space, base) else {
            return true;
        };
        let Some(terms) = evaluator.measure(&params, &at) else {
            return false;
        };
        for (&p, t) in run.points.iter().zip(terms) {
            self.terms.insert(p, t);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smooth::Filter;

    #[test]
    fn cumulative_filters_share_one_run_per_weight_setting() {
        let space = ParamSpace::of(Filter::Laplace);
        let pts = [
            GridPoint([2, 3, 0]),
            GridPoint([2, 1, 0]),
            GridPoint([4, 1, 0]),
            GridPoint([2, 3, 0]),
        ];
        let runs = plan_runs(&space, &pts);
        assert_eq!(
            runs,
            vec![
                Run {
                    points: vec![GridPoint([2, 1, 0]), GridPoint([2, 3, 0])]
                },
                Run {
                    points: vec![GridPoint([4, 1, 0])]
                },
            ]
        );
        let sinc = ParamSpace::of(Filter::Sinc);
        assert_eq!(plan_runs(&sinc, &pts[..2]).len(), 2);
    }
}
