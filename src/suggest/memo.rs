//! Terms already measured, kept for the next search. The terms of a parameter set do not depend
//! on tau, and searches on the same model and filter measure many of the same sets: the
//! gallery's five local searches (one per tau), the suggestion made when a model opens, a
//! Suggest at another tau, the quality graphs. [`Memoized`] answers those from a [`TermsMemo`]
//! and asks its evaluator only for the iteration counts never measured.

use super::{Evaluator, Request, Terms};
use crate::smooth::{Filter, Params};
use std::collections::HashMap;

/// A parameter set without its iteration count, hashable (the weights' bit patterns).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct RunKey {
    filter: Filter,
    weights: [u32; 5],
    bound: Option<u32>,
}

impl RunKey {
    pub(crate) fn of(p: &Params) -> Self {
        Self {
            filter: p.filter,
            weights: [p.lambda, p.mu, p.alpha, p.beta, p.passband].map(f32::to_bits),
            bound: p.max_displacement.map(f32::to_bits),
        }
    }
}

/// Measured terms by parameter set and iteration count, for one model with its weights (the
/// caller keeps one memo per model, weights and engine, and drops it when they change).
#[derive(Debug, Default)]
pub struct TermsMemo {
    known: HashMap<(RunKey, u32), Terms>,
}

impl TermsMemo {
    /// Entries kept at most (about 10 MB); past it the memo starts again empty.
    pub const CAPACITY: usize = 200_000;

    /// How many (parameter set, count) terms are kept.
    pub fn len(&self) -> usize {
        self.known.len()
    }

    pub fn is_empty(&self) -> bool {
        self.known.is_empty()
    }

    fn get(&self, key: RunKey, count: u32) -> Option<Terms> {
        self.known.get(&(key, count)).copied()
    }

    /// The counts of `at` not measured yet for `params`.
    fn missing(&self, params: &Params, at: &[u32]) -> Vec<u32> {
        let key = RunKey::of(params);
        at.iter()
            .copied()
            .filter(|&k| self.get(key, k).is_none())
            .collect()
    }

    fn insert(&mut self, params: &Params, at: &[u32], terms: &[Terms]) {
        if self.known.len() + at.len() > Self::CAPACITY {
            self.known.clear();
        }
        let key = RunKey::of(params);
        for (&k, t) in at.iter().zip(terms) {
            // A failed evaluator answers NaN terms: never keep those.
            if !t.failed() {
                self.known.insert((key, k), *t);
            }
        }
    }
}

/// `inner` with the terms it measured kept in `memo`, and requests for known terms answered
/// from there. Answers are the inner evaluator's, so a search gives the same result with or
/// without the memo; it only measures less.
pub struct Memoized<'a, E: Evaluator> {
    pub memo: &'a mut TermsMemo,
    pub inner: E,
}

impl<E: Evaluator> Evaluator for Memoized<'_, E> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        let missing = self.memo.missing(params, at);
        let mut fresh = None;
        if !missing.is_empty() {
            let terms = self.inner.measure(params, &missing)?;
            self.memo.insert(params, &missing, &terms);
            fresh = Some((missing, terms));
        }
        let key = RunKey::of(params);
        let answer = at
            .iter()
            .map(|&k| {
                let just_measured = fresh.as_ref().and_then(|(counts, terms)| {
                    counts.iter().position(|&c| c == k).map(|i| terms[i])
                });
                just_measured.or_else(|| self.memo.get(key, k))
            })
            .collect::<Option<Vec<Terms>>>();
        // Every count was either known or just measured.
        debug_assert!(answer.is_some());
        answer
    }

    /// Known terms are exact; the inner evaluator bounds the rest (its exact answers are kept).
    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        let missing = self.memo.missing(params, at);
        let fresh = if missing.is_empty() {
            Vec::new()
        } else {
            self.inner.measure_bounds(params, &missing)?
        };
        for (&k, &(t, exact)) in missing.iter().zip(&fresh) {
            if exact {
                self.memo.insert(params, &[k], &[t]);
            }
        }
        let key = RunKey::of(params);
        let answer = at
            .iter()
            .map(|&k| match missing.iter().position(|&c| c == k) {
                Some(i) => fresh.get(i).copied(),
                None => self.memo.get(key, k).map(|t| (t, true)),
            })
            .collect::<Option<Vec<(Terms, bool)>>>();
        debug_assert!(answer.is_some());
        answer
    }

    fn wants_prefetch(&self) -> bool {
        self.inner.wants_prefetch()
    }

    /// Passes on only what is not known yet.
    fn prefetch(&mut self, requests: &[Request]) {
        let unknown: Vec<Request> = requests
            .iter()
            .filter_map(|(params, at)| {
                let missing = self.memo.missing(params, at);
                (!missing.is_empty()).then_some((*params, missing))
            })
            .collect();
        self.inner.prefetch(&unknown);
    }
}

