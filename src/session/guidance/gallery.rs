//! The gallery job: the suggested parameters for each of [`GALLERY_TAUS`] (local searches, or
//! an evaluated grid's answers), then the model smoothed and measured with each.

use super::{Engine, Running, SearchKey, GALLERY_TAUS};
use crate::metrics::VertexMeasures;
use crate::smooth::Params;
use crate::suggest::{LocalSearch, Task, Terms};
use crate::worker::{metrics_of, Reply, SmoothJob};

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
    /// The next pick's smoothing, asked of the CPU engine's workers.
    pub(super) smoothing: Option<SmoothJob>,
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
        let (task, mut ev) = running.evaluator(engine);
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
    // The pick's positions and per-vertex measures are wanted here: a run on the CPU engine.
    let asked = match job.smoothing {
        Some(asked) => asked,
        None => {
            let asked = engine.cpu.smooth(&engine.model, &params, tau, false);
            job.smoothing = Some(asked);
            asked
        }
    };
    let Some(reply) = engine.cpu.take_smoothed(asked) else {
        return false;
    };
    job.smoothing = None;
    let (positions, metrics, vertex) = match reply {
        Reply::Smoothed {
            positions,
            metrics,
            vertex,
            ..
        } => match metrics_of(&metrics) {
            Ok(m) => (positions, m, vertex),
            Err(why) => return gave_up(job, why),
        },
        Reply::Failed { why, .. } => return gave_up(job, why),
        _ => return gave_up(job, "another reply to a smoothing".into()),
    };
    job.picks.push(GalleryPick {
        tau,
        params,
        terms,
        volume_change: metrics.volume_change,
        positions,
        vertex,
    });
    job.picks.len() == n
}

/// Ends the gallery with what it has, saying why.
fn gave_up(job: &mut GalleryJob, why: String) -> bool {
    job.problem = Some(format!("No gallery: {why}"));
    true
}
