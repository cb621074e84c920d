//! "Suggest all": the suggestion for every structure of a case at one target smoothness, each
//! structure then smoothed with it. This file is its one description: which structures, in
//! what order and batches, what each search starts from, and what a structure's part does.
//! The runners only carry it out: [`suggest_all`] on rayon's threads (the CLI, the tests), the
//! page's session on its worker pool, a [`SuggestAllPlan::next_job`] handed to each free worker.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use super::pipeline::measured;
use super::{Case, CaseStructure};
use crate::mesh::Topology;
use crate::metrics::Original;
use crate::smooth::{Filter, Params};
use crate::suggest::{
    search_evaluator, suggest_for_goal, suggest_from, Evaluator, Goal, Patches, SearchMethod,
    SuggestError, Suggestion,
};

/// How "Suggest all" searches each structure's parameters.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum SuggestAllSearch {
    /// Every grid point of each structure.
    Grid,
    /// The paper's local search, from the corners, for each structure.
    Local,
    /// The local search from where the searches of smaller structures ended: the default.
    #[default]
    Learned,
}

impl SuggestAllSearch {
    pub const ALL: [SuggestAllSearch; 3] = [Self::Grid, Self::Local, Self::Learned];

    pub fn name(self) -> &'static str {
        match self {
            Self::Grid => "grid",
            Self::Local => "local",
            Self::Learned => "learned",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The search each structure runs.
    pub fn method(self) -> SearchMethod {
        match self {
            Self::Grid => SearchMethod::Grid,
            Self::Local | Self::Learned => SearchMethod::Local,
        }
    }

    /// Whether structures start where those searched before them ended.
    pub fn learns(self) -> bool {
        self == Self::Learned
    }
}

impl std::fmt::Display for SuggestAllSearch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The most volume a structure's suggestion may change by, unless told: thin structures
/// (vessels) lose volume faster than the score weighs it.
pub const DEFAULT_MAX_VOLUME_CHANGE: f64 = 0.05;

/// What "Suggest all" does.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SuggestAllOptions {
    pub tau: f64,
    /// Every structure's filter becomes this one first; `None` keeps each structure's own.
    pub filter: Option<Filter>,
    pub search: SuggestAllSearch,
    /// Each structure's suggestion changes its volume by at most this fraction, when given.
    pub max_volume_change: Option<f64>,
}

impl SuggestAllOptions {
    /// At `tau` with `search`, each structure's own filter, the default volume bound.
    pub fn new(tau: f64, search: SuggestAllSearch) -> Self {
        Self {
            tau,
            filter: None,
            search,
            max_volume_change: Some(DEFAULT_MAX_VOLUME_CHANGE),
        }
    }
}

/// How many structures, smallest first, search at once when they learn from each other.
pub const LEARNING_BATCH: usize = 4;

/// How many of the batches just before its own a batch neither waits for nor learns from: while
/// the last structures of one batch run, the next batch's already can, so no thread waits at
/// the end of each batch (the large structures, last, take longest).
pub const LEARNING_LAG: usize = 1;

/// One structure's part, ready to run: its index in the case and where its search starts
/// (empty: the corners).
#[derive(Clone, Debug, PartialEq)]
pub struct SuggestJob {
    pub structure: usize,
    pub starts: Vec<Params>,
}

/// The order, the batches and the learned starts of one "Suggest all", as its structures are
/// handed out and finish. Learning, a batch is handed out only once the batches before the
/// [`LEARNING_LAG`] just before it have finished, and its starts come from their suggestions in
/// the plan's order: the same starts on one thread, several, or a pool of workers finishing in
/// any order.
#[derive(Clone, Debug)]
pub struct SuggestAllPlan {
    options: SuggestAllOptions,
    /// Structure indices in the plan's order: learning, the smallest first.
    order: Vec<usize>,
    /// How many structures have been handed out ([`Self::position`] gives which).
    handed_out: usize,
    /// Per position in `order`: finished, with its suggestion's parameters if it got one.
    finished: Vec<Option<Option<Params>>>,
    cancelled: bool,
}

