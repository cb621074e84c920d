use super::*;
use crate::metrics;
use crate::suggest::{quality_graphs, suggest, Evaluator, Terms};
use std::cell::Cell;

const SAMPLE: &[u8] = include_bytes!("../../../tests/data/bent_tube_staircase.ply");

fn session(filter: &str) -> Session {
    let mut s = Session::default();
    s.open("sample.ply", SAMPLE).unwrap();
    s.case_mut().set_filter_name(filter).unwrap();
    s
}

/// The quality graphs of the session's model and parameters, computed here.
fn graphs_here(s: &Session) -> QualityGraphs {
    let original = model_original(s);
    let (params, tau) = (s.case().params(), s.case().tau());
    quality_graphs(&original, None, params, tau, &mut |_| true).unwrap()
}

/// Steps the background until nothing is left, on a clock that ticks 1 ms per reading;
/// returns the calls it took.
fn settle(s: &mut Session) -> usize {
    settle_on(s, None)
}

/// [`settle`] with the runs on `offload` when given.
fn settle_on(s: &mut Session, mut offload: Option<&mut dyn Offload>) -> usize {
    let ticks = Cell::new(0.0);
    let clock = || {
        ticks.set(ticks.get() + 1.0);
        ticks.get()
    };
    let mut calls = 0;
    while s.background().guidance_busy() {
        let lent = offload.as_mut().map(|o| &mut **o as &mut dyn Offload);
        s.step_guidance_on(&clock, lent);
        calls += 1;
        assert!(calls < 1_000_000, "the background never settles");
    }
    calls
}

#[test]
fn a_loaded_model_gets_the_local_search_suggestion() {
    let mut s = Session::default();
    s.open("sample.ply", SAMPLE).unwrap();
    assert!(
        s.background().suggesting(),
        "a search starts with the model"
    );
    settle(&mut s);
    let got = s
        .background()
        .suggestion()
        .expect("a suggestion")
        .suggestion;
    assert_eq!(
        got,
        local_suggestion(&s.case().model().unwrap().original, &s)
    );
}

#[test]
fn a_session_that_only_shows_starts_no_search_for_a_model() {
    let mut s = Session::default();
    s.set_suggest_on_open(false);
    s.open("sample.ply", SAMPLE).unwrap();
    assert!(
        !s.background().suggesting(),
        "no search starts with the model"
    );
    assert!(
        !s.background().guidance_busy(),
        "nothing runs in the background"
    );
    assert!(s.background().suggestion().is_none());
}

#[test]
fn a_grid_suggestion_follows_tau_without_smoothing_again() {
    let mut s = session("laplace");
    s.case_mut()
        .set_params_json(&serde_json::json!({"max_displacement": 0.4}))
        .unwrap();
    s.start_suggest(SearchMethod::Grid);
    settle(&mut s);
    for tau in [0.5, 0.2, 0.9] {
        s.case_mut().set_tau(tau).unwrap();
        assert!(!s.background().guidance_busy());
        let got = s.background().suggestion().unwrap().suggestion;
        let expected = suggest(
            &model_original(&s),
            None,
            s.case().params(),
            tau,
            SearchMethod::Grid,
            &mut |_| true,
        )
        .unwrap();
        assert_eq!(got, expected, "tau {tau}");
        assert_eq!(got.params.max_displacement, Some(0.4));
    }
    // Another filter: the grid is not for it.
    s.case_mut().set_filter_name("hc").unwrap();
    assert!(s.background().suggestion().is_none());
}

/// The one-shot engine's local-search suggestion for `original` at the session's parameters
/// and tau, unweighted: what the background must arrive at.
fn local_suggestion(original: &metrics::Original, s: &Session) -> crate::suggest::Suggestion {
    let method = SearchMethod::Local;
    suggest(
        original,
        None,
        s.case().params(),
        s.case().tau(),
        method,
        &mut |_| true,
    )
    .unwrap()
}

fn model_original(s: &Session) -> metrics::Original {
    s.case().model().unwrap().original.clone()
}

#[test]
fn graphs_follow_the_parameters_in_the_background() {
    let mut s = session("taubin");
    s.cancel_suggest();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 8}))
        .unwrap();
    assert!(
        !s.background().guidance_busy(),
        "graphs are only made when wanted"
    );
    s.set_graphs_wanted(true);
    settle(&mut s);
    assert!(s.background().graphs_current());
    let expected = graphs_here(&s);
    assert_eq!(s.background().graphs().unwrap(), expected);

    // A new value: the old graphs stay on show, marked stale, until new ones are made.
    s.case_mut()
        .set_params_json(&serde_json::json!({"lambda": 0.4}))
        .unwrap();
    assert!(!s.background().graphs_current());
    assert_eq!(s.background().graphs().unwrap(), expected);
    assert!(s.background().guidance_busy());
    settle(&mut s);
    assert!(s.background().graphs_current());
    assert_eq!(s.background().graphs().unwrap().current, *s.case().params());

    // tau rescored without smoothing.
    s.case_mut().set_tau(0.9).unwrap();
    assert!(!s.background().guidance_busy());
    assert_eq!(s.background().graphs().unwrap().tau, 0.9);
}

