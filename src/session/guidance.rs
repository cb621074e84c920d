//! The work that guides the user, done in the background between frames: the quality graphs of
//! the active filter around its current parameters, the suggested parameters for a target
//! smoothness tau (grid or local search), and a gallery of the model smoothed as suggested at
//! several tau values.
//!
//! Every job runs on the CPU engine's workers or, when the caller lends one, on an [`Offload`]
//! (the GPU engine): a run goes out and its measures come back by a later call to
//! [`Session::step_guidance`], so the page never blocks. A job
//! belongs to the model, filter, weights and displacement bound it was started for: when one of
//! them changes it is dropped (the graphs also when any parameter changes) and its result no
//! longer shown as current.

use super::{Background, CaseDocument, Session};
use crate::smooth::{Filter, Params};
use crate::suggest::{
    EvaluatedGrid, GridSearch, LocalOutcome, LocalSearch, ModelRef, Offload, Progress,
    QualityGraphs, QualitySweep, SearchMethod, Suggestion, Task, TermsMemo,
};
use crate::worker::Pool;

/// The tau values of the gallery, from accuracy to smoothness.
pub const GALLERY_TAUS: [f64; 5] = [0.1, 0.3, 0.5, 0.7, 0.9];

/// What a search result depends on besides tau: the model, the weights, the filter and the
/// displacement bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchKey {
    model: u64,
    weights: u64,
    filter: Filter,
    bound: Option<f32>,
}

enum Search {
    Grid(GridSearch),
    Local(LocalSearch),
}

/// A suggestion search under way.
struct SearchJob {
    key: SearchKey,
    tau: f64,
    method: SearchMethod,
    running: Running<Search>,
}

/// A finished suggestion with what it was computed for.
#[derive(Clone, Debug)]
pub struct Suggested {
    pub suggestion: Suggestion,
    pub key: SearchKey,
    /// Wall time of the search (milliseconds), spread over frames.
    pub elapsed_ms: f64,
}

/// What the background is doing, for progress bars.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Activity {
    Graphs(Progress),
    Suggest {
        progress: Progress,
        tau: f64,
        method: SearchMethod,
    },
    Gallery {
        done: usize,
        total: usize,
    },
}

impl Activity {
    /// The fraction done, in [0, 1].
    pub fn fraction(&self) -> f32 {
        let (done, total) = match *self {
            Activity::Graphs(p) | Activity::Suggest { progress: p, .. } => (p.done, p.total),
            Activity::Gallery { done, total } => (done, total),
        };
        if total == 0 {
            0.0
        } else {
            (done as f32 / total as f32).min(1.0)
        }
    }

    pub fn describe(&self) -> String {
        match *self {
            Activity::Graphs(p) => format!("Quality graphs: {} of {} samples", p.done, p.total),
            Activity::Suggest {
                progress,
                tau,
                method,
            } => match method {
                // Short enough for the side panel. The local search ends long before it could
                // have measured the whole grid, so it counts without a total.
                SearchMethod::Local => {
                    format!("Local search, τ {tau:.2}: {} sets measured", progress.done)
                }
                SearchMethod::Grid => format!(
                    "Grid search, τ {tau:.2}: {} of {} sets",
                    progress.done, progress.total
                ),
            },
            Activity::Gallery { done, total } => format!("Gallery: {done} of {total} models"),
        }
    }
}

/// The background jobs and their latest results.
#[derive(Default)]
pub struct Guidance {
    /// The latest finished graphs (maybe for other parameters: see [`Session::graphs_current`]).
    graphs: Option<(SearchKey, QualityGraphs)>,
    /// How long the sweep of `graphs` took (ms of wall time, spread over frames).
    graphs_elapsed_ms: f64,
    sweep: Option<(SearchKey, Params, Running<QualitySweep>)>,
    /// Whether the graphs are kept up to date.
    pub graphs_wanted: bool,
    suggested: Option<Suggested>,
    /// The evaluated grid of the last grid search: a suggestion for any tau without smoothing.
    grid: Option<(SearchKey, EvaluatedGrid)>,
    search: Option<SearchJob>,
    gallery: Vec<GalleryPick>,
    gallery_key: Option<SearchKey>,
    /// Counts finished galleries, so views know when to redraw their thumbnails.
    gallery_version: u64,
    gallery_job: Option<GalleryJob>,
    /// Why the last job gave no result.
    pub problem: Option<String>,
    /// Terms every job measured, for the model, weights and engine of `memo_for`: searches at
    /// other tau values and the graphs reuse them.
    memo: TermsMemo,
    memo_for: Option<(u64, u64, bool)>,
}

impl CaseDocument {
    pub(super) fn search_key(&self) -> SearchKey {
        SearchKey {
            model: self.model_id,
            weights: self.weights_version,
            filter: self.filter(),
            bound: self.params().max_displacement,
        }
    }
}

