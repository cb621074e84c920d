//! "Suggest all" in the page's session: every structure gets what `case build`'s pipeline
//! finds for it, one structure per engine worker, learning as the pipeline does.

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::read;
use meshsmooth::session::StructureOutcome;
mod common_session;
use common_session::smooth_cpu;

/// "Suggest all" in the page's session: each structure gets what the CLI's pipeline suggests for
/// it (its own filter and bound), the model's structure as its new parameters, the others kept
/// with their smoothed surfaces; cancelling leaves the rest as they were.
#[test]
fn a_session_suggests_every_structure_as_the_case_pipeline_does() {
    use meshsmooth::case::{self, Case, SuggestAllOptions, SuggestAllSearch};
    use meshsmooth::session::Session;
    let bytes = read("labelmaps/case_phantom_shared.seg.nrrd");
    let mut session = Session::default();
    session.begin_open("case_phantom_shared.seg.nrrd", bytes.clone());
    session.poll_opening().expect("done").expect("opens");
    // Each structure starts from its own filter and bound, the model's as the session has it.
    let mut expected = Case {
        structures: session.case().as_case().structures.as_slice().to_vec(),
        ..Case::default()
    };
    assert_eq!(expected.structures[0].params, *session.case().params());
    assert!(session
        .start_suggest_all(1.5, SuggestAllSearch::Local, None, 0.0)
        .is_err());
    let version = session.case().case_version();
    session
        .start_suggest_all(0.5, SuggestAllSearch::Local, None, 0.0)
        .unwrap();
    // Workers on this thread answer at once: one step ends it.
    assert!(session.step_suggest_all());
    assert!(!session.background().suggesting_all());
    // The three structures besides the model took new surfaces, each a new case version (the
    // model takes its parameters, and its surface comes from the view's engine).
    assert_eq!(session.background().suggest_all_applied(), 3);
    assert!(session.case().case_version() >= version + 3);
    let outcome = session.background().suggest_all().unwrap();
    assert_eq!((outcome.done, outcome.total), (4, 4));
    let suggested: Vec<meshsmooth::smooth::Params> = (outcome.structures.iter())
        .filter_map(|o| match o {
            Some(StructureOutcome::Suggested { params, .. }) => Some(*params),
            _ => None,
        })
        .collect();

    let options = SuggestAllOptions {
        tau: 0.5,
        filter: None,
        search: SuggestAllSearch::Local,
        max_volume_change: Some(0.05),
    };
    let mut liver = expected.structures[0].clone();
    let first = case::suggest_structure(&mut liver, &options, &[], &mut |_| true)
        .unwrap()
        .unwrap();
    case::suggest_all(&mut expected, &options, &|_| true).unwrap();
    assert_eq!(
        *session.case().params(),
        first.params,
        "the model takes its suggestion"
    );
    smooth_cpu(&mut session);
    assert_eq!(
        session.case().result().unwrap().positions,
        liver.smoothed.as_ref().unwrap().positions
    );
    for i in 1..4 {
        let kept = &session.case().as_case().structures[i];
        let want = &expected.structures[i];
        assert_eq!(kept.params, want.params, "structure {i}");
        let smoothed = kept.smoothed.as_ref().unwrap();
        assert_eq!(
            smoothed.positions,
            want.smoothed.as_ref().unwrap().positions
        );
        assert_eq!(smoothed.metrics, want.smoothed.as_ref().unwrap().metrics);
    }
    let want: Vec<_> = expected.structures.iter().map(|s| s.params).collect();
    assert_eq!(
        suggested, want,
        "each structure's outcome names its parameters"
    );
    // Drawn as suggested.
    let others = session.case().other_structures();
    assert_eq!(
        others[0].positions,
        &expected.structures[1].smoothed.as_ref().unwrap().positions[..]
    );

    session.begin_open("case_phantom_shared.seg.nrrd", bytes);
    session.poll_opening().expect("done").expect("opens");
    assert!(
        session.background().suggest_all().is_none(),
        "a new file starts over"
    );
}

