use super::testing::smooth_cpu;
use super::*;
use crate::case::Smoothed;
use crate::export::ExportFormat;
use crate::io;
use crate::metrics::{self, DriftingReference, VertexMeasures};
use crate::smooth::{Filter, Params};

const SAMPLE: &[u8] = include_bytes!("../../tests/data/bent_tube_staircase.ply");

/// A result's per-vertex measures, as an engine hands them over.
fn vertex(r: &Smoothed) -> VertexMeasures {
    let (local_error, curvature) = r.vertex_measures().expect("measured here");
    VertexMeasures {
        local_error: local_error.to_vec(),
        gaussian_curvature: curvature.to_vec(),
    }
}

fn sample_session() -> Session {
    let mut s = Session::default();
    s.open("bent_tube_staircase.ply", SAMPLE)
        .expect("the sample opens");
    s
}

#[test]
fn a_bad_file_keeps_the_model_and_names_the_problem() {
    let mut s = sample_session();
    let before = s.case().revision();
    let e = s.open("notes.txt", b"not a mesh").unwrap_err();
    assert!(e.starts_with("Cannot open notes.txt: "), "{e}");
    assert_eq!(s.error(), Some(e.as_str()));
    assert_eq!(
        s.case().model().map(|m| m.name.as_str()),
        Some("bent_tube_staircase.ply")
    );
    assert_eq!(s.case().revision(), before, "a failed open changes nothing");
    s.open("again.ply", SAMPLE).unwrap();
    assert_eq!(s.error(), None);
}

#[test]
fn cpu_result_equals_smoothing_then_measuring_directly() {
    let mut s = sample_session();
    s.case_mut().set_filter_name("taubin").unwrap();
    s.case_mut()
        .set_params_json(&serde_json::json!({"lambda": 0.6, "mu": -0.65, "iterations": 12}))
        .unwrap();
    assert!(s.case().needs_smoothing());
    smooth_cpu(&mut s);
    let r = s
        .case()
        .result()
        .expect("a result for the current revision");

    let model = s.case().model().unwrap();
    let params = *s.case().params();
    let mut drift = DriftingReference::new(&model.original);
    let positions =
        crate::smooth::smooth(model.mesh(), model.topology(), &params, None, &mut drift);
    let direct = metrics::measure(&model.original, &positions, drift.reference(), DEFAULT_TAU);
    assert_eq!(r.positions, positions);
    assert_eq!(r.metrics, direct);
    assert_eq!(s.case().result().unwrap().metrics, direct);
    assert!(
        r.metrics.curvature < r.metrics.curvature0,
        "smoothing lowers K"
    );
}

#[test]
fn every_change_makes_the_result_stale_and_late_results_are_refused() {
    let mut s = sample_session();
    smooth_cpu(&mut s);
    assert!(!s.case().needs_smoothing());
    let old = s.case().revision();
    let r = s.case().result().unwrap().clone();
    let n = r.positions.len();

    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 3}))
        .unwrap();
    assert!(s.case().needs_smoothing());
    assert!(
        s.case().last_result().is_some(),
        "the old result is shown meanwhile"
    );
    let take = |s: &mut Session, revision, positions: Vec<[f32; 3]>| {
        s.accept_measured(revision, positions, r.metrics.clone(), vertex(&r))
    };
    assert!(!take(&mut s, old, r.positions.clone()));
    let current = s.case().revision();
    assert!(!take(&mut s, current, r.positions[1..].to_vec()));
    assert_eq!(n, s.case().model().unwrap().mesh().vertex_count());
    assert!(take(&mut s, current, r.positions.clone()));
    assert!(!s.case().needs_smoothing());

    // Setting the same values again is not a change.
    let r = s.case().revision();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 3}))
        .unwrap();
    s.case_mut().set_filter_name("hc").unwrap();
    assert_eq!(s.case().revision(), r);
}

#[test]
fn refused_parameters_change_nothing_and_each_filter_keeps_its_values() {
    let mut s = sample_session();
    let e = s
        .case_mut()
        .set_params_json(&serde_json::json!({"iterations": 1000}))
        .unwrap_err();
    assert!(e.contains("iterations") && e.contains("[0, 50]"), "{e}");
    assert!(s
        .case_mut()
        .set_filter_name("gaussian")
        .unwrap_err()
        .contains("unknown filter"));
    assert_eq!(*s.case().params(), Params::defaults(Filter::Hc));

    s.case_mut().set_filter_name("laplace").unwrap();
    s.case_mut()
        .set_params_json(&serde_json::json!({"lambda": 0.3}))
        .unwrap();
    s.case_mut().set_filter_name("sinc").unwrap();
    assert_eq!(s.case().params().iterations, 20);
    s.case_mut().set_filter_name("laplace").unwrap();
    assert_eq!(s.case().params().lambda, 0.3);
    assert!(s.case_mut().set_tau(1.5).is_err());
    assert!(s.case_mut().set_voxel_size(Some([1.0, 0.0, 1.0])).is_err());
}