impl SuggestAllPlan {
    /// The plan for the structures `which` of `case` (indices; `None`: every one).
    pub fn new(case: &Case, which: Option<&[usize]>, options: SuggestAllOptions) -> Self {
        let mut order: Vec<usize> = match which {
            Some(w) => w.to_vec(),
            None => (0..case.structures.len()).collect(),
        };
        order.sort_unstable();
        order.dedup();
        let vertices = |i: usize| {
            case.structures
                .get(i)
                .map_or(0, |s| s.original.vertex_count())
        };
        // Learning, the smallest first, so the large ones start where the small ones ended;
        // else the largest first, so no thread is left with one big structure at the end.
        order.sort_by_key(|&i| vertices(i));
        if !options.search.learns() {
            order.reverse();
        }
        Self {
            options,
            finished: vec![None; order.len()],
            order,
            handed_out: 0,
            cancelled: false,
        }
    }

    pub fn options(&self) -> &SuggestAllOptions {
        &self.options
    }

    /// The structures in the plan's order.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// The position in [`Self::order`] of the `k`-th structure handed out; as the order only
    /// turns within a batch, also the reverse. Learning, a batch goes out its largest first:
    /// its starts come from the batches before it whatever the order within it, and a large
    /// structure started last would leave the other threads idle at the batch's end.
    fn position(&self, k: usize) -> usize {
        if !self.options.search.learns() {
            return k;
        }
        let batch_start = k - k % LEARNING_BATCH;
        let batch_len = LEARNING_BATCH.min(self.order.len() - batch_start);
        batch_start + (batch_len - 1 - (k - batch_start))
    }

    /// Whether the structure at `position` in [`Self::order`] has been handed out.
    fn handed(&self, position: usize) -> bool {
        self.position(position) < self.handed_out
    }

    /// The next structure's part if it may start now: `None` when all are handed out, or
    /// learning, while the batch before it runs. `case` gives each structure's filter.
    pub fn next_job(&mut self, case: &Case) -> Option<SuggestJob> {
        if self.handed_out >= self.order.len() {
            return None;
        }
        let position = self.position(self.handed_out);
        let structure = self.order[position];
        if self.cancelled {
            return None;
        }
        let learning = self.options.search.learns();
        let batch_start = position - position % LEARNING_BATCH;
        let learned_to = batch_start.saturating_sub(LEARNING_BATCH * LEARNING_LAG);
        if learning && self.finished[..learned_to].iter().any(Option::is_none) {
            return None;
        }
        let starts = match (learning, case.structures.get(structure)) {
            (true, Some(s)) => {
                let learned: Vec<Params> = (self.finished[..learned_to].iter())
                    .filter_map(|f| f.flatten())
                    .collect();
                starts_from(&learned, self.options.filter.unwrap_or(s.params.filter))
            }
            _ => Vec::new(),
        };
        self.handed_out += 1;
        Some(SuggestJob { structure, starts })
    }

    /// Structure `structure` finished, with its suggestion's parameters (`None`: none, as when
    /// it failed or had nothing to smooth).
    pub fn finish(&mut self, structure: usize, suggested: Option<Params>) {
        let position = self.order.iter().position(|&i| i == structure);
        if let Some(p) = position.filter(|&p| self.handed(p)) {
            self.finished[p] = Some(suggested);
        }
    }

    /// Hands nothing more out; parts already handed out still finish.
    pub fn cancel(&mut self) {
        self.cancelled = true;
    }

    pub fn cancelled(&self) -> bool {
        self.cancelled
    }

    /// Handed out and not finished.
    pub fn running(&self) -> usize {
        // Only structures handed out finish.
        self.handed_out - self.done()
    }

    /// Structures finished.
    pub fn done(&self) -> usize {
        self.finished.iter().filter(|f| f.is_some()).count()
    }

    /// Structures in the plan.
    pub fn total(&self) -> usize {
        self.order.len()
    }

    /// Whether nothing runs and nothing more will be handed out.
    pub fn is_over(&self) -> bool {
        self.running() == 0 && (self.cancelled || self.handed_out == self.order.len())
    }
}