/// Learning, the page hands the structures out batch by batch as `case build` does, so each
/// structure's search starts at the same sets and every structure gets the CLI's suggestion.
#[test]
fn a_learned_suggest_all_in_the_session_finds_what_the_pipeline_finds() {
    use meshsmooth::case::{
        self, Case, SuggestAllOptions, SuggestAllSearch, LEARNING_BATCH, LEARNING_LAG,
    };
    use meshsmooth::session::{structure_work, Session};
    let bytes = read("labelmaps/case_phantom_shared.seg.nrrd");
    let mut session = Session::default();
    session.begin_open("case_phantom_shared.seg.nrrd", bytes.clone());
    session.poll_opening().expect("done").expect("opens");
    // Three copies of the phantom: more structures than one batch.
    for copy in ["copy1.seg.nrrd", "copy2.seg.nrrd"] {
        session.begin_add(copy, bytes.clone());
        session.poll_opening().expect("done").expect("adds");
    }
    let count = session.case().as_case().structures.len();
    assert!(
        count > (LEARNING_LAG + 1) * LEARNING_BATCH,
        "{count} structures"
    );
    let mut expected = Case {
        structures: session.case().as_case().structures.as_slice().to_vec(),
        ..Case::default()
    };
    session
        .start_suggest_all(0.5, SuggestAllSearch::Learned, None, 5000.0)
        .unwrap();
    // The time estimate's fraction: the work of the structures answered, each weighed by its
    // size, rising batch by batch.
    let work: Vec<f64> = (expected.structures.iter())
        .map(|s| structure_work(s.original.vertex_count()))
        .collect();
    let mut done_before = 0.0;
    while session.background().suggesting_all() {
        let done = session.background().suggest_all_work_done().unwrap();
        let answered = session.background().suggest_all().unwrap().structures;
        let expected_done: f64 = (work.iter().zip(answered))
            .filter(|(_, o)| o.is_some())
            .map(|(w, _)| w)
            .sum::<f64>()
            / work.iter().sum::<f64>();
        assert!(
            (done - expected_done).abs() < 1e-12,
            "{done} {expected_done}"
        );
        assert!(
            done >= done_before && done < 1.0,
            "{done_before} then {done}"
        );
        done_before = done;
        // Ten seconds after its start (on the clock it was started by), the work left at
        // that pace.
        let left = session.background().suggest_all_seconds_left(15_000.0);
        match done > 0.0 {
            true => assert!((left.unwrap() - 10.0 * (1.0 - done) / done).abs() < 1e-9),
            false => assert_eq!(left, None),
        }
        // Workers on this thread answer at once: each step takes a batch, and only the
        // step that takes the last one says it ended.
        let ended = session.step_suggest_all();
        let answered = session.background().suggest_all().unwrap().structures;
        let all = answered.iter().all(Option::is_some);
        assert_eq!(ended, all, "ended only with every structure answered");
        assert_eq!(ended, !session.background().suggesting_all());
    }
    assert!(done_before > 0.0, "some work was seen done before the end");
    assert_eq!(session.background().suggest_all_work_done(), None);
    assert_eq!(
        session.background().suggest_all_seconds_left(15_000.0),
        None
    );
    let options = SuggestAllOptions {
        tau: 0.5,
        filter: None,
        search: SuggestAllSearch::Learned,
        max_volume_change: Some(0.05),
    };
    let want = case::suggest_all(&mut expected, &options, &|_| true).unwrap();
    let outcome = session.background().suggest_all().unwrap();
    assert_eq!((outcome.done, outcome.total), (count, count));
    for (i, (got, want)) in outcome.structures.iter().zip(&want).enumerate() {
        let Some(StructureOutcome::Suggested { params, .. }) = got else {
            panic!("structure {i}: {got:?}");
        };
        assert_eq!(*params, want.unwrap().params, "structure {i}");
    }
}