#[test]
fn exports_carry_the_smoothing_and_read_back() {
    let mut s = sample_session();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 5}))
        .unwrap();
    smooth_cpu(&mut s);
    let r = s.case().result().unwrap().clone();
    for format in [
        ExportFormat::Ply,
        ExportFormat::Stl,
        ExportFormat::Obj,
        ExportFormat::Glb,
    ] {
        let name = format!("out.{}", format!("{format:?}").to_lowercase());
        let bytes = s.case().export(format, None).unwrap();
        let back = io::load(&bytes, &name).unwrap();
        assert_eq!(back.vertex_count(), r.positions.len(), "{name}");
        assert_eq!(
            back.triangle_count(),
            s.case().model().unwrap().mesh().triangle_count()
        );
        if format != ExportFormat::Stl {
            assert_eq!(back.positions, r.positions, "{name}");
        }
    }
    let glb = s.case().export(ExportFormat::Glb, None).unwrap();
    let text = String::from_utf8_lossy(&glb);
    assert!(text.contains("\"filter\":\"hc\""), "extras name the filter");
    assert!(text.contains("\"mean_error\""), "extras carry the measures");
}

#[test]
fn an_export_never_states_parameters_its_surface_was_not_made_with() {
    let mut s = sample_session();
    smooth_cpu(&mut s);
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 7}))
        .unwrap();
    let stale = s.case().export(ExportFormat::Glb, None);
    assert!(stale.unwrap_err().contains("still being computed"));
    smooth_cpu(&mut s);
    let glb = s.case().export(ExportFormat::Glb, None).unwrap();
    assert!(String::from_utf8_lossy(&glb).contains("\"iterations\":7"));
}

#[test]
fn colours_follow_the_field_and_the_legend_reads_in_voxel_diagonals() {
    let mut s = sample_session();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 0}))
        .unwrap();
    smooth_cpu(&mut s);
    let (colors, legend) = s.case().colors(ColorField::LocalError).unwrap();
    assert_eq!(
        colors.len(),
        s.case().model().unwrap().mesh().vertex_count()
    );
    assert!(
        colors.iter().all(|c| *c == legend.bar[0]),
        "no error: all at the bottom"
    );

    s.case_mut().set_voxel_size(Some([1.0, 1.0, 1.0])).unwrap();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 10}))
        .unwrap();
    smooth_cpu(&mut s);
    let (colors, legend) = s.case().colors(ColorField::LocalError).unwrap();
    assert!(colors.iter().any(|c| *c != legend.bar[0]));
    assert_eq!(legend.min, 0.0);
    let max = s.case().result().unwrap().metrics.max_error;
    assert!(
        legend.max > 0.0 && legend.max <= 2.5 * max.max(1e-9),
        "{legend:?} max {max}"
    );
    assert!(
        legend.ticks.last().unwrap().label.contains("vd"),
        "{:?}",
        legend.ticks
    );

    let (_, k) = s.case().colors(ColorField::Curvature).unwrap();
    assert_eq!(k.min, -k.max);
    assert!(!k.ticks[0].label.contains("vd"));
    let (d, _) = s.case().colors(ColorField::Displacement).unwrap();
    assert_eq!(d.len(), colors.len());
}

#[test]
fn every_filter_gives_what_the_cli_computes() {
    for filter in ["laplace", "taubin", "hc", "sinc"] {
        let mut s = sample_session();
        s.case_mut().set_filter_name(filter).unwrap();
        let timings = smooth_cpu(&mut s).expect("smoothed");
        assert!(timings.smooth_ms >= 0.0 && timings.measure_ms >= 0.0);
        let original = &s.case().model().unwrap().original;
        let (positions, reference) =
            crate::metrics::smooth_drifting(original, s.case().params(), None);
        let expected = crate::metrics::measure(original, &positions, &reference, s.case().tau());
        let result = s.case().result().unwrap();
        assert_eq!(result.positions, positions, "{filter}");
        assert_eq!(result.metrics, expected, "{filter}");
        assert!(!s.smoothing_on_cpu());
    }
}