impl<'a> Background<'a> {
    /// How long the sweep of [`Self::graphs`] took, in seconds of wall time spread over frames.
    pub fn graphs_seconds(&self) -> f64 {
        self.guidance.graphs_elapsed_ms / 1000.0
    }

    /// The latest finished quality graphs of the active filter (maybe for other parameters
    /// than the current ones while new ones are computed), rescored at the current tau.
    pub fn graphs(&self) -> Option<QualityGraphs> {
        let (key, graphs) = self.guidance.graphs.as_ref()?;
        (key.model == self.doc.model_id && key.filter == self.doc.filter())
            .then(|| graphs.clone().rescored(self.doc.tau()))
    }

    /// Whether [`Self::graphs`] are for exactly the current parameters, weights and model.
    pub fn graphs_current(&self) -> bool {
        self.guidance.graphs.as_ref().is_some_and(|(key, g)| {
            *key == self.doc.search_key() && g.current == *self.doc.params()
        })
    }

    /// The last suggestion, if it is for the current model, filter, weights and bound; from
    /// an evaluated grid it follows tau.
    pub fn suggestion(&self) -> Option<Suggested> {
        let key = self.doc.search_key();
        if let Some((k, grid)) = &self.guidance.grid {
            if *k == key {
                if let (Some(mut s), Some(last)) =
                    (grid.best(self.doc.tau()), &self.guidance.suggested)
                {
                    s.params.max_displacement = key.bound;
                    return Some(Suggested {
                        suggestion: s,
                        key,
                        elapsed_ms: last.elapsed_ms,
                    });
                }
            }
        }
        // A local search answers for its own tau only; the caller shows which.
        self.guidance.suggested.clone().filter(|s| s.key == key)
    }

    /// Why the last background job gave no result.
    pub fn guidance_problem(&self) -> Option<&'a str> {
        self.guidance.problem.as_deref()
    }

    /// Whether a suggestion search is under way.
    pub fn suggesting(&self) -> bool {
        self.guidance.search.is_some()
    }

    /// Changes when a gallery is finished.
    pub fn gallery_version(&self) -> u64 {
        self.guidance.gallery_version
    }

    /// Whether a gallery is being made.
    pub fn making_gallery(&self) -> bool {
        self.guidance.gallery_job.is_some()
    }

    /// The last finished gallery, if it is for the current model, filter, weights and bound.
    pub fn gallery(&self) -> &'a [GalleryPick] {
        if self.guidance.gallery_key == Some(self.doc.search_key()) {
            &self.guidance.gallery
        } else {
            &[]
        }
    }

    /// What the background is working on.
    pub fn activities(&self) -> Vec<Activity> {
        let mut out = Vec::new();
        if let Some(job) = &self.guidance.search {
            let progress = match &job.running.task {
                Search::Grid(t) => t.progress(),
                Search::Local(t) => t.progress(),
            };
            out.push(Activity::Suggest {
                progress,
                tau: job.tau,
                method: job.method,
            });
        }
        if let Some(job) = &self.guidance.gallery_job {
            out.push(Activity::Gallery {
                done: job.picks.len(),
                total: GALLERY_TAUS.len(),
            });
        }
        if let Some((_, _, running)) = &self.guidance.sweep {
            out.push(Activity::Graphs(running.task.progress()));
        }
        out
    }

    /// Whether any background job is under way or due.
    pub fn guidance_busy(&self) -> bool {
        self.guidance.search.is_some()
            || self.guidance.gallery_job.is_some()
            || self.guidance.sweep.is_some()
            || self.graphs_due()
    }

    fn graphs_due(&self) -> bool {
        self.guidance.graphs_wanted && self.doc.model().is_some() && !self.graphs_current()
    }
}

impl Session {
    /// Drops jobs and results of another model.
    pub(super) fn reset_guidance(&mut self) {
        let wanted = self.guidance.graphs_wanted;
        self.guidance = Guidance {
            graphs_wanted: wanted,
            ..Guidance::default()
        };
    }

    /// Starts a suggestion search for the active filter at the current tau (replacing one
    /// under way). A grid already evaluated for this model, filter, weights and bound answers
    /// at once.
    pub fn start_suggest(&mut self, method: SearchMethod) {
        self.guidance.search = None;
        if self.doc.model().is_some() {
            self.queue_suggest(method);
        }
    }

    /// Sets up a search for the current key (the model may be about to be set).
    pub(super) fn queue_suggest(&mut self, method: SearchMethod) {
        let key = self.doc.search_key();
        let base = *self.doc.params();
        let search = match method {
            SearchMethod::Grid => GridSearch::new(base.filter, &base).map(Search::Grid),
            SearchMethod::Local => {
                LocalSearch::new(base.filter, &base, self.doc.tau()).map(Search::Local)
            }
        };
        match search {
            Ok(task) => {
                self.guidance.search = Some(SearchJob {
                    key,
                    tau: self.doc.tau(),
                    method,
                    running: Running::new(task),
                })
            }
            Err(e) => self.guidance.problem = Some(format!("No suggestion: {e}")),
        }
    }

