//! Model quality graphs and parameter suggestions (paper section 5; ALGORITHMS.md, "Model
//! quality graphs" and "Parameter suggestion").
//!
//! Everything here is generic over an [`Evaluator`]: something that smooths with given
//! parameters and returns the score terms. The search logic never smooths by itself, so it is
//! tested on synthetic evaluators with known minima, and runs unchanged on the real engine.
//!
//! The work is split into [`Task`]s that do one smoothing run per [`Task::step`], so the web app
//! can interleave them with frames (wasm32 is single-threaded) and the CLI can run them to the end
//! with [`run`], reporting progress and honouring cancellation between runs.

mod auto;
mod bounded;
mod grid;
mod local;
mod memo;
mod mesh_evaluator;
mod offload;
mod points;
mod run_states;
mod sliced;
mod space;
mod sweep;

pub use auto::{
    quality_graphs, quality_graphs_on, search_evaluator, suggest, suggest_for_goal,
    suggest_for_mesh, suggest_on, SuggestError, LOCAL_SEARCH_STATE_BYTES,
};
pub use bounded::GridMinimum;
pub use grid::{EvaluatedGrid, GridSearch};
pub use local::{LocalOutcome, LocalSearch};
pub use memo::{Memoized, TermsMemo};
pub use mesh_evaluator::{check_weights, terms_of, MeshEvaluator, WeightsError};
pub use offload::{failed_terms, unchanged_terms, ModelRef, Offload, Offloaded};
pub use sliced::{Sliced, SlicedRuns};
pub use space::{Axis, GridPoint, Param, ParamSpace};
pub use sweep::{Curve, QualityGraphs, QualitySweep, Sample};

use crate::smooth::{Filter, Params};
use serde::{Deserialize, Serialize};

/// The quantities the score is made of (paper eq. 4). Equal when every field is, NaN equal to
/// NaN: the terms of a set not measured further ([`Terms::roughened`]) are the same answer.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Terms {
    /// K/K0: mean |Gaussian curvature| relative to the original mesh.
    pub curvature_ratio: f64,
    /// E: mean local error (mesh units, mm).
    pub mean_error: f64,
    /// |V - V0| / V0; `None` when the mesh is open and its volume means nothing.
    pub volume_change: Option<f64>,
    /// R/R0, the roughness relative to the original's ([`crate::metrics::roughness()`]). Not
    /// part of S: above 1 the filter amplified what it should damp (it is unstable at these
    /// parameters on this mesh), and [`Terms::rank`] puts the set after every one that smooths.
    pub roughness_ratio: f64,
}

/// What a search looks for: the lowest S(tau), among the sets that change the volume by at
/// most `max_volume_change` (a fraction) when one is given. Thin structures (vessels) lose
/// volume to smoothing faster than the score weighs it; an author of a case can hold them to
/// a limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goal {
    pub tau: f64,
    pub max_volume_change: Option<f64>,
}

impl From<f64> for Goal {
    fn from(tau: f64) -> Self {
        Goal {
            tau,
            max_volume_change: None,
        }
    }
}

/// Where a measured parameter set stands in a search (lower is better): every set that does
/// not roughen the mesh by its score S, then those that do by their roughness ratio (so a
/// local search that starts among them walks out towards the sets that smooth), then the
/// failed ones (NaN).
#[derive(Clone, Copy, Debug)]
pub struct Rank {
    class: u8,
    /// Never NaN.
    key: f64,
}

