//! The real evaluator: smooth with the CPU engine, drift the local error's reference vertices
//! along the run, and measure against the original.

use super::run_states::RunStates;
use crate::evaluate::{is_cumulative, unchanged_terms, Evaluator, Terms};
// pub(super) for the sibling modules that import it from here.
pub(super) use crate::evaluate::terms_of;
use crate::metrics::{measure, measure_shape, DriftState, DriftingReference, Original};
use crate::smooth::{self, smooth, Follower, Params, StepObserver};

/// Per-vertex weights that do not fit the mesh.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WeightsError {
    #[error("{given} vertex weights for a mesh of {vertices} vertices")]
    Count { given: usize, vertices: usize },
    #[error("vertex weight {index} is {value}; weights lie in [0, 1]")]
    Range { index: usize, value: f32 },
}

/// Checks per-vertex weights against the mesh: one per vertex, each in [0, 1].
pub fn check_weights(weights: &[f32], vertices: usize) -> Result<(), WeightsError> {
    if weights.len() != vertices {
        return Err(WeightsError::Count {
            given: weights.len(),
            vertices,
        });
    }
    match weights.iter().position(|w| !(0.0..=1.0).contains(w)) {
        Some(index) => Err(WeightsError::Range {
            index,
            value: weights[index],
        }),
        None => Ok(()),
    }
}

/// Smooths the original mesh of an [`Original`] and measures the results.
pub struct MeshEvaluator<'a> {
    original: &'a Original,
    weights: Option<&'a [f32]>,
    /// States of earlier runs to resume from ([`Self::keeping_states`]).
    states: Option<RunStates>,
    /// Smoothing runs so far (for benchmarks).
    pub runs: usize,
    /// Iterations smoothed so far (for benchmarks).
    pub iterations: u64,
}

impl<'a> MeshEvaluator<'a> {
    /// `weights`, when given, has one entry in [0, 1] per vertex and is passed to every run.
    pub fn new(original: &'a Original, weights: Option<&'a [f32]>) -> Result<Self, WeightsError> {
        if let Some(w) = weights {
            check_weights(w, original.mesh().vertex_count())?;
        }
        Ok(Self {
            original,
            weights,
            states: None,
            runs: 0,
            iterations: 0,
        })
    }

    /// Keeps the states of its runs every `every` iterations, within `budget_bytes`, and
    /// resumes later runs of the same weights from them (`RunStates`): the same terms, fewer
    /// iterations, for searches that come back to the same weights at other counts (the
    /// local search; the grid never does).
    pub fn keeping_states(mut self, budget_bytes: usize, every: u32) -> Self {
        self.states = Some(RunStates::new(budget_bytes, every));
        self
    }

    /// The terms of the unchanged mesh (no volume term when it is open).
    pub(crate) fn unchanged(&self) -> Terms {
        unchanged_terms(self.original)
    }

    /// The positions after `params` and the local error's drifting references, as
    /// [`crate::metrics::smooth_drifting`] gives them, resumed from the latest state its runs
    /// kept of these weights: a search's suggestion is most often a count it ran to, so the
    /// structure it is applied to is not smoothed a second time.
    pub fn smooth_drifting(&mut self, params: &Params) -> (Vec<[f32; 3]>, Vec<u32>) {
        let (mesh, topology) = (self.original.mesh(), self.original.topology());
        let fresh = |e: &Self| crate::metrics::smooth_drifting(e.original, params, e.weights);
        let Some(mut kept) = self.resume_point(params, params.iterations) else {
            return fresh(self);
        };
        let more = params.iterations - kept.count;
        let (start, count) = (kept.positions, kept.count);
        let resumed = smooth::resume(
            mesh,
            topology,
            params,
            self.weights,
            start,
            count,
            more,
            &mut kept.drift,
        );
        match resumed {
            Some(positions) => (positions, kept.drift.into_reference()),
            None => fresh(self),
        }
    }

    /// Where a run of `params` can resume: the latest state the runs kept of its weights at
    /// `count` iterations or before (for a cumulative filter; `None` when none was kept).
    fn resume_point(&mut self, params: &Params, count: u32) -> Option<ResumePoint<'a>> {
        let states = self
            .states
            .as_mut()
            .filter(|_| is_cumulative(params.filter))?;
        let kept = states.latest(params, count)?;
        let state = DriftState::at_home(self.original, kept.reference.clone());
        Some(ResumePoint {
            drift: DriftingReference::resume(self.original, state),
            count: kept.count,
            positions: kept.positions.clone(),
        })
    }
}