/// Where a structure's search starts, from the suggestions of the structures finished before
/// it: the three `filter`'s searches ended at most often. None (the corners) before any.
pub fn starts_from(learned: &[Params], filter: Filter) -> Vec<Params> {
    let mut counted: Vec<(Params, usize)> = Vec::new();
    for p in learned.iter().filter(|p| p.filter == filter) {
        match counted.iter_mut().find(|(q, _)| same_point(q, p)) {
            Some((_, n)) => *n += 1,
            None => counted.push((*p, 1)),
        }
    }
    // The most frequent first; among equals the latest (`learned` is in order of size: the
    // nearest in size).
    counted.reverse();
    counted.sort_by_key(|&(_, n)| std::cmp::Reverse(n));
    counted.into_iter().take(3).map(|(p, _)| p).collect()
}

/// The same grid point: every parameter equal but the bound, which each structure keeps.
fn same_point(a: &Params, b: &Params) -> bool {
    let unbound = |p: &Params| Params {
        max_displacement: None,
        ..*p
    };
    unbound(a) == unbound(b)
}

/// How far "Suggest all" has come: structures finished, of all, and parameter sets measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SuggestAllProgress {
    pub structures_done: usize,
    pub structures: usize,
    pub evaluations: usize,
}

/// Runs the plan of every structure of `case` on rayon's threads: each structure's suggestion at
/// `options.tau` with its own filter and bound, then smoothed with it. Structures run in
/// parallel (most are small, and one structure's passes use few threads), each handed out as
/// soon as the plan lets it start. `on_progress` returns `false` to cancel: structures already
/// finished keep their new parameters, the others are left as they were. Returns each
/// structure's suggestion, in order; a structure with nothing to smooth (no vertices) gets
/// `None` and is left alone.
pub fn suggest_all(
    case: &mut Case,
    options: &SuggestAllOptions,
    on_progress: &(dyn Fn(SuggestAllProgress) -> bool + Sync),
) -> Result<Vec<Option<Suggestion>>, SuggestError> {
    let total = case.structures.len();
    let plan = SuggestAllPlan::new(case, None, *options);
    let runner = Runner {
        options,
        on_progress,
        total,
        cancelled: AtomicBool::new(false),
        done: AtomicUsize::new(0),
        evaluations: AtomicUsize::new(0),
        report: Mutex::new(()),
        shared: Mutex::new(Shared {
            case,
            plan,
            suggestions: vec![None; total],
            first_error: None,
        }),
    };
    rayon::scope(|scope| runner.hand_out(scope));
    let shared = runner
        .shared
        .into_inner()
        .unwrap_or_else(|e| e.into_inner());
    match shared.first_error {
        Some(e) => Err(e),
        None => Ok(shared.suggestions),
    }
}

/// What the threads of [`suggest_all`] share.
struct Runner<'a> {
    options: &'a SuggestAllOptions,
    on_progress: &'a (dyn Fn(SuggestAllProgress) -> bool + Sync),
    total: usize,
    cancelled: AtomicBool,
    done: AtomicUsize,
    evaluations: AtomicUsize,
    /// Progress is told one report at a time.
    report: Mutex<()>,
    shared: Mutex<Shared<'a>>,
}

/// The case, the plan and what came of the structures so far.
struct Shared<'a> {
    case: &'a mut Case,
    plan: SuggestAllPlan,
    suggestions: Vec<Option<Suggestion>>,
    first_error: Option<SuggestError>,
}

impl<'a> Runner<'a> {
    fn shared(&self) -> std::sync::MutexGuard<'_, Shared<'a>> {
        self.shared.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Starts every structure the plan lets start now; each, as it finishes, hands out again.
    fn hand_out<'s>(&'s self, scope: &rayon::Scope<'s>) {
        let mut shared = self.shared();
        if self.cancelled.load(Ordering::Relaxed) {
            shared.plan.cancel();
        }
        let Shared { case, plan, .. } = &mut *shared;
        while let Some(job) = plan.next_job(case) {
            scope.spawn(move |scope| {
                self.run(job);
                self.hand_out(scope);
            });
        }
    }