#[test]
fn a_change_while_a_run_is_out_takes_only_the_newer_result() {
    let mut s = sample_session();
    assert!(s.compute_cpu().is_none(), "asked, not back yet");
    assert!(s.smoothing_on_cpu());
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 4}))
        .unwrap();
    assert!(!s.smoothing_on_cpu(), "the run out is for other parameters");
    assert!(s.compute_cpu().is_none(), "the old result is refused");
    assert!(s.case().result().is_none() && s.case().last_result().is_none());
    assert!(s.compute_cpu().is_some());
    assert!(s.case().result().is_some());
    assert_eq!(s.case().params().iterations, 4);
}

#[test]
fn measured_results_from_elsewhere_are_taken_only_for_the_current_revision() {
    let mut s = sample_session();
    smooth_cpu(&mut s);
    let r = s.case().result().unwrap().clone();
    let old = s.case().revision();
    s.case_mut()
        .set_params_json(&serde_json::json!({"iterations": 2}))
        .unwrap();
    assert!(!s.accept_measured(old, r.positions.clone(), r.metrics.clone(), vertex(&r)));
    let mut short = vertex(&r);
    short.local_error.pop();
    assert!(!s.accept_measured(
        s.case().revision(),
        r.positions.clone(),
        r.metrics.clone(),
        short
    ));
    assert!(s.accept_measured(
        s.case().revision(),
        r.positions.clone(),
        r.metrics.clone(),
        vertex(&r)
    ));
    assert!(s.case().result().is_some());
    assert_eq!(s.case().params().iterations, 2);
    assert_eq!(s.case().result().unwrap().metrics, r.metrics);
}

/// A session whose CPU engine answers only once `deliver` is set, as busy workers do.
fn deferred_session() -> (Session, std::rc::Rc<std::cell::Cell<bool>>) {
    let (carrier, deliver) = crate::worker::deferred::Deferred::new(1);
    (
        {
            let mut s = Session::default();
            s.set_cpu_engine(Pool::new(Box::new(carrier)));
            s
        },
        deliver,
    )
}

#[test]
fn opening_in_a_worker_equals_opening_at_once_and_keeps_the_model_until_done() {
    let (mut s, deliver) = deferred_session();
    s.open("first.ply", SAMPLE).unwrap();
    let at_once = Model::load("second.ply", SAMPLE).unwrap().model;
    assert!(!s.opening_unanswered(), "nothing is opening");
    assert_eq!(s.begin_open("second.ply", SAMPLE.to_vec()), None);
    for _ in 0..3 {
        s.pump_cpu_engine();
        assert!(s.opening_unanswered(), "the worker is busy");
        let p = s.loading().expect("opening");
        assert_eq!((p.name.as_str(), p.stage), ("second.ply", 0));
        assert_eq!(p.doing, "waiting for a worker");
        assert_eq!(s.poll_opening(), None, "the worker is busy");
        assert_eq!(
            s.case().model().unwrap().name,
            "first.ply",
            "the model stays"
        );
    }
    deliver.set(true);
    s.pump_cpu_engine();
    assert!(!s.opening_unanswered(), "answered, to be taken up");
    assert!(s.loading().is_some(), "not taken up yet");
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert!(!s.opening_unanswered());
    let timed: Vec<&str> = s.open_stages().iter().map(|(d, _)| d.as_str()).collect();
    assert_eq!(
        timed,
        [
            "reading the file",
            "building the topology",
            "checking the mesh",
            "measuring the original"
        ]
    );
    assert!(s.loading().is_none());
    let model = s.case().model().unwrap();
    assert_eq!(model.name, "second.ply");
    assert_eq!(model.report, at_once.report);
    assert_eq!(model.edges, at_once.edges);
    assert_eq!(model.original.curvature(), at_once.original.curvature());
    assert_eq!(model.original.volume(), at_once.original.volume());
    assert_eq!(s.poll_opening(), None, "nothing left to open");
    // The workers hold the new model: the view's result comes from them.
    assert!(smooth_cpu(&mut s).is_some() && s.case().result().is_some());
}