/// "Suggest all" on some structures: those get their suggestions, the others keep their
/// parameters; an index past the case is refused.
#[test]
fn suggest_all_on_some_structures_leaves_the_others_as_they_were() {
    use meshsmooth::case::SuggestAllSearch;
    use meshsmooth::session::Session;
    let bytes = read("labelmaps/case_phantom_shared.seg.nrrd");
    let mut session = Session::default();
    session.begin_open("case_phantom_shared.seg.nrrd", bytes);
    session.poll_opening().expect("done").expect("opens");
    let before: Vec<_> = (session.case().as_case().structures.iter())
        .map(|s| s.params)
        .collect();
    let refused = session.start_suggest_all(0.5, SuggestAllSearch::Local, Some(&[1, 4]), 0.0);
    assert!(refused.unwrap_err().contains("structure 4 does not exist"));
    session
        .start_suggest_all(0.5, SuggestAllSearch::Local, Some(&[1, 3]), 0.0)
        .unwrap();
    while session.background().suggesting_all() {
        session.step_suggest_all();
    }
    let outcome = session.background().suggest_all().unwrap();
    assert_eq!((outcome.done, outcome.total), (2, 2));
    let got: Vec<bool> = outcome.structures.iter().map(Option::is_some).collect();
    assert_eq!(got, [false, true, false, true]);
    let after: Vec<_> = (session.case().as_case().structures.iter())
        .map(|s| s.params)
        .collect();
    assert_eq!((after[0], after[2]), (before[0], before[2]));
    for i in [1, 3] {
        match &outcome.structures[i] {
            Some(StructureOutcome::Suggested { params, .. }) => assert_eq!(after[i], *params),
            other => panic!("structure {i}: {other:?}"),
        }
    }
}

/// Workers on this thread that answer one request a step, the latest posted first: structures
/// finish in another order than they were handed out, as a pool of real workers' may.
struct OutOfOrder {
    inner: meshsmooth::worker::InThread,
    posted: Vec<(usize, meshsmooth::worker::Request)>,
}

impl meshsmooth::worker::Carrier for OutOfOrder {
    fn workers(&self) -> usize {
        meshsmooth::worker::Carrier::workers(&self.inner)
    }

    fn post(&mut self, worker: usize, request: &meshsmooth::worker::Request) {
        self.posted.push((worker, request.clone()));
    }

    fn take_replies(&mut self) -> Vec<(usize, meshsmooth::worker::Reply)> {
        if let Some((worker, request)) = self.posted.pop() {
            self.inner.post(worker, &request);
        }
        self.inner.take_replies()
    }

    fn threaded(&self) -> bool {
        false
    }
}

/// The page's Suggest all, by default, gives every structure of the phantom and of the JHU atlas
/// the parameters and score of `case build`'s default, on one worker and on three answering out
/// of order: one plan, whoever runs it.
#[test]
fn the_pages_default_suggest_all_equals_the_clis_on_one_worker_and_several() {
    use meshsmooth::case::{self, Case, SuggestAllOptions, SuggestAllSearch};
    use meshsmooth::session::Session;
    use meshsmooth::worker::{InThread, Pool};
    for file in [
        "case_phantom_shared.seg.nrrd",
        "JHU-WhiteMatter-labels-1mm.nii.gz",
    ] {
        let bytes = read(&format!("labelmaps/{file}"));
        let mut cli: Option<Case> = None;
        for workers in [1, 3] {
            let mut session = Session::default();
            session.set_cpu_engine(Pool::new(Box::new(OutOfOrder {
                inner: InThread::new(workers),
                posted: Vec::new(),
            })));
            session.begin_open(file, bytes.clone());
            let opened = (0..1000).find_map(|_| session.poll_opening());
            opened.expect("done").expect("opens");
            let cli = cli.get_or_insert_with(|| {
                let mut case = Case {
                    structures: session.case().as_case().structures.as_slice().to_vec(),
                    ..Case::default()
                };
                let options = SuggestAllOptions::new(0.5, SuggestAllSearch::default());
                case::suggest_all(&mut case, &options, &|_| true).expect("suggests");
                case
            });
            session
                .start_suggest_all(0.5, SuggestAllSearch::default(), None, 0.0)
                .unwrap();
            while session.background().suggesting_all() {
                session.step_suggest_all();
            }
            let outcome = session.background().suggest_all().unwrap();
            assert_eq!(outcome.options.search, SuggestAllSearch::Learned);
            assert_eq!(outcome.done, cli.structures.len(), "{file}");
            for (i, (got, want)) in outcome.structures.iter().zip(&cli.structures).enumerate() {
                let Some(StructureOutcome::Suggested {
                    params, metrics, ..
                }) = got
                else {
                    panic!("{file} structure {i}: {got:?}");
                };
                let what = format!("{file}, {workers} workers, structure {i}");
                assert_eq!(*params, want.params, "{what}");
                let smoothed = want.smoothed.as_ref().expect("smoothed");
                assert_eq!(metrics.score, smoothed.metrics.score, "{what}");
            }
        }
    }
}
