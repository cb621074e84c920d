//! The gallery job: the suggested parameters for each of [`GALLERY_TAUS`] (local searches, or
//! an evaluated grid's answers), then the model smoothed and measured with each.

use super::{Engine, Running, SearchKey, GALLERY_TAUS};
use crate::metrics::{self, VertexMeasures};
use crate::smooth::Params;
use crate::suggest::{LocalSearch, Sliced, Task, Terms};

/// The model smoothed as suggested for one tau, with its measures.
#[derive(Clone, Debug)]
pub struct GalleryPick {
    pub tau: f64,
    pub params: Params,
    pub terms: Terms,
    /// Signed `(V - V0) / V0` of the result (the terms hold its size); `None` for open meshes.
    pub volume_change: Option<f64>,
    pub positions: Vec<[f32; 3]>,
    pub vertex: VertexMeasures,
}

/// The gallery under way: the suggested parameters per tau first, then one smoothing per tau.
pub(super) struct GalleryJob {
    pub(super) key: SearchKey,
    /// Suggested parameters and terms, in [`GALLERY_TAUS`] order, as they are found.
    pub(super) suggested: Vec<(Params, Terms)>,
    pub(super) search: Option<Running<LocalSearch>>,
    pub(super) smoothing: Running<()>,
    pub(super) picks: Vec<GalleryPick>,
    pub(super) problem: Option<String>,
}

pub(super) fn with_bound(mut params: Params, bound: Option<f32>) -> Params {
    params.max_displacement = bound;
    params
}

/// One call's work on the gallery: the next tau's local search until every tau has
/// parameters, then the next smoothing. Returns whether the gallery is complete.
pub(super) fn step_gallery(job: &mut GalleryJob, engine: &mut Engine<'_, '_>) -> bool {
    let n = GALLERY_TAUS.len();
    if job.suggested.len() < n {
        let tau = GALLERY_TAUS[job.suggested.len()];
        let base = with_bound(Params::defaults(job.key.filter), job.key.bound);
        if job.search.is_none() {
            match LocalSearch::new(job.key.filter, &base, tau) {
                Ok(task) => job.search = Some(Running::new(task)),
                Err(e) => {
                    job.problem = Some(format!("No gallery: {e}"));
                    return true;
                }
            }
        }
        let Some(running) = job.search.as_mut() else {
            return true;
        };
        let Some((task, mut ev)) = running.evaluator(engine) else {
            return true;
        };
        if task.step(&mut ev) {
            if let Some(outcome) = job.search.take().and_then(|r| r.task.into_output()) {
                let s = outcome.suggestion;
                job.suggested
                    .push((with_bound(s.params, job.key.bound), s.terms));
            } else {
                return true;
            }
        }
        return false;
    }
    let Some(&(params, terms)) = job.suggested.get(job.picks.len()) else {
        return true;
    };
    let tau = GALLERY_TAUS[job.picks.len()];
    // The pick's positions and per-vertex measures are wanted here: a CPU run, sliced.
    let original = engine.model.original;
    let Ok(mut ev) = Sliced::new(
        original,
        engine.model.weights,
        &mut job.smoothing.runs,
        engine.clock,
        engine.budget_ms,
    ) else {
        return true;
    };
    let Some((positions, reference)) = ev.smoothed(&params) else {
        return false;
    };
    let (measured, vertex) = metrics::measure_vertices(original, &positions, &reference, tau);
    job.picks.push(GalleryPick {
        tau,
        params,
        terms,
        volume_change: measured.volume_change,
        positions,
        vertex,
    });
    job.picks.len() == n
}