    /// Keeps the quality graphs of the active filter up to date in the background (or stops).
    pub fn set_graphs_wanted(&mut self, wanted: bool) {
        self.guidance.graphs_wanted = wanted;
        if !wanted {
            self.guidance.sweep = None;
        }
    }

    /// Stops the suggestion search under way.
    pub fn cancel_suggest(&mut self) {
        self.guidance.search = None;
    }

    /// Starts the gallery of [`GALLERY_TAUS`] for the active filter.
    pub fn start_gallery(&mut self) {
        if self.doc.model().is_none() {
            self.guidance.gallery_job = None;
            return;
        }
        let key = self.doc.search_key();
        // With an evaluated grid the suggestions are known already.
        let suggested = match &self.guidance.grid {
            Some((k, grid)) if *k == key => GALLERY_TAUS
                .iter()
                .filter_map(|&tau| grid.best(tau))
                .map(|s| (with_bound(s.params, key.bound), s.terms))
                .collect(),
            _ => Vec::new(),
        };
        self.guidance.gallery_job = Some(GalleryJob {
            key,
            suggested,
            search: None,
            smoothing: None,
            picks: Vec::new(),
            problem: None,
        });
    }

    pub fn cancel_gallery(&mut self) {
        self.guidance.gallery_job = None;
    }

    /// The engine the background ran on failed (`why`): the jobs under way start again (on the
    /// CPU engine, which the caller turns to) and the problem is shown.
    pub fn guidance_engine_failed(&mut self, why: &str) {
        let search = self.guidance.search.take().map(|j| j.method);
        let gallery = self.guidance.gallery_job.take().is_some();
        self.guidance.sweep = None;
        self.guidance.graphs = None;
        if let Some(method) = search {
            self.start_suggest(method);
        }
        if gallery {
            self.start_gallery();
        }
        self.guidance.problem = Some(format!(
            "The GPU engine failed ({why}); guidance goes on on the CPU"
        ));
    }

    /// Works on the background jobs on the CPU engine's workers: the suggestion first (the
    /// user asked and waits), then the gallery, then the graphs. Returns whether a job finished.
    pub fn step_guidance(&mut self, clock: &dyn Fn() -> f64) -> bool {
        self.step_guidance_on(clock, None)
    }

    /// [`Self::step_guidance`] with the smoothing runs of the searches and graphs on `offload`
    /// when given (the GPU engine). It returns as soon as a job waits for a run, and a later
    /// call collects it. The gallery's final smoothings stay on the CPU engine.
    pub fn step_guidance_on(
        &mut self,
        clock: &dyn Fn() -> f64,
        mut offload: Option<&mut dyn Offload>,
    ) -> bool {
        let mut cpu = std::mem::take(&mut self.cpu);
        let mut finished = false;
        // A task step asks for at most one run; what the engines already answered goes on
        // (a bound on the steps keeps a job that never waits from holding the frame).
        for _ in 0..10_000 {
            cpu.clear_waiting();
            // Reborrowed for this call only (a `dyn` object's lifetime shortens here, not
            // inside an Option).
            let lent = offload.as_mut().map(|o| &mut **o as &mut dyn Offload);
            finished |= self.step_guidance_once(clock, &mut cpu, lent);
            let waiting = cpu.waiting() || offload.as_deref().is_some_and(|o| o.waiting());
            if waiting || !self.background().guidance_busy() {
                break;
            }
        }
        if !self.background().guidance_busy() || offload.is_some() {
            cpu.clear_guidance();
        }
        self.cpu = cpu;
        finished
    }

    /// One task step, with the memo of measured terms for this model, weights and engine.
    fn step_guidance_once(
        &mut self,
        clock: &dyn Fn() -> f64,
        cpu: &mut Pool,
        offload: Option<&mut dyn Offload>,
    ) -> bool {
        let memo_for = Some((
            self.doc.model_id,
            self.doc.weights_version,
            offload.is_some(),
        ));
        if self.guidance.memo_for != memo_for {
            self.guidance.memo = TermsMemo::default();
            self.guidance.memo_for = memo_for;
        }
        let mut memo = std::mem::take(&mut self.guidance.memo);
        let finished = self.step_job(clock, cpu, offload, &mut memo);
        self.guidance.memo = memo;
        finished
    }

