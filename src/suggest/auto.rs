//! Entry points on a real mesh: quality graphs, whole-filter suggestions, and the suggested
//! parameters for `smooth --auto`.

use super::mesh_evaluator::{MeshEvaluator, WeightsError};
use super::space::GRID_ITERATION_STEP;
use super::{
    run, Cancelled, Evaluator, Goal, GridMinimum, LocalSearch, Progress, QualityGraphs,
    QualitySweep, SearchMethod, Suggestion,
};
use crate::metrics::Original;
use crate::smooth::{Filter, ParamError, Params};

/// Why a sweep or suggestion could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SuggestError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error(transparent)]
    Weights(#[from] WeightsError),
    #[error("tau = {0} is out of range: [0, 1]")]
    Tau(f64),
    #[error("the volume change limit {0} is not a fraction >= 0")]
    VolumeLimit(f64),
    #[error("cancelled")]
    Cancelled,
    #[error("the mesh has no vertices")]
    Empty,
}

impl From<Cancelled> for SuggestError {
    fn from(_: Cancelled) -> Self {
        SuggestError::Cancelled
    }
}

fn check_tau(tau: f64) -> Result<(), SuggestError> {
    if (0.0..=1.0).contains(&tau) {
        Ok(())
    } else {
        Err(SuggestError::Tau(tau))
    }
}

/// The quality graphs of `current.filter` around `current`, on the CPU engine.
pub fn quality_graphs(
    original: &Original,
    weights: Option<&[f32]>,
    current: &Params,
    tau: f64,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<QualityGraphs, SuggestError> {
    let mut evaluator = MeshEvaluator::new(original, weights)?;
    quality_graphs_on(&mut evaluator, current, tau, on_progress)
}

/// [`quality_graphs`] on any evaluator (the GPU's, say).
pub fn quality_graphs_on(
    evaluator: &mut dyn Evaluator,
    current: &Params,
    tau: f64,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<QualityGraphs, SuggestError> {
    check_tau(tau)?;
    let task = QualitySweep::new(current, tau)?;
    Ok(run(task, evaluator, on_progress)?)
}

/// The suggested parameters for `base.filter` at target smoothness `tau`, on the CPU engine.
/// `base` carries the displacement bound; `weights` (one per vertex) are passed to every run.
pub fn suggest(
    original: &Original,
    weights: Option<&[f32]>,
    base: &Params,
    tau: f64,
    method: SearchMethod,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Suggestion, SuggestError> {
    if original.mesh().vertex_count() == 0 {
        return Err(SuggestError::Empty);
    }
    let mut evaluator = search_evaluator(original, weights, base.filter, method)?;
    suggest_on(&mut evaluator, base, tau, method, on_progress)
}

/// Bytes of run states the CPU engine keeps for HC's local search (a sixteenth of that per
/// vertex and state: about 80 states of the 206k-vertex brain).
pub const LOCAL_SEARCH_STATE_BYTES: usize = 256 << 20;

/// The CPU engine's evaluator for a search of `filter`'s parameters by `method`. HC's local
/// search comes back to the same weights at other iteration counts, so its runs keep their
/// states ([`MeshEvaluator::keeping_states`]): on the 206k-vertex brain, 3010 iterations
/// smoothed become 2390 and the search takes about a tenth less time. Taubin's search saves
/// iterations too, but fewer than the copies of the states cost (a few percent slower,
/// measured), and the grid never comes back.
pub fn search_evaluator<'a>(
    original: &'a Original,
    weights: Option<&'a [f32]>,
    filter: Filter,
    method: SearchMethod,
) -> Result<MeshEvaluator<'a>, WeightsError> {
    let evaluator = MeshEvaluator::new(original, weights)?;
    Ok(match (filter, method) {
        (Filter::Hc, SearchMethod::Local) => {
            evaluator.keeping_states(LOCAL_SEARCH_STATE_BYTES, GRID_ITERATION_STEP)
        }
        _ => evaluator,
    })
}

/// [`suggest`] on any evaluator (the GPU's, say) of a mesh with vertices.
pub fn suggest_on(
    evaluator: &mut dyn Evaluator,
    base: &Params,
    tau: f64,
    method: SearchMethod,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Suggestion, SuggestError> {
    suggest_for_goal(evaluator, base, tau.into(), method, on_progress)
}

/// [`suggest_on`] for a [`Goal`] that may also limit the volume change.
pub fn suggest_for_goal(
    evaluator: &mut dyn Evaluator,
    base: &Params,
    goal: Goal,
    method: SearchMethod,
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Suggestion, SuggestError> {
    check_tau(goal.tau)?;
    if let Some(limit) = goal.max_volume_change.filter(|l| l.is_nan() || *l < 0.0) {
        return Err(SuggestError::VolumeLimit(limit));
    }
    let (tau, limit) = (goal.tau, goal.max_volume_change);
    let suggestion = match method {
        SearchMethod::Grid => {
            let task = GridMinimum::new(base.filter, base, tau)?.limiting_volume(limit);
            Some(run(task, evaluator, on_progress)?)
        }
        SearchMethod::Local => {
            let task = LocalSearch::new(base.filter, base, tau)?.limiting_volume(limit);
            Some(run(task, evaluator, on_progress)?.suggestion)
        }
    };
    suggestion.ok_or(SuggestError::Empty)
}

/// [`suggest_for_goal`]'s local search started at `starts` (see [`LocalSearch::starting_at`];
/// the corners where no start fits), stepping along the axes first
/// ([`LocalSearch::axes_first`]): it stops at a local minimum as the paper's search does, for
/// about two thirds of the parameter sets on the JHU atlas and the phantom.
pub fn suggest_from(
    evaluator: &mut dyn Evaluator,
    base: &Params,
    goal: Goal,
    starts: &[Params],
    on_progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Suggestion, SuggestError> {
    check_tau(goal.tau)?;
    if let Some(limit) = goal.max_volume_change.filter(|l| l.is_nan() || *l < 0.0) {
        return Err(SuggestError::VolumeLimit(limit));
    }
    let task = LocalSearch::new(base.filter, base, goal.tau)?
        .limiting_volume(goal.max_volume_change)
        .starting_at(starts)
        .axes_first();
    Ok(run(task, evaluator, on_progress)?.suggestion)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_hcs_local_search_resumes_runs_from_kept_states() {
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "tube.ply").expect("the sample");
        let topology = crate::mesh::Topology::build(&mesh);
        let original = Original::new(&mesh, &topology);
        for filter in [Filter::Hc, Filter::Taubin, Filter::Laplace] {
            for method in [SearchMethod::Local, SearchMethod::Grid] {
                let mut ev = search_evaluator(&original, None, filter, method).expect("no weights");
                let p = Params::defaults(filter);
                ev.measure(&p, &[20]).expect("measured");
                ev.measure(&p, &[15]).expect("measured");
                // 15 resumes from the state kept at 10.
                let resumed = filter == Filter::Hc && method == SearchMethod::Local;
                let expected = if resumed { 20 + 5 } else { 20 + 15 };
                assert_eq!(ev.iterations, expected, "{filter} {method:?}");
            }
        }
    }
}