/// A kept state of a run, ready to go on from: the drift as it was, after `count` iterations
/// at `positions`.
struct ResumePoint<'o> {
    drift: DriftingReference<'o>,
    count: u32,
    positions: Vec<[f32; 3]>,
}

/// Measures after the wanted iterations of a run; with a drifting reference watching every
/// step the full terms, without one curvature and volume only (the mean error left at 0).
///
/// A run the filter blows up makes every vertex check its ring at every drift step, tens of
/// times the cost of the smoothing. So when most vertices checked their rings in a step, the
/// roughness is taken there too (at most every [`CHECK_EVERY`] iterations); once the mesh is
/// rougher than the original, the drift stops. Each count measured after that which still
/// roughens the mesh needs no drift; one that does not (a filter that is not linear, with
/// weights or a bound, may come back) is left for a run of its own.
struct Along<'o, 'e> {
    original: &'o Original,
    /// Where to keep the run's states, and the run's parameters.
    keep: Option<(&'e mut RunStates, Params)>,
    drift: Option<DriftingReference<'o>>,
    /// Whether the terms are full (measured with the drift): the drift was asked for.
    full: bool,
    /// Whether the roughness may stop the drift.
    checks: bool,
    last_check: u32,
    at: &'e [u32],
    terms: Vec<Terms>,
    /// Indices into `at` of the counts that need a run of their own.
    rerun: Vec<usize>,
}

/// Iterations between roughness checks of a run.
const CHECK_EVERY: u32 = 5;

impl<'o, 'e> Along<'o, 'e> {
    fn new(original: &'o Original, full: bool, at: &'e [u32]) -> Self {
        Self {
            original,
            keep: None,
            drift: full.then(|| DriftingReference::new(original)),
            full,
            checks: full,
            last_check: 0,
            at,
            terms: Vec::with_capacity(at.len()),
            rerun: Vec::new(),
        }
    }

    /// The roughness first: a set that roughens the mesh needs no measure.
    fn measure(&mut self, positions: &[[f32; 3]]) {
        let roughness = self.original.roughness_ratio(positions);
        if roughness > 1.0 {
            self.terms.push(Terms::roughened(roughness));
            return;
        }
        let metrics = match (&self.drift, self.full) {
            (Some(drift), _) => measure(self.original, positions, drift.reference(), 0.5),
            (None, false) => measure_shape(self.original, positions, 0.5),
            (None, true) => {
                self.rerun.push(self.terms.len());
                self.terms.push(Terms::roughened(f64::NAN));
                return;
            }
        };
        self.terms.push(terms_of(&metrics, roughness));
    }

    fn wants_check(&self, iteration: u32) -> bool {
        let n = self.original.mesh().vertex_count();
        self.checks
            && iteration >= self.last_check + CHECK_EVERY
            && self.drift.as_ref().is_some_and(|d| d.ring_checks() > n / 2)
    }

    /// Whether the run's state after `iteration` is to be kept ([`RunStates::keeps`]) while
    /// the drift still follows the run.
    fn keeps(&self, iteration: u32) -> bool {
        let first = self.at.first().copied().unwrap_or(0);
        self.drift.is_some() && (self.keep.as_ref()).is_some_and(|(s, _)| s.keeps(iteration, first))
    }
}

impl StepObserver for Along<'_, '_> {
    fn watches_iteration(&self, iteration: u32) -> bool {
        self.at.get(self.terms.len()) == Some(&iteration)
            || self.wants_check(iteration)
            || self.keeps(iteration)
    }

    fn follower(&mut self) -> Option<&mut dyn Follower> {
        self.drift.as_mut().map(|d| d as &mut dyn Follower)
    }

