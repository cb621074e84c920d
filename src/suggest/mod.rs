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
mod patches;
mod points;
mod run_states;
mod space;
mod sweep;

pub use auto::{
    quality_graphs, quality_graphs_on, search_evaluator, suggest, suggest_for_goal, suggest_from,
    suggest_on, SuggestError, LOCAL_SEARCH_STATE_BYTES,
};
pub use bounded::GridMinimum;
pub use grid::{EvaluatedGrid, GridSearch};
pub use local::{LocalOutcome, LocalSearch};
pub use memo::{Memoized, TermsMemo};
pub use mesh_evaluator::{check_weights, MeshEvaluator, WeightsError};
pub use patches::{Patches, PATCHES_ABOVE};
pub use space::{Axis, GridPoint, Param, ParamSpace};
pub use sweep::{Curve, QualityGraphs, QualitySweep, Sample};

// The evaluator interface lives below this module and the GPU engine, in crate::evaluate;
// re-exported here, where the searches' callers have always found it.
pub use crate::evaluate::{
    failed_terms, is_cumulative, terms_of, unchanged_terms, Evaluator, Goal, ModelRef, Offload,
    Offloaded, Rank, Request, Terms,
};

// NaN-equal comparison for the searches' own results (`super::same`).
use crate::evaluate::same;
use crate::smooth::{Filter, Params};
use serde::{Deserialize, Serialize};

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

#[cfg(test)]
pub(crate) mod synthetic;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_names_round_trip() {
        for m in [SearchMethod::Grid, SearchMethod::Local] {
            assert_eq!(SearchMethod::from_name(m.name()), Some(m));
        }
        assert_eq!(SearchMethod::from_name("random"), None);
    }
}