    /// One structure's part on a copy of it, put back in the case when it finishes: a case of
    /// millions of vertices is never held twice.
    fn run(&self, job: SuggestJob) {
        let i = job.structure;
        // Copied only when it will be searched: a job handed out after a cancel finishes at once.
        let outcome = match self.cancelled.load(Ordering::Relaxed) {
            true => Ok(None),
            false => {
                let mut s = self.shared().case.structures[i].clone();
                let found = suggest_structure(&mut s, self.options, &job.starts, &mut |_| {
                    self.evaluations.fetch_add(1, Ordering::Relaxed);
                    self.tell(false)
                });
                found.map(|f| f.map(|suggestion| (suggestion, s)))
            }
        };
        if matches!(outcome, Ok(Some(_))) {
            self.tell(true);
        }
        let mut shared = self.shared();
        match outcome {
            Ok(Some((suggestion, s))) => {
                shared.plan.finish(i, Some(suggestion.params));
                shared.case.structures[i] = s;
                shared.suggestions[i] = Some(suggestion);
            }
            Ok(None) | Err(SuggestError::Cancelled) => shared.plan.finish(i, None),
            Err(e) => {
                shared.plan.finish(i, None);
                shared.first_error.get_or_insert(e);
            }
        }
    }

    /// Reports progress; `false` once cancelled.
    fn tell(&self, finished: bool) -> bool {
        let _one_at_a_time = self.report.lock();
        if finished {
            self.done.fetch_add(1, Ordering::Relaxed);
        }
        let p = SuggestAllProgress {
            structures_done: self.done.load(Ordering::Relaxed),
            structures: self.total,
            evaluations: self.evaluations.load(Ordering::Relaxed),
        };
        if !(self.on_progress)(p) {
            self.cancelled.store(true, Ordering::Relaxed);
        }
        !self.cancelled.load(Ordering::Relaxed)
    }
}

