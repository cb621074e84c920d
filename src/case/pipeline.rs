//! Smoothing a case's structures: one structure with its own parameters, and "Suggest all",
//! the suggestion for every structure at one target smoothness followed by smoothing with it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use super::{Case, CaseStructure, Smoothed};
use crate::mesh::Topology;
use crate::metrics::{measure_vertices, smooth_drifting, Original};
use crate::smooth::{Filter, Params};
use crate::suggest::{
    search_evaluator, suggest_for_goal, suggest_from, Evaluator, Goal, Patches, SearchMethod,
    SuggestError, Suggestion,
};

/// Smooths a structure from its original with its parameters and weights and measures the
/// result (with the drifting reference, as every other caller does).
pub fn smooth_structure(structure: &mut CaseStructure) {
    let topology = Topology::build(&structure.original);
    let original = Original::new(&structure.original, &topology);
    let smoothed = smooth_on(structure, &original);
    structure.keep(smoothed);
}

fn smooth_on(structure: &CaseStructure, original: &Original) -> Smoothed {
    let weights = structure.weights.as_deref();
    let (positions, reference) = smooth_drifting(original, &structure.params, weights);
    let (metrics, vertex) = measure_vertices(original, &positions, &reference, structure.tau);
    Smoothed {
        curvature: Some(vertex.gaussian_curvature),
        ..Smoothed::new(positions, metrics, Some(vertex.local_error))
    }
}

/// What "Suggest all" does.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SuggestAllOptions {
    pub tau: f64,
    /// Every structure's filter becomes this one first; `None` keeps each structure's own.
    pub filter: Option<Filter>,
    pub method: SearchMethod,
    /// Each structure's suggestion changes its volume by at most this fraction, when given.
    pub max_volume_change: Option<f64>,
    /// With the local search: start each structure's search where the searches of structures
    /// finished before it ended, smallest structures first, instead of at the corners.
    pub learn: bool,
}

/// How far "Suggest all" has come: structures finished, of all, and parameter sets measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SuggestAllProgress {
    pub structures_done: usize,
    pub structures: usize,
    pub evaluations: usize,
}

/// Suggests each structure's parameters at `options.tau` with its own filter and bound, then
/// smooths it with them. Structures run in parallel (most are small, and one structure's
/// passes use few threads). `on_progress` returns `false` to cancel: structures already
/// finished keep their new parameters, the others are left as they were. Returns each
/// structure's suggestion, in order; a structure with nothing to smooth (no vertices) gets
/// `None` and is left alone.
pub fn suggest_all(
    case: &mut Case,
    options: &SuggestAllOptions,
    on_progress: &(dyn Fn(SuggestAllProgress) -> bool + Sync),
) -> Result<Vec<Option<Suggestion>>, SuggestError> {
    let total = case.structures.len();
    let cancelled = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let evaluations = AtomicUsize::new(0);
    let report = Mutex::new(());
    let tell = |finished: bool| {
        let _one_at_a_time = report.lock();
        if finished {
            done.fetch_add(1, Ordering::Relaxed);
        }
        let p = SuggestAllProgress {
            structures_done: done.load(Ordering::Relaxed),
            structures: total,
            evaluations: evaluations.load(Ordering::Relaxed),
        };
        if !on_progress(p) {
            cancelled.store(true, Ordering::Relaxed);
        }
        !cancelled.load(Ordering::Relaxed)
    };
    let learning = options.learn && options.method == SearchMethod::Local;
    // Learning goes batch by batch, each starting from the batches before it: the same starts
    // on any number of threads, so the page's workers find what the CLI finds.
    let batch = if learning {
        LEARNING_BATCH
    } else {
        total.max(1)
    };
    let mut learned: Vec<Params> = Vec::new();
    let mut kept = Kept {
        suggestions: vec![None; total],
        first_error: None,
    };
    for part in in_order(case, learning).chunks(batch) {
        // Copies of this batch's structures only, each back in the case as it finishes its
        // batch: a case of millions of vertices is never held twice.
        let copies: Vec<(usize, CaseStructure)> = (part.iter())
            .map(|&i| (i, case.structures[i].clone()))
            .collect();
        let outcomes: Vec<(usize, Outcome)> = (copies.into_par_iter())
            .with_max_len(1)
            .map(|(i, mut s)| {
                if cancelled.load(Ordering::Relaxed) {
                    return (i, Ok(None));
                }
                if let Some(filter) = options.filter {
                    s.set_filter(filter);
                }
                let starts = starts_from(&learned, s.params.filter);
                let outcome = suggest_structure(&mut s, options, &starts, &mut |_| {
                    evaluations.fetch_add(1, Ordering::Relaxed);
                    tell(false)
                });
                if matches!(outcome, Ok(Some(_))) {
                    tell(true);
                }
                (i, outcome.map(|o| o.map(|sg| (sg, s))))
            })
            .collect();
        if learning {
            learned.extend(outcomes.iter().filter_map(|(_, o)| match o {
                Ok(Some((sg, _))) => Some(sg.params),
                _ => None,
            }));
        }
        kept.keep(case, outcomes);
    }
    match kept.first_error {
        Some(e) => Err(e),
        None => Ok(kept.suggestions),
    }
}

/// The structures in the order they are searched: the largest first, so the pool is not left
/// waiting on one big structure at the end; learning, the smallest first, so the large ones
/// start where the small ones ended.
fn in_order(case: &Case, learning: bool) -> Vec<usize> {
    let mut order: Vec<usize> = (0..case.structures.len()).collect();
    order.sort_by_key(|&i| case.structures[i].original.vertex_count());
    if !learning {
        order.reverse();
    }
    order
}

/// Each structure's suggestion in the case's order, and the first error met.
struct Kept {
    suggestions: Vec<Option<Suggestion>>,
    first_error: Option<SuggestError>,
}

impl Kept {
    /// Puts each structure of `outcomes` that got a suggestion back into `case`.
    fn keep(&mut self, case: &mut Case, outcomes: Vec<(usize, Outcome)>) {
        for (i, result) in outcomes {
            match result {
                Ok(Some((suggestion, structure))) => {
                    case.structures[i] = structure;
                    self.suggestions[i] = Some(suggestion);
                }
                Ok(None) | Err(SuggestError::Cancelled) => {}
                Err(e) => {
                    self.first_error.get_or_insert(e);
                }
            }
        }
    }
}

/// How many structures, smallest first, search at once when they learn from each other.
pub const LEARNING_BATCH: usize = 4;

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

/// A structure's suggestion and the structure smoothed with it; `None` when cancelled or empty.
type Outcome = Result<Option<(Suggestion, CaseStructure)>, SuggestError>;

/// One structure's suggestion, applied and smoothed; `None` when it has no vertices.
/// `starts`, when not empty, are where its local search starts ([`starts_from`]).
pub fn suggest_structure(
    s: &mut CaseStructure,
    options: &SuggestAllOptions,
    starts: &[Params],
    on_progress: &mut dyn FnMut(crate::suggest::Progress) -> bool,
) -> Result<Option<Suggestion>, SuggestError> {
    if s.original.vertex_count() == 0 {
        return Ok(None);
    }
    let topology = Topology::build(&s.original);
    let original = Original::new(&s.original, &topology);
    let weights = s.weights.as_deref();
    let goal = Goal {
        tau: options.tau,
        max_volume_change: options.max_volume_change,
    };
    let (filter, method) = (s.params.filter, options.method);
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
    s.set_params(suggestion.params);
    s.set_tau(options.tau);
    let smoothed = smooth_on(s, &original);
    s.keep(smoothed);
    Ok(Some(suggestion))
}