#[cfg(test)]
mod tests {
    use super::super::synthetic::{smoothing_model, FnEvaluator};
    use super::super::{run, LocalSearch, Progress};
    use super::*;

    fn never_cancel(_: Progress) -> bool {
        true
    }

    #[test]
    fn searches_at_several_taus_give_the_same_answers_measuring_less() {
        for filter in [Filter::Laplace, Filter::Taubin, Filter::Hc, Filter::Sinc] {
            let base = Params::defaults(filter);
            let mut memo = TermsMemo::default();
            let (mut alone, mut shared) = (0, 0);
            for tau in [0.1, 0.3, 0.5, 0.7, 0.9] {
                let mut plain = FnEvaluator::new(smoothing_model(filter));
                let task = LocalSearch::new(filter, &base, tau).unwrap();
                let want = run(task, &mut plain, &mut never_cancel).unwrap();
                alone += plain.seen.len();

                let mut inner = FnEvaluator::new(smoothing_model(filter));
                let mut memoized = Memoized {
                    memo: &mut memo,
                    inner: &mut inner,
                };
                let task = LocalSearch::new(filter, &base, tau).unwrap();
                let got = run(task, &mut memoized, &mut never_cancel).unwrap();
                shared += inner.seen.len();
                assert_eq!(got.suggestion, want.suggestion, "{filter:?} tau {tau}");
            }
            assert!(
                shared < alone,
                "{filter:?}: {shared} counts measured with the memo, {alone} without"
            );
            assert_eq!(memo.len(), shared, "{filter:?}: each count measured once");
        }
    }

    #[test]
    fn answers_mix_known_and_new_counts_in_the_order_asked() {
        let filter = Filter::Hc;
        let params = Params::defaults(filter);
        let want = FnEvaluator::new(smoothing_model(filter))
            .measure(&params, &[0, 5, 10, 15, 20])
            .unwrap();
        let mut memo = TermsMemo::default();
        let mut inner = FnEvaluator::new(smoothing_model(filter));
        let mut memoized = Memoized {
            memo: &mut memo,
            inner: &mut inner,
        };
        assert_eq!(
            memoized.measure(&params, &[5, 15]).unwrap(),
            [want[1], want[3]]
        );
        assert_eq!(
            memoized.measure(&params, &[0, 5, 10, 15, 20]).unwrap(),
            want
        );
        assert_eq!(
            memoized.measure(&params, &[10, 20]).unwrap(),
            [want[2], want[4]]
        );
        // Another parameter set is measured afresh.
        let other = Params {
            alpha: 0.3,
            ..params
        };
        memoized.measure(&other, &[5]).unwrap();
        assert_eq!(
            inner.seen.len(),
            6,
            "each count measured once: {:?}",
            inner.seen
        );
    }

    #[test]
    fn failed_measurements_are_not_kept() {
        let nan = Terms {
            curvature_ratio: f64::NAN,
            mean_error: f64::NAN,
            volume_change: None,
            roughness_ratio: f64::NAN,
        };
        let mut inner = FnEvaluator::new(|_: &Params| nan);
        let mut memo = TermsMemo::default();
        let mut memoized = Memoized {
            memo: &mut memo,
            inner: &mut inner,
        };
        let params = Params::defaults(Filter::Laplace);
        let got = memoized.measure(&params, &[5, 10]).unwrap();
        assert!(got.iter().all(|t| t.curvature_ratio.is_nan()));
        assert!(memo.is_empty());
        // A set that blew the mesh up has NaN measures too, but its answer is known: kept.
        let mut inner = FnEvaluator::new(|_: &Params| Terms::roughened(3.0));
        let mut memoized = Memoized {
            memo: &mut memo,
            inner: &mut inner,
        };
        memoized.measure(&params, &[5, 10]).unwrap();
        assert_eq!(memo.len(), 2);
    }
}
