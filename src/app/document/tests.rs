//! The document between frames: opening, the workers' replies, the calls waiting.

use super::*;
use std::cell::Cell;
use wasm_bindgen_test::wasm_bindgen_test;

wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_browser);

/// A voxelised bent tube: one small staircase surface.
const TUBE_NAME: &str = "bent_tube_staircase.ply";
const TUBE: &[u8] = include_bytes!("../../../tests/data/bent_tube_staircase.ply");

/// A document on the CPU engine whose `workers` workers run beside the page (unless `here`)
/// and answer once `deliver` is set.
fn doc_on_workers(workers: usize, here: bool) -> (Document, std::rc::Rc<Cell<bool>>) {
    let mut doc = Document::with_backend(Backend::Cpu);
    let (carrier, deliver) = crate::worker::deferred::Deferred::new(workers);
    let carrier = if here { carrier } else { carrier.in_workers() };
    doc.session
        .set_cpu_engine(crate::worker::Pool::new(Box::new(carrier)));
    (doc, deliver)
}

#[wasm_bindgen_test]
fn a_bad_file_keeps_the_previous_model_and_reports_why() {
    let mut doc = Document::with_backend(Backend::Cpu);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    let generation = doc.session.case().model_id();
    let error = doc.open_now("notes.txt", b"not a mesh").unwrap_err();
    assert!(error.starts_with("Cannot open notes.txt: "), "{error}");
    assert!(error.contains(".stl .obj .ply"), "{error}");
    assert_eq!(doc.session.case().model_id(), generation);
    let state = doc.state_json();
    assert_eq!(state["model"], TUBE_NAME);
    assert_eq!(state["error"], error.as_str());
    assert!(doc
        .open_now("empty.stl", b"")
        .unwrap_err()
        .contains("empty"));
}

#[wasm_bindgen_test]
fn a_workers_reply_asks_for_a_frame_only_when_what_is_shown_changed() {
    let (mut doc, deliver) = doc_on_workers(2, false);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    assert!(
        !doc.step_cpu_engine(),
        "the smoothing is asked, not answered"
    );
    assert!(doc.busy());
    deliver.set(true);
    assert!(doc.step_cpu_engine(), "the result came");
    assert!(!doc.busy() && doc.timings.is_some());
    assert!(!doc.step_cpu_engine(), "nothing new");

    deliver.set(false);
    doc.session.set_graphs_wanted(true);
    assert!(!doc.step_cpu_engine(), "the graphs' runs are asked");
    assert!(doc.session.background().guidance_busy());
    deliver.set(true);
    assert!(doc.step_cpu_engine(), "the graphs are done, between frames");
    assert!(!doc.session.background().guidance_busy() && doc.session.background().graphs_current());
}

#[wasm_bindgen_test]
fn the_end_of_suggest_all_asks_for_a_frame_at_once() {
    // Replies come between frames; the bar moves with paced frames, its end must not wait.
    let (mut doc, deliver) = doc_on_workers(1, true);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    let search = crate::case::SuggestAllSearch::Local;
    doc.session
        .start_suggest_all(0.5, search, None, 0.0)
        .unwrap();
    assert!(!doc.step_cpu_engine(), "the structure is handed out");
    assert!(doc.session.background().suggesting_all());
    deliver.set(true);
    assert!(doc.step_cpu_engine(), "Suggest all ended");
    assert!(!doc.session.background().suggesting_all());
    assert!(!doc.step_cpu_engine(), "nothing new");
}