impl PartialEq for Terms {
    fn eq(&self, other: &Self) -> bool {
        same(self.curvature_ratio, other.curvature_ratio)
            && same(self.mean_error, other.mean_error)
            && same(self.roughness_ratio, other.roughness_ratio)
            && match (self.volume_change, other.volume_change) {
                (Some(a), Some(b)) => same(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

/// Equal, or both NaN.
pub(crate) fn same(a: f64, b: f64) -> bool {
    a == b || a.is_nan() && b.is_nan()
}

impl PartialEq for Rank {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Rank {}

impl PartialOrd for Rank {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Rank {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.class
            .cmp(&other.class)
            .then_with(|| score_order(self.key, other.key))
    }
}

impl Terms {
    /// The terms of the unchanged mesh.
    pub const UNCHANGED: Terms = Terms {
        curvature_ratio: 1.0,
        mean_error: 0.0,
        volume_change: Some(0.0),
        roughness_ratio: 1.0,
    };

    /// The terms of a set that left the mesh `roughness_ratio` (> 1) times as rough as the
    /// original: the score's terms are NaN, since measures of a mesh the filter blew up mean
    /// nothing (its curvature falls as it grows, and E/(E+1) saturates), and the evaluators
    /// skip them.
    pub fn roughened(roughness_ratio: f64) -> Terms {
        Terms {
            curvature_ratio: f64::NAN,
            mean_error: f64::NAN,
            volume_change: None,
            roughness_ratio,
        }
    }

    /// Whether the smoothed mesh came out rougher than the original: the filter diverges here.
    pub fn roughens(&self) -> bool {
        self.roughness_ratio > 1.0
    }

    /// Whether the evaluation failed (a lost device): NaN terms that say nothing, not even
    /// the roughness.
    pub fn failed(&self) -> bool {
        self.roughness_ratio.is_nan()
            || !self.roughens() && (self.curvature_ratio.is_nan() || self.mean_error.is_nan())
    }

    /// The set's [`Rank`] for a goal (a `tau`, or a [`Goal`] that also limits the volume
    /// change): the sets within the limit by S, then those past it by their volume change (a
    /// search that starts among them walks towards the limit), then those that roughen the
    /// mesh, then the failed ones.
    pub fn rank(&self, goal: impl Into<Goal>) -> Rank {
        let goal = goal.into();
        let score = self.score(goal.tau);
        let past_limit = match (goal.max_volume_change, self.volume_change) {
            (Some(limit), Some(change)) => change.abs() > limit,
            _ => false,
        };
        if self.failed() || score.is_nan() && !self.roughens() {
            Rank { class: 3, key: 0.0 }
        } else if self.roughens() {
            Rank {
                class: 2,
                key: self.roughness_ratio,
            }
        } else if past_limit {
            Rank {
                class: 1,
                key: self.volume_change.map_or(0.0, f64::abs),
            }
        } else {
            Rank {
                class: 0,
                key: score,
            }
        }
    }

    /// The accuracy half of the score, `0.5 * (E/(E+1) + |V-V0|/V0)`. Without a volume (open
    /// mesh) it is `E/(E+1)` alone, the mean of the terms that exist, as in [`crate::metrics`].
    pub fn accuracy(&self) -> f64 {
        let e = self.mean_error / (self.mean_error + 1.0);
        match self.volume_change {
            Some(v) => 0.5 * (e + v),
            None => e,
        }
    }

    /// `S(tau) = tau * K/K0 + (1 - tau) * accuracy`. Lower is better. NaN terms give NaN, which
    /// every comparison here ranks last.
    pub fn score(&self, tau: f64) -> f64 {
        tau * self.curvature_ratio + (1.0 - tau) * self.accuracy()
    }
}

/// Smooths and measures. Implementations: the real engine ([`crate::smooth`] plus
/// [`crate::metrics`]) and synthetic functions in tests.
pub trait Evaluator {
    /// Smooths with `params` (its `iterations` field is ignored) and returns the terms after each
    /// iteration count in `at` (ascending, distinct; 0 means the unchanged mesh), in that order.
    ///
    /// For filters whose k-iteration result is a prefix of a longer run (all but windowed sinc)
    /// this is one run measured along the way; callers pass sinc one count at a time.
    ///
    /// `None` means the run is under way but not finished: the caller asks again, with the same
    /// request, later. Evaluators that spread a run over several calls (the web app's frames)
    /// use it; the others always answer.
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>>;

    /// [`Self::measure`], where the evaluator may leave out the local error (which needs the
    /// drifting reference along the run and about half of each measure): such terms hold a
    /// mean error of 0, below the true one, and the flag beside them is `false`. Their score is
    /// then a lower bound of the true score (the other terms are exact), which lets a search
    /// rule parameter sets out before measuring them fully ([`GridMinimum`]). By default every
    /// answer is exact.
    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        let terms = self.measure(params, at)?;
        Some(terms.into_iter().map(|t| (t, true)).collect())
    }

    /// Whether this evaluator does better knowing the requests to come ([`Self::prefetch`]):
    /// one that answers a frame later (the GPU's) batches them.
    fn wants_prefetch(&self) -> bool {
        false
    }

    /// The requests the caller will make after the next one, in order, as far as it knows
    /// them. Only a hint: what is asked later is answered either way.
    fn prefetch(&mut self, _requests: &[Request]) {}
}

/// An evaluator lent by reference (to wrap it, as [`Memoized`] does).
impl<E: Evaluator + ?Sized> Evaluator for &mut E {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        (**self).measure(params, at)
    }

    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        (**self).measure_bounds(params, at)
    }

    fn wants_prefetch(&self) -> bool {
        (**self).wants_prefetch()
    }

    fn prefetch(&mut self, requests: &[Request]) {
        (**self).prefetch(requests)
    }
}

/// One [`Evaluator::measure`] request: parameters and iteration counts.
pub type Request = (Params, Vec<u32>);

/// Whether the k-iteration result of `filter` is the state after k iterations of a longer run.
/// Windowed sinc's iteration count is the degree of its polynomial, so each count is its own run.
pub fn is_cumulative(filter: Filter) -> bool {
    filter != Filter::Sinc
}

/// How far a task has come, in parameter sets measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Progress {
    pub done: usize,
    /// Known for sweeps and the grid; for the local search an upper bound (the grid's size).
    pub total: usize,
}

/// A piece of work done one smoothing run at a time.
pub trait Task {
    type Output;
    /// Does one smoothing run (or finishes without one); returns `true` once nothing is left.
    /// When the evaluator has not finished the run ([`Evaluator::measure`] gave `None`) nothing
    /// advances and the next call asks for the same run.
    fn step(&mut self, evaluator: &mut dyn Evaluator) -> bool;
    fn progress(&self) -> Progress;
    /// The result, once [`Task::step`] has returned `true`; `None` before.
    fn into_output(self) -> Option<Self::Output>;
}

/// The caller asked to stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

/// Runs `task` to the end. `on_progress` is called after every run; returning `false` cancels.
pub fn run<T: Task>(
    mut task: T,
    evaluator: &mut dyn Evaluator,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<T::Output, Cancelled> {
    loop {
        let finished = task.step(evaluator);
        if !on_progress(task.progress()) {
            return Err(Cancelled);
        }
        if finished {
            return task.into_output().ok_or(Cancelled);
        }
    }
}

/// Which whole-filter search to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SearchMethod {
    /// Every grid point.
    Grid,
    /// The paper's local search from opposite corners.
    Local,
}

impl SearchMethod {
    pub fn name(self) -> &'static str {
        match self {
            SearchMethod::Grid => "grid",
            SearchMethod::Local => "local",
        }
    }