#[test]
fn a_bad_file_opened_in_a_worker_keeps_the_model_and_a_later_file_replaces_an_earlier() {
    let mut s = sample_session();
    let revision = s.case().revision();
    s.begin_open(
        "broken.ply",
        b"ply\nformat ascii 1.0\nelement vertex 99\n".to_vec(),
    );
    let e = s.poll_opening().unwrap().unwrap_err();
    assert!(e.starts_with("Cannot open broken.ply: "), "{e}");
    assert_eq!(s.error(), Some(e.as_str()));
    assert_eq!(s.case().model().unwrap().name, "bent_tube_staircase.ply");
    assert_eq!(s.case().revision(), revision, "nothing changed");

    let (mut s, deliver) = deferred_session();
    s.begin_open("first.ply", SAMPLE.to_vec());
    assert_eq!(s.poll_opening(), None);
    let replaced = s.begin_open("second.ply", SAMPLE.to_vec());
    assert_eq!(replaced.as_deref(), Some("first.ply"));
    deliver.set(true);
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert_eq!(s.case().model().unwrap().name, "second.ply");
    assert_eq!(s.error(), None);
}

#[test]
fn files_asked_together_end_once_with_the_first_failure_among_them() {
    let mut s = sample_session();
    assert_eq!((s.openings().ended(), s.openings().last()), (0, None));
    s.begin_open("one.ply", SAMPLE.to_vec());
    s.begin_add("broken.ply", b"ply\n".to_vec());
    s.begin_add("two.ply", SAMPLE.to_vec());
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert_eq!(s.openings().ended(), 0, "two files still to add");
    let e = s.poll_opening().unwrap().unwrap_err();
    assert!(e.starts_with("Cannot open broken.ply: "), "{e}");
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert_eq!(s.openings().ended(), 1);
    assert_eq!(s.openings().last(), Some(&Err(e)), "the first failure");
    assert_eq!(
        s.case().as_case().structures.len(),
        2,
        "one.ply and two.ply"
    );
    s.begin_open("three.ply", SAMPLE.to_vec());
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert_eq!(
        (s.openings().ended(), s.openings().last()),
        (2, Some(&Ok(())))
    );
}

/// A session whose CPU engine runs "on other threads" and answers once `deliver` is set.
fn session_in_workers() -> (Session, std::rc::Rc<std::cell::Cell<bool>>) {
    let (carrier, deliver) = crate::worker::deferred::Deferred::new(1);
    let mut s = Session::default();
    s.set_cpu_engine(Pool::new(Box::new(carrier.in_workers())));
    (s, deliver)
}

#[test]
fn a_large_structure_selected_the_first_time_is_built_in_a_worker_while_the_model_stays() {
    let path = "../shared/data/segmentations/seg_mni152_brainmask_2mm.ply";
    let large = std::fs::read(format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let here = Model::load("brain.ply", &large).unwrap().model;
    assert!(here.mesh().vertex_count() > BUILT_ELSEWHERE_ABOVE);
    let (mut s, deliver) = session_in_workers();
    s.open("tube.ply", SAMPLE).unwrap();
    deliver.set(true);
    s.begin_add("brain.ply", large);
    assert_eq!(s.poll_opening(), Some(Ok(())));
    let (ended, model_id) = (s.openings().ended(), s.case().model_id());

    // Asked, then taken back by the model before it: the worker's answer is dropped.
    deliver.set(false);
    s.select_structure(1).unwrap();
    assert_eq!(s.selecting(), Some(1));
    s.select_structure(0).unwrap();
    assert_eq!((s.selecting(), s.loading()), (None, None));
    deliver.set(true);
    s.pump_cpu_engine();
    assert_eq!(s.poll_opening(), None);
    assert_eq!(s.case().model_id(), model_id, "the tube stayed the model");

    deliver.set(false);
    s.select_structure(1).unwrap();
    s.select_structure(1).unwrap();
    for _ in 0..2 {
        s.pump_cpu_engine();
        assert_eq!(s.poll_opening(), None, "the worker is busy");
        assert_eq!(s.case().current_structure(), Some(0), "the model stays");
        assert_eq!(s.loading().unwrap().name, "tube.ply: brain");
    }
    deliver.set(true);
    s.pump_cpu_engine();
    assert_eq!(s.poll_opening(), Some(Ok(())));
    assert_eq!(
        (s.selecting(), s.case().current_structure()),
        (None, Some(1))
    );
    assert_eq!(s.openings().ended(), ended, "no file was opened");
    let model = s.case().model().unwrap();
    assert_eq!(model.name, "tube.ply: brain");
    assert_eq!((&model.report, &model.edges), (&here.report, &here.edges));
    assert_eq!(model.topology(), here.topology());
    assert_eq!(model.original.curvature(), here.original.curvature());
    assert!(smooth_cpu(&mut s).is_some() && s.case().result().is_some());

    // Both models are kept: no worker builds either again.
    for index in [0, 1] {
        s.select_structure(index).unwrap();
        assert_eq!(
            (s.selecting(), s.case().current_structure()),
            (None, Some(index))
        );
    }
}