    /// One task step of the job due.
    fn step_job(
        &mut self,
        clock: &dyn Fn() -> f64,
        cpu: &mut Pool,
        offload: Option<&mut dyn Offload>,
        memo: &mut TermsMemo,
    ) -> bool {
        let key = self.doc.search_key();
        let (params, tau) = (*self.doc.params(), self.doc.tau());
        self.guidance.drop_stale(key, &params);
        // Field by field: the guidance below is borrowed to change.
        let Some(model) = self.doc.models.get(self.doc.current) else {
            return false;
        };
        let structure = self.doc.case.structures.get(self.doc.current);
        let mut engine = Engine {
            model: ModelRef {
                original: &model.original,
                id: self.doc.model_id,
                weights: structure.and_then(|s| s.weights.as_deref()),
                weights_version: self.doc.weights_version,
            },
            clock,
            cpu,
            offload,
            memo,
        };
        let guidance = &mut self.guidance;
        if guidance.search.is_some() {
            guidance.step_search(key, &mut engine)
        } else if guidance.gallery_job.is_some() {
            guidance.step_gallery(&mut engine)
        } else {
            guidance.step_graphs(key, &params, tau, &mut engine)
        }
    }
}

impl Guidance {
    /// Drops the jobs for another model, filter, weights or bound (the graphs': or other
    /// parameters).
    fn drop_stale(&mut self, key: SearchKey, params: &Params) {
        if self.search.as_ref().is_some_and(|j| j.key != key) {
            self.search = None;
        }
        if self.gallery_job.as_ref().is_some_and(|j| j.key != key) {
            self.gallery_job = None;
        }
        if (self.sweep.as_ref()).is_some_and(|(k, p, _)| *k != key || p != params) {
            self.sweep = None;
        }
    }

    /// A step of the suggestion's search; once it finishes, the suggestion (and a grid's
    /// answers) are kept. Whether it finished.
    fn step_search(&mut self, key: SearchKey, engine: &mut Engine<'_, '_>) -> bool {
        let Some(job) = self.search.as_mut() else {
            return false;
        };
        let (task, mut ev) = job.running.evaluator(engine);
        let finished = match task {
            Search::Grid(t) => t.step(&mut ev),
            Search::Local(t) => t.step(&mut ev),
        };
        if !finished {
            return false;
        }
        let Some(job) = self.search.take() else {
            return false;
        };
        let elapsed_ms = (engine.clock)() - job.running.started_ms.unwrap_or_default();
        let suggestion = match job.running.task {
            Search::Grid(t) => t.into_output().and_then(|grid| {
                let best = grid.best(job.tau);
                self.grid = Some((key, grid));
                best
            }),
            Search::Local(t) => t.into_output().map(|o: LocalOutcome| o.suggestion),
        };
        if let Some(mut suggestion) = suggestion {
            suggestion.params.max_displacement = key.bound;
            self.suggested = Some(Suggested {
                suggestion,
                key,
                elapsed_ms,
            });
        }
        true
    }

    /// A step of the gallery's job; once it finishes, its pictures are kept.
    fn step_gallery(&mut self, engine: &mut Engine<'_, '_>) -> bool {
        let Some(job) = self.gallery_job.as_mut() else {
            return false;
        };
        let finished = step_gallery(job, engine);
        if finished {
            if let Some(job) = self.gallery_job.take() {
                self.problem = job.problem;
                self.gallery = job.picks;
                self.gallery_key = Some(job.key);
                self.gallery_version += 1;
            }
        }
        finished
    }

    /// A step of the quality graphs around `params`, while they are wanted and not current.
    fn step_graphs(
        &mut self,
        key: SearchKey,
        params: &Params,
        tau: f64,
        engine: &mut Engine<'_, '_>,
    ) -> bool {
        if !self.graphs_wanted {
            self.sweep = None;
            return false;
        }
        let current =
            (self.graphs.as_ref()).is_some_and(|(k, g)| *k == key && g.current == *params);
        if current {
            return false;
        }
        if self.sweep.is_none() {
            match QualitySweep::new(params, tau) {
                Ok(task) => self.sweep = Some((key, *params, Running::new(task))),
                Err(e) => {
                    self.problem = Some(format!("No quality graphs: {e}"));
                    return false;
                }
            }
        }
        let Some((_, _, running)) = self.sweep.as_mut() else {
            return false;
        };
        let (task, mut ev) = running.evaluator(engine);
        if !task.step(&mut ev) {
            return false;
        }
        if let Some((key, _, running)) = self.sweep.take() {
            self.graphs_elapsed_ms = (engine.clock)() - running.started_ms.unwrap_or_default();
            if let Some(graphs) = running.task.into_output() {
                self.graphs = Some((key, graphs));
            }
        }
        true
    }
}

mod engine;
mod gallery;
#[cfg(test)]
mod tests;

use engine::{Engine, Running};
pub use gallery::GalleryPick;
use gallery::{step_gallery, with_bound, GalleryJob};