/// One structure's part: its suggestion (with `options.filter` first, when given), applied and
/// smoothed; `None` when it has no vertices. `starts`, when not empty, are where its local
/// search starts ([`SuggestAllPlan::next_job`]).
pub fn suggest_structure(
    s: &mut CaseStructure,
    options: &SuggestAllOptions,
    starts: &[Params],
    on_progress: &mut dyn FnMut(crate::suggest::Progress) -> bool,
) -> Result<Option<Suggestion>, SuggestError> {
    if s.original.vertex_count() == 0 {
        return Ok(None);
    }
    if let Some(filter) = options.filter {
        s.set_filter(filter);
    }
    let topology = Topology::build(&s.original);
    let original = Original::new(&s.original, &topology);
    let weights = s.weights.as_deref();
    let goal = Goal {
        tau: options.tau,
        max_volume_change: options.max_volume_change,
    };
    let (filter, method) = (s.params.filter, options.search.method());
    let mut search = |evaluator: &mut dyn Evaluator, starts: &[Params]| match method {
        SearchMethod::Local if !starts.is_empty() => {
            suggest_from(evaluator, &s.params, goal, starts, on_progress)
        }
        method => suggest_for_goal(evaluator, &s.params, goal, method, on_progress),
    };
    let mut whole = search_evaluator(&original, weights, filter, method)?;
    // A large surface's local search runs on patches of it first, and the search on the whole
    // starts where that one ended: most often its minimum already, so it measures only the
    // neighbours. The grid stays whole, the reference the searches are measured against.
    let patches = match method {
        SearchMethod::Local => Patches::of(&original, weights),
        SearchMethod::Grid => None,
    };
    let suggestion = match &patches {
        Some(p) => {
            let mut on_patches = search_evaluator(&p.original, Some(&p.weights), filter, method)?;
            let rough = search(&mut on_patches, starts)?;
            let found = search(&mut whole, &[rough.params])?;
            Suggestion {
                evaluations: found.evaluations + rough.evaluations,
                ..found
            }
        }
        None => search(&mut whole, starts)?,
    };
    let (positions, reference) = whole.smooth_drifting(&suggestion.params);
    s.set_params(suggestion.params);
    s.set_tau(options.tau);
    let smoothed = measured(s, &original, positions, reference);
    s.keep(smoothed);
    Ok(Some(suggestion))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    fn case_of_sizes(sizes: &[usize]) -> Case {
        let structure = |n: usize| {
            let mesh = Mesh {
                positions: vec![[0.0; 3]; n],
                ..Mesh::default()
            };
            CaseStructure::from_mesh("s", mesh, [1.0; 3])
        };
        Case {
            structures: sizes.iter().map(|&n| structure(n)).collect(),
            ..Case::default()
        }
    }

    #[test]
    fn search_names_round_trip_and_learned_is_the_default() {
        for s in SuggestAllSearch::ALL {
            assert_eq!(SuggestAllSearch::from_name(s.name()), Some(s));
        }
        assert_eq!(SuggestAllSearch::from_name("random"), None);
        assert_eq!(SuggestAllSearch::default(), SuggestAllSearch::Learned);
        assert_eq!(SuggestAllSearch::Learned.method(), SearchMethod::Local);
    }

    #[test]
    fn without_learning_every_structure_is_handed_out_at_once_the_largest_first() {
        let case = case_of_sizes(&[10, 30, 20]);
        let options = SuggestAllOptions::new(0.5, SuggestAllSearch::Local);
        let mut plan = SuggestAllPlan::new(&case, None, options);
        let jobs: Vec<SuggestJob> = std::iter::from_fn(|| plan.next_job(&case)).collect();
        let order: Vec<usize> = jobs.iter().map(|j| j.structure).collect();
        assert_eq!(order, [1, 2, 0]);
        assert!(jobs.iter().all(|j| j.starts.is_empty()));
        assert_eq!((plan.running(), plan.done(), plan.total()), (3, 0, 3));
        for i in [2, 0, 1] {
            assert!(!plan.is_over());
            plan.finish(i, None);
        }
        assert!(plan.is_over());
    }

    #[test]
    fn learning_hands_out_batch_by_batch_the_smallest_first_starting_where_they_ended() {
        let ahead = (LEARNING_LAG + 1) * LEARNING_BATCH;
        let sizes: Vec<usize> = (0..ahead + 2).rev().map(|n| 10 + n).collect();
        let case = case_of_sizes(&sizes);
        let options = SuggestAllOptions::new(0.5, SuggestAllSearch::Learned);
        let mut plan = SuggestAllPlan::new(&case, None, options);
        // The first batch and those it does not wait for, from the corners.
        let first: Vec<SuggestJob> = std::iter::from_fn(|| plan.next_job(&case)).collect();
        assert_eq!(first.len(), ahead);
        // The smallest batch first, each batch its largest first.
        let smallest_first: Vec<usize> = (0..sizes.len()).rev().collect();
        let by_batch: Vec<usize> = (smallest_first[..ahead].chunks(LEARNING_BATCH))
            .flat_map(|batch| batch.iter().rev().copied())
            .collect();
        let order: Vec<usize> = first.iter().map(|j| j.structure).collect();
        assert_eq!(order, by_batch);
        assert_eq!(plan.order(), smallest_first);
        assert!(first.iter().all(|j| j.starts.is_empty()), "the corners");
        let found = Params {
            iterations: 17,
            ..case.structures[0].params
        };
        let other = Params {
            iterations: 33,
            ..found
        };
        // The batches after the first, finished first, teach nothing and start nothing.
        for job in first[LEARNING_BATCH..].iter().rev() {
            plan.finish(job.structure, Some(other));
            assert_eq!(plan.next_job(&case), None, "waits for the first batch");
        }
        // The first batch, in any order; the last waits for the last of it.
        for (k, job) in first[..LEARNING_BATCH].iter().enumerate().rev() {
            assert_eq!(plan.next_job(&case), None, "waits for the first batch");
            plan.finish(job.structure, (k != 1).then_some(found));
        }
        let last: Vec<SuggestJob> = std::iter::from_fn(|| plan.next_job(&case)).collect();
        assert_eq!(last.len(), 2);
        for job in &last {
            assert_eq!(job.starts, [found], "learned from the first batch only");
        }
        plan.cancel();
        assert!(!plan.is_over(), "the last batch still runs");
        for job in &last {
            plan.finish(job.structure, None);
        }
        assert!(plan.is_over());
        assert_eq!(plan.done(), sizes.len());
    }

    #[test]
    fn a_plan_for_some_structures_hands_out_only_those() {
        let case = case_of_sizes(&[10, 30, 20, 40]);
        let options = SuggestAllOptions::new(0.5, SuggestAllSearch::Grid);
        let mut plan = SuggestAllPlan::new(&case, Some(&[0, 2]), options);
        let order: Vec<usize> = std::iter::from_fn(|| plan.next_job(&case))
            .map(|j| j.structure)
            .collect();
        assert_eq!(order, [2, 0]);
        plan.cancel();
        assert_eq!(plan.next_job(&case), None);
    }
}