#[test]
fn the_gallery_holds_the_local_suggestion_of_each_tau() {
    let mut s = session("laplace");
    s.cancel_suggest();
    s.start_gallery();
    settle(&mut s);
    let picks = s.background().gallery();
    assert_eq!(picks.len(), GALLERY_TAUS.len());
    let original = model_original(&s);
    for (pick, &tau) in picks.iter().zip(&GALLERY_TAUS) {
        let expected = suggest(
            &original,
            None,
            s.case().params(),
            tau,
            SearchMethod::Local,
            &mut |_| true,
        )
        .unwrap();
        assert_eq!(
            (pick.tau, pick.params, pick.terms),
            (tau, expected.params, expected.terms)
        );
        let (positions, _) = metrics::smooth_drifting(&original, &pick.params, None);
        assert_eq!(pick.positions, positions);
        assert_eq!(pick.vertex.local_error.len(), positions.len());
    }
    // Stronger smoothing as tau grows.
    let k: Vec<f64> = picks.iter().map(|p| p.terms.curvature_ratio).collect();
    assert!(k.first() > k.last(), "{k:?}");
}

#[test]
fn a_search_for_another_filter_or_model_is_dropped() {
    let mut s = session("hc");
    let ticks = Cell::new(0.0);
    let clock = || {
        ticks.set(ticks.get() + 1.0);
        ticks.get()
    };
    s.start_suggest(SearchMethod::Local);
    assert!(s.background().suggesting());
    s.case_mut().set_filter_name("sinc").unwrap();
    s.step_guidance(&clock);
    assert!(!s.background().suggesting());
    s.case_mut().set_filter_name("hc").unwrap();
    s.start_gallery();
    s.open("again.ply", SAMPLE).unwrap();
    assert!(s.background().gallery().is_empty());
    assert_eq!(
        s.background().activities().len(),
        1,
        "only the new model's suggestion: {:?}",
        s.background().activities()
    );
}

/// An offload that answers each request one call after it was made (as the GPU does between
/// frames), from the CPU engine, for the model it is lent; it counts the requests per model.
#[derive(Default)]
struct Deferred {
    asked: Option<(u64, Params, Vec<u32>)>,
    requests: Vec<u64>,
}

impl Offload for Deferred {
    fn measure(&mut self, model: &ModelRef<'_>, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        let request = (model.id, *params, at.to_vec());
        if self.asked.as_ref() != Some(&request) {
            self.asked = Some(request);
            self.requests.push(model.id);
            return None;
        }
        self.asked = None;
        let mut ev = crate::suggest::MeshEvaluator::new(model.original, model.weights).ok()?;
        ev.measure(params, at)
    }

    fn waiting(&self) -> bool {
        self.asked.is_some()
    }

    fn failure(&self) -> Option<String> {
        None
    }
}

#[test]
fn an_offload_runs_the_searches_and_graphs_with_the_same_results() {
    let mut s = session("taubin");
    let mut offload = Deferred::default();
    s.start_suggest(SearchMethod::Local);
    s.set_graphs_wanted(true);
    let calls = settle_on(&mut s, Some(&mut offload));
    // One request per call at most: a call returns once its run is on the device.
    assert!(calls >= offload.requests.len(), "{calls} calls");
    let original = model_original(&s);
    let expected = local_suggestion(&original, &s);
    assert_eq!(s.background().suggestion().unwrap().suggestion, expected);
    assert_eq!(s.background().graphs().unwrap(), graphs_here(&s));
    assert!(offload.requests.iter().all(|&id| id == s.doc.model_id));
}

#[test]
fn searches_reuse_the_terms_measured_before_until_the_weights_change() {
    let mut s = session("hc");
    let mut offload = Deferred::default();
    settle_on(&mut s, Some(&mut offload));
    let suggestion = offload.requests.len();
    assert!(suggestion > 0, "the suggestion made at opening measured");
    s.start_gallery();
    settle_on(&mut s, Some(&mut offload));
    let gallery = offload.requests.len() - suggestion;
    let picks_of = |s: &Session| -> Vec<_> {
        let gallery = s.background().gallery();
        gallery.iter().map(|p| (p.params, p.terms)).collect()
    };
    let picks = picks_of(&s);
    // Made again: every search is answered from what was measured, with the same picks.
    s.start_gallery();
    settle_on(&mut s, Some(&mut offload));
    assert_eq!(offload.requests.len(), suggestion + gallery);
    assert_eq!(picks_of(&s), picks);
    // The gallery's tau 0.5 search is the opening suggestion's: it measured nothing new, so
    // the gallery asked for fewer runs than five searches alone would.
    let mut alone = Deferred::default();
    let mut fresh = session("hc");
    fresh.cancel_suggest();
    fresh.start_gallery();
    settle_on(&mut fresh, Some(&mut alone));
    assert!(
        gallery < alone.requests.len(),
        "{gallery} runs, {} alone",
        alone.requests.len()
    );
    // Other weights: measured afresh.
    assert!(s
        .case_mut()
        .dab_weights(&[(0, 1.0), (1, 1.0)], crate::session::Dab::Paint(0.0)));
    s.start_gallery();
    settle_on(&mut s, Some(&mut offload));
    assert!(offload.requests.len() > suggestion + gallery);
}

#[test]
fn a_suggestion_in_progress_says_how_far_it_is_in_a_line_the_side_panel_fits() {
    let progress = Progress {
        done: 250,
        total: 1331,
    };
    let grid = Activity::Suggest {
        progress,
        tau: 0.5,
        method: SearchMethod::Grid,
    };
    assert_eq!(grid.describe(), "Grid search, τ 0.50: 250 of 1331 sets");
    let local = Activity::Suggest {
        progress,
        tau: 0.5,
        method: SearchMethod::Local,
    };
    assert_eq!(local.describe(), "Local search, τ 0.50: 250 sets measured");
    // About 40 characters fit the side panel's default width.
    for a in [grid, local] {
        assert!(a.describe().chars().count() <= 40, "{}", a.describe());
    }
}