#[wasm_bindgen_test]
fn suggest_all_in_the_workers_needs_no_frames_with_either_engine() {
    let (mut doc, deliver) = doc_on_workers(2, false);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    doc.step_cpu_engine();
    deliver.set(true);
    doc.step_cpu_engine();
    assert!(!doc.busy(), "the current result is there");
    deliver.set(false);
    let search = crate::case::SuggestAllSearch::Local;
    doc.session
        .start_suggest_all(0.5, search, None, 0.0)
        .unwrap();
    assert!(doc.session.background().suggesting_all());
    // The graphs' runs wait in the workers behind Suggest all's structures (on a software
    // adapter the GPU engine takes none of them).
    doc.session.set_graphs_wanted(true);
    doc.step_cpu_engine();
    assert!(doc.session.background().guidance_busy());
    for backend in [Backend::Cpu, Backend::WebGpu] {
        doc.backend = backend;
        assert!(doc.working(), "{backend:?}");
        assert!(
            doc.working_elsewhere(),
            "{backend:?}: the workers' replies wake the page"
        );
    }
    doc.guidance_on_gpu = true;
    assert!(
        !doc.working_elsewhere(),
        "the GPU engine's runs need frames"
    );
    doc.guidance_on_gpu = false;
    // Between frames the workers' replies move the graphs on with either engine.
    deliver.set(true);
    for _ in 0..1000 {
        let background = doc.session.background();
        if !background.suggesting_all() && !background.guidance_busy() {
            break;
        }
        doc.step_cpu_engine();
    }
    assert!(
        doc.session.background().graphs_current(),
        "{:?}",
        doc.backend
    );
    deliver.set(false);
    // The GPU engine computes the current result in frames; the CPU engine's workers do not.
    let mut params = *doc.session.case().params();
    params.iterations += 5;
    doc.session.case_mut().set_params(params).unwrap();
    assert!(doc.busy());
    doc.backend = Backend::WebGpu;
    assert!(!doc.working_elsewhere(), "the GPU engine needs frames");
    doc.backend = Backend::Cpu;
    assert!(doc.working_elsewhere());
}

#[wasm_bindgen_test]
fn waiting_calls_are_answered_once_the_result_is_computed() {
    let mut doc = Document::with_backend(Backend::Cpu);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    let answered = Rc::new(Cell::new(0));
    let seen = answered.clone();
    doc.when_current(Box::new(move |s| {
        assert!(s.case().result().is_some());
        seen.set(seen.get() + 1);
    }));
    doc.answer_waiting();
    assert_eq!(answered.get(), 0, "nothing computed yet");
    while doc.busy() {
        doc.compute_on_cpu();
    }
    doc.answer_waiting();
    assert_eq!(answered.get(), 1);
    assert!(doc.timings.is_some());
    assert_eq!(doc.state_json()["busy"], false);
    let model = doc.session.case().model().unwrap();
    assert_eq!(
        (model.report.vertices, model.report.faces),
        (2296, 4588),
        "the tube"
    );
}

#[wasm_bindgen_test]
fn a_structure_built_in_a_worker_becomes_the_model_and_a_tour_step_that_chose_it_goes_on() {
    // A brain mask at 2 mm: one structure larger than a frame's build.
    const MASK: &[u8] = include_bytes!(
        "../../../../shared/data/segmentations/seg_mni152_brainmask_2mm_mask.nii.gz"
    );
    let (mut doc, deliver) = doc_on_workers(2, false);
    deliver.set(true);
    doc.open_now(TUBE_NAME, TUBE).unwrap();
    doc.ask_add("mask.nii.gz", MASK.to_vec(), None);
    assert_eq!(doc.step_loading(), Opening::Done);
    let structures = &doc.session.case().as_case().structures;
    let large = structures[1].original.vertex_count();
    assert!(large > crate::session::BUILT_ELSEWHERE_ABOVE, "{large}");

    deliver.set(false);
    doc.tour = Some(0);
    doc.select(1).unwrap();
    assert_eq!(doc.session.selecting(), Some(1));
    assert_eq!(
        doc.tour, None,
        "selecting another structure leaves the tour"
    );
    // A tour step selects its structure, then shows itself.
    doc.tour = Some(0);
    assert_eq!(doc.step_loading(), Opening::Working);
    assert_eq!(doc.session.case().current_structure(), Some(0));
    deliver.set(true);
    assert_eq!(doc.step_loading(), Opening::Done);
    assert_eq!(doc.session.case().current_structure(), Some(1));
    assert_eq!(
        doc.session.case().model().unwrap().mesh().vertex_count(),
        large
    );
    assert_eq!(doc.tour, Some(0), "the step's tour goes on");
}