    pub fn from_name(name: &str) -> Option<SearchMethod> {
        [SearchMethod::Grid, SearchMethod::Local]
            .into_iter()
            .find(|m| m.name() == name)
    }
}

/// A suggested parameter set for one filter and target smoothness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Suggestion {
    pub filter: Filter,
    /// The suggested parameters; weights and displacement bound are the caller's, passed through.
    /// `iterations == 0` means "leave the mesh unchanged" for every filter, windowed sinc included.
    pub params: Params,
    pub tau: f64,
    /// S(tau) of `params`.
    pub score: f64,
    pub terms: Terms,
    /// Distinct parameter sets measured to find it.
    pub evaluations: usize,
    pub search: SearchMethod,
}

impl Suggestion {
    /// Whether the suggestion is to leave the mesh as it is.
    pub fn leaves_mesh_unchanged(&self) -> bool {
        self.params.iterations == 0
    }

    /// What `suggest --json` prints and the web API's `suggest()` resolves with; `seconds` is
    /// how long the search took.
    pub fn to_json(&self, seconds: f64) -> serde_json::Value {
        serde_json::json!({
            "filter": self.filter,
            "params": self.params.to_json(),
            "score": self.score,
            "terms": self.terms,
            "evaluations": self.evaluations,
            "seconds": seconds,
        })
    }
}