    fn after_iteration(&mut self, iteration: u32, positions: &[[f32; 3]]) {
        if self.keeps(iteration) {
            if let (Some((states, params)), Some(drift)) = (self.keep.as_mut(), &self.drift) {
                states.keep(params, iteration, positions, drift.reference());
            }
        }
        if self.at.get(self.terms.len()) == Some(&iteration) {
            self.measure(positions);
        } else if self.wants_check(iteration) {
            self.last_check = iteration;
            if self.original.roughness_ratio(positions) > 1.0 {
                self.drift = None;
            }
        }
    }
}

impl MeshEvaluator<'_> {
    /// The terms after each count of `at`: the unchanged mesh's for the counts that move
    /// nothing, then one run per cumulative request (one per count for windowed sinc). With
    /// `drift` the full terms, else curvature and volume only.
    fn measure_runs(&mut self, params: &Params, at: &[u32], drift: bool) -> Vec<Terms> {
        let (mesh, topology) = (self.original.mesh(), self.original.topology());
        // Zero iterations (or steps that move nothing) give the original mesh, whose terms are
        // known exactly.
        let zeros = params.unchanged_counts(at);
        let mut out: Vec<Terms> = (0..zeros).map(|_| self.unchanged()).collect();
        let rest = &at[zeros..];
        let cumulative = is_cumulative(params.filter);
        let runs: Vec<&[u32]> = match cumulative {
            true if !rest.is_empty() => vec![rest],
            true => Vec::new(),
            false => rest.chunks(1).collect(),
        };
        for run in runs {
            let mut p = *params;
            p.iterations = run[run.len() - 1];
            // Windowed sinc reports no iterations on the way: measured once it is done.
            let mut along = Along::new(self.original, drift, if cumulative { run } else { &[] });
            // A kept state of these weights before the first count: the run resumes there.
            let mut from = None;
            if drift {
                if let Some(kept) = self.resume_point(&p, run[0].saturating_sub(1)) {
                    along.drift = Some(kept.drift);
                    along.last_check = kept.count;
                    from = Some((kept.count, kept.positions));
                }
                along.keep = (self.states.as_mut())
                    .filter(|_| cumulative)
                    .map(|s| (s, p));
            }
            let done = from.as_ref().map_or(0, |f| f.0);
            self.iterations += u64::from(p.iterations - done);
            let positions = match from {
                Some((count, start)) => {
                    let more = p.iterations - count;
                    smooth::resume(
                        mesh,
                        topology,
                        &p,
                        self.weights,
                        start,
                        count,
                        more,
                        &mut along,
                    )
                    .expect("a cumulative filter's run of the mesh's length resumes")
                }
                None => smooth(mesh, topology, &p, self.weights, &mut along),
            };
            // A mesh the engine cannot smooth (nothing to move) reports no iterations: its
            // result is the same for every count.
            while along.terms.len() < run.len() {
                along.measure(&positions);
            }
            self.runs += 1;
            let mut terms = along.terms;
            for k in along.rerun {
                terms[k] = self.run_alone(&p, run[k]);
            }
            out.extend(terms);
        }
        out
    }

    /// The full terms after `count` iterations of `params`, drifting all the way.
    fn run_alone(&mut self, params: &Params, count: u32) -> Terms {
        let (mesh, topology) = (self.original.mesh(), self.original.topology());
        let mut p = *params;
        p.iterations = count;
        let at = [count];
        let mut along = Along::new(self.original, true, &at);
        along.checks = false;
        self.iterations += u64::from(count);
        let positions = smooth(mesh, topology, &p, self.weights, &mut along);
        if along.terms.is_empty() {
            along.measure(&positions);
        }
        self.runs += 1;
        along.terms[0]
    }
}