/// Orders scores with NaN last, so a broken measurement never wins.
pub(crate) fn score_order(a: f64, b: f64) -> std::cmp::Ordering {
    match (a.is_nan(), b.is_nan()) {
        (false, false) => a.total_cmp(&b),
        (true, true) => std::cmp::Ordering::Equal,
        (true, false) => std::cmp::Ordering::Greater,
        (false, true) => std::cmp::Ordering::Less,
    }
}

#[cfg(test)]
pub(crate) mod synthetic;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_that_smooth_rank_first_then_the_least_rough_then_failures() {
        let smooths = |s: f64| Terms {
            curvature_ratio: s,
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.3,
        };
        let (good, worse) = (smooths(0.4), smooths(0.9));
        // A blown-up mesh whose score, had it been measured, would beat both.
        let (rough, rougher) = (Terms::roughened(1.5), Terms::roughened(80.0));
        let failed = failed_terms(1)[0];
        let ranks = [good, worse, rough, rougher, failed].map(|t| t.rank(1.0));
        for pair in ranks.windows(2) {
            assert!(pair[0] < pair[1], "{pair:?}");
        }
        assert!(
            !Terms::UNCHANGED.roughens(),
            "the unchanged mesh is as rough as itself"
        );
        assert!(Terms::roughened(1.0 + 1e-9).roughens());
        assert_eq!(smooths(0.4).rank(1.0), good.rank(1.0));
    }

    #[test]
    fn a_volume_limit_puts_the_sets_past_it_after_those_within_by_their_change() {
        let set = |k: f64, dv: f64| Terms {
            curvature_ratio: k,
            mean_error: 0.1,
            volume_change: Some(dv),
            roughness_ratio: 0.3,
        };
        let (strong, mild) = (set(0.1, -0.07), set(0.6, -0.02));
        assert!(
            strong.rank(0.5) < mild.rank(0.5),
            "without a limit S decides"
        );
        let goal = Goal {
            tau: 0.5,
            max_volume_change: Some(0.05),
        };
        let nearer = set(0.05, 0.06);
        let ranks = [mild, nearer, strong, Terms::roughened(1.5)].map(|t| t.rank(goal));
        for pair in ranks.windows(2) {
            assert!(pair[0] < pair[1], "{pair:?}");
        }
        // An open mesh has no volume to hold.
        let open = Terms {
            volume_change: None,
            ..strong
        };
        assert_eq!(open.rank(goal), open.rank(0.5));
    }

    #[test]
    fn score_follows_equation_four() {
        let t = Terms {
            curvature_ratio: 0.4,
            mean_error: 0.25,
            volume_change: Some(0.02),
            roughness_ratio: 0.5,
        };
        let accuracy = 0.5 * (0.25 / 1.25 + 0.02);
        assert!((t.accuracy() - accuracy).abs() < 1e-15);
        assert!((t.score(0.3) - (0.3 * 0.4 + 0.7 * accuracy)).abs() < 1e-15);
        assert_eq!(t.score(1.0), 0.4);
        let open = Terms {
            volume_change: None,
            ..t
        };
        assert!((open.accuracy() - 0.2).abs() < 1e-15);
        assert_eq!(Terms::UNCHANGED.score(0.0), 0.0);
        assert_eq!(Terms::UNCHANGED.score(0.7), 0.7);
    }

    #[test]
    fn nan_scores_rank_last() {
        use std::cmp::Ordering::*;
        assert_eq!(score_order(f64::NAN, 1e9), Greater);
        assert_eq!(score_order(0.1, f64::NAN), Less);
        assert_eq!(score_order(0.1, 0.2), Less);
    }

    #[test]
    fn search_names_round_trip() {
        for m in [SearchMethod::Grid, SearchMethod::Local] {
            assert_eq!(SearchMethod::from_name(m.name()), Some(m));
        }
        assert_eq!(SearchMethod::from_name("random"), None);
    }
}