impl Evaluator for MeshEvaluator<'_> {
    /// Without the local error: the smoothing runs without the drifting reference and each
    /// measure skips half its work.
    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        let zeros = params.unchanged_counts(at);
        let terms = self.measure_runs(params, at, false);
        Some(
            terms
                .into_iter()
                .enumerate()
                .map(|(k, t)| (t, k < zeros))
                .collect(),
        )
    }

    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        Some(self.measure_runs(params, at, true))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::smooth_drifting;
    use crate::smooth::Filter;

    #[test]
    fn a_run_that_moves_nothing_is_answered_without_smoothing_and_truthfully() {
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "sample.ply").unwrap();
        let original = Original::new(&mesh, &crate::mesh::Topology::build(&mesh));
        let mut params = Params::defaults(Filter::Laplace);
        params.lambda = 0.0;
        let at = [0, 5, 50];
        let mut ev = MeshEvaluator::new(&original, None).unwrap();
        let answered = ev.measure(&params, &at).unwrap();
        assert_eq!(ev.runs, 0, "no smoothing run");
        for (&k, terms) in at.iter().zip(&answered) {
            params.iterations = k;
            let (positions, reference) = smooth_drifting(&original, &params, None);
            assert_eq!(
                positions,
                original.mesh().positions,
                "lambda 0 moves nothing"
            );
            let measured = crate::metrics::measure(&original, &positions, &reference, 0.5);
            let roughness = original.roughness_ratio(&positions);
            assert_eq!(roughness, 1.0);
            assert_eq!(*terms, terms_of(&measured, roughness), "{k}");
        }
    }

    fn bent_tube() -> Original {
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "sample.ply").unwrap();
        Original::new(&mesh, &crate::mesh::Topology::build(&mesh))
    }

    /// The terms by hand: smooth with the drift all the way, then the roughness and measures.
    fn by_hand(original: &Original, params: &Params, count: u32) -> Terms {
        let mut p = *params;
        p.iterations = count;
        let (positions, reference) = smooth_drifting(original, &p, None);
        let metrics = crate::metrics::measure(original, &positions, &reference, 0.5);
        terms_of(&metrics, original.roughness_ratio(&positions))
    }

    #[test]
    fn a_run_the_filter_blows_up_stops_drifting_and_reports_the_same_terms() {
        let original = bent_tube();
        let mut params = Params::defaults(Filter::Hc);
        (params.alpha, params.beta) = (0.0, 0.0);
        let at = [5, 30, 50];
        let mut ev = MeshEvaluator::new(&original, None).unwrap();
        let got = ev.measure(&params, &at).unwrap();
        for (&k, t) in at.iter().zip(&got) {
            // By their printouts: the terms of a blown-up mesh are NaN, which equals nothing.
            let want = by_hand(&original, &params, k);
            assert_eq!(format!("{t:?}"), format!("{want:?}"), "{k}");
        }
        assert!(!got[0].roughens() && got[2].roughens(), "{got:?}");
        // The run stopped its drift on the way.
        let mut p = params;
        p.iterations = 50;
        let at = [50];
        let mut along = Along::new(&original, true, &at);
        smooth(original.mesh(), original.topology(), &p, None, &mut along);
        assert!(along.drift.is_none() && along.last_check > 0 && along.last_check < 50);
        assert!(along.terms[0].roughens() && along.rerun.is_empty());
    }

    #[test]
    fn a_count_that_smooths_after_the_drift_stopped_gets_a_run_of_its_own() {
        let original = bent_tube();
        let params = Params::defaults(Filter::Hc);
        let at = [7];
        let mut along = Along::new(&original, true, &at);
        along.drift = None;
        along.measure(&original.mesh().positions);
        assert_eq!(along.rerun, vec![0]);
        let mut ev = MeshEvaluator::new(&original, None).unwrap();
        assert_eq!(ev.run_alone(&params, 7), by_hand(&original, &params, 7));
    }

    #[test]
    fn bounds_are_the_terms_without_the_local_error() {
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "sample.ply").unwrap();
        let original = Original::new(&mesh, &crate::mesh::Topology::build(&mesh));
        let mut ev = MeshEvaluator::new(&original, None).unwrap();
        for filter in Filter::ALL {
            let params = Params::defaults(filter);
            let at: &[u32] = if filter == Filter::Sinc {
                &[0, 7]
            } else {
                &[0, 3, 12]
            };
            let exact = ev.measure(&params, at).unwrap();
            let bounds = ev.measure_bounds(&params, at).unwrap();
            assert_eq!(
                bounds[0],
                (exact[0], true),
                "{filter}: the unchanged mesh is exact"
            );
            for ((b, is_exact), e) in bounds.iter().zip(&exact).skip(1) {
                assert!(!is_exact);
                assert_eq!(b.curvature_ratio, e.curvature_ratio, "{filter}");
                assert_eq!(b.volume_change, e.volume_change, "{filter}");
                assert_eq!(b.mean_error, 0.0);
                assert!(
                    e.mean_error > 0.0 && b.score(0.5) < e.score(0.5),
                    "{filter}"
                );
            }
        }
    }

    #[test]
    fn runs_resumed_from_kept_states_measure_the_same_terms() {
        let original = bent_tube();
        let n = original.mesh().vertex_count();
        let weights: Vec<f32> = (0..n).map(|i| (i % 4) as f32 / 3.0).collect();
        for (filter, weights, bound) in [
            (Filter::Hc, None, None),
            (Filter::Hc, Some(&weights[..]), Some(0.5)),
            (Filter::Taubin, None, None),
            // Shrinks: vertices drift many hops from their own references.
            (Filter::Laplace, None, None),
        ] {
            let mut params = Params::defaults(filter);
            params.max_displacement = bound;
            if filter == Filter::Laplace {
                params.lambda = 0.9;
            }
            // Down the iteration axis as the local search walks it, and up again.
            let requests: [&[u32]; 5] = [&[45, 50], &[40], &[30, 35], &[33], &[48]];
            let mut fresh = MeshEvaluator::new(&original, weights).unwrap();
            let mut kept = MeshEvaluator::new(&original, weights)
                .unwrap()
                .keeping_states(1 << 30, 5);
            for at in requests {
                let want = fresh.measure(&params, at).unwrap();
                assert_eq!(kept.measure(&params, at).unwrap(), want, "{filter} {at:?}");
            }
            // From 0 to 50 (keeping 35 to 50), then from 35, from 0 (nothing kept below 35;
            // keeping 20 to 35), from 30 and from 45.
            assert_eq!(fresh.iterations, 50 + 40 + 35 + 33 + 48, "{filter}");
            assert_eq!(kept.iterations, 50 + 5 + 35 + 3 + 3, "{filter}");
            // Other weights share nothing.
            params.beta = 0.25;
            params.lambda *= 0.8;
            kept.measure(&params, &[10]).unwrap();
            assert_eq!(kept.iterations, 96 + 10, "{filter}");
        }
        // A run the filter blows up keeps no states once its drift stopped, and a count
        // measured after that comes out the same.
        let mut blown = Params::defaults(Filter::Hc);
        (blown.alpha, blown.beta) = (0.0, 0.0);
        let mut fresh = MeshEvaluator::new(&original, None).unwrap();
        let mut kept = MeshEvaluator::new(&original, None)
            .unwrap()
            .keeping_states(1 << 30, 5);
        for at in [&[50][..], &[45], &[5]] {
            let (want, got) = (fresh.measure(&blown, at), kept.measure(&blown, at));
            assert_eq!(format!("{got:?}"), format!("{want:?}"), "{at:?}");
        }
    }

    #[test]
    fn the_smoothing_after_a_search_resumes_from_its_runs_and_equals_a_fresh_one() {
        let original = bent_tube();
        let n = original.mesh().vertex_count();
        let weights: Vec<f32> = (0..n).map(|i| (i % 4) as f32 / 3.0).collect();
        for (filter, weights) in [
            (Filter::Hc, None),
            (Filter::Hc, Some(&weights[..])),
            (Filter::Taubin, None),
            (Filter::Sinc, None),
        ] {
            let params = Params::defaults(filter);
            let mut kept = MeshEvaluator::new(&original, weights)
                .unwrap()
                .keeping_states(1 << 30, 5);
            kept.measure(&params, &[20, 25]).unwrap();
            let before = kept.iterations;
            // At a count it ran to, from a kept state below one, and past every kept state.
            for count in [25, 22, 40, 0] {
                let mut p = params;
                p.iterations = count;
                let want = crate::metrics::smooth_drifting(&original, &p, weights);
                assert_eq!(kept.smooth_drifting(&p), want, "{filter} {count}");
            }
            assert_eq!(kept.iterations, before, "not counted as the search's");
        }
    }

    #[test]
    fn weights_must_fit_the_mesh() {
        assert!(check_weights(&[0.0, 0.5, 1.0], 3).is_ok());
        assert_eq!(
            check_weights(&[0.0, 0.5], 3),
            Err(WeightsError::Count {
                given: 2,
                vertices: 3
            })
        );
        assert!(matches!(
            check_weights(&[0.0, f32::NAN, 1.0], 3),
            Err(WeightsError::Range { index: 1, .. })
        ));
        assert!(check_weights(&[1.5], 1).is_err());
    }
}
