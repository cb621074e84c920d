use super::deferred::Deferred;
use super::*;
use crate::evaluate::{ModelRef, Offload};
use crate::io;
use crate::model::Model;
use crate::smooth::Filter;

const SAMPLE: &[u8] = include_bytes!("../../tests/data/bent_tube_staircase.ply");

fn sample() -> Original {
    let mesh = io::load(SAMPLE, "bent_tube_staircase.ply").unwrap();
    let topology = Topology::build(&mesh);
    Original::new(&mesh, &topology)
}

fn model<'a>(original: &'a Original, weights: Option<&'a [f32]>, version: u64) -> ModelRef<'a> {
    ModelRef {
        original,
        id: 7,
        weights,
        weights_version: version,
    }
}

fn params(filter: Filter, iterations: u32) -> Params {
    Params {
        iterations,
        ..Params::defaults(filter)
    }
}

/// Asks until the pool answers (the in-thread pool answers on the next call).
fn measure(pool: &mut Pool, model: &ModelRef<'_>, p: &Params, at: &[u32]) -> Vec<Terms> {
    for _ in 0..4 {
        if let Some(terms) = pool.measure(model, p, at) {
            return terms;
        }
    }
    panic!("the pool never answered {p:?} at {at:?}");
}

#[test]
fn a_smoothing_job_answers_what_the_cli_computes() {
    let original = sample();
    let mut pool = Pool::in_thread(2);
    let p = params(Filter::Hc, 12);
    let job = pool.smooth(&model(&original, None, 0), &p, 0.5, true);
    let Some(Reply::Smoothed {
        positions,
        metrics,
        vertex,
        ..
    }) = pool.take_smoothed(job)
    else {
        panic!("no smoothing came back");
    };
    let (expected, reference) = metrics::smooth_drifting(&original, &p, None);
    let (measured, expected_vertex) =
        metrics::measure_vertices(&original, &expected, &reference, 0.5);
    assert_eq!(positions, expected);
    assert_eq!(metrics_of(&metrics).unwrap(), measured);
    assert_eq!(vertex, expected_vertex);
    assert!(!pool.busy());
}

#[test]
fn terms_spread_over_the_workers_equal_the_evaluators() {
    let original = sample();
    let weights: Vec<f32> = (0..original.mesh().vertex_count())
        .map(|i| if i % 3 == 0 { 0.0 } else { 1.0 })
        .collect();
    let mut pool = Pool::in_thread(3);
    for (w, version) in [(None, 1), (Some(weights.as_slice()), 2)] {
        let m = model(&original, w, version);
        let requests: Vec<(Params, Vec<u32>)> = [Filter::Laplace, Filter::Hc, Filter::Sinc]
            .iter()
            .map(|&f| (params(f, 0), vec![if f == Filter::Sinc { 10 } else { 5 }]))
            .collect();
        pool.prefetch(&m, &requests[1..]);
        for (p, at) in &requests {
            let mut direct = MeshEvaluator::new(&original, w).unwrap();
            let expected = direct.measure(p, at).unwrap();
            assert_eq!(
                measure(&mut pool, &m, p, at),
                expected,
                "{p:?} weights {version}"
            );
        }
    }
    assert_eq!(pool.failure(), None);
}

#[test]
fn a_newer_view_job_supersedes_one_still_waiting() {
    let original = sample();
    let m = model(&original, None, 0);
    let (carrier, deliver) = Deferred::new(1);
    let mut pool = Pool::new(Box::new(carrier));
    // The first goes out at once; the second waits behind it and the third replaces it.
    let first = pool.smooth(&m, &params(Filter::Laplace, 2), 0.5, true);
    let second = pool.smooth(&m, &params(Filter::Laplace, 3), 0.5, true);
    let gallery = pool.smooth(&m, &params(Filter::Hc, 4), 0.5, false);
    let third = pool.smooth(&m, &params(Filter::Laplace, 4), 0.5, true);
    assert!(!pool.pending(second), "superseded while it waited");
    assert!(pool.pending(first) && pool.pending(gallery) && pool.pending(third));
    deliver.set(true);
    let mut answered = Vec::new();
    for _ in 0..8 {
        for job in [first, gallery, third] {
            if let Some(reply) = pool.take_smoothed(job) {
                assert!(matches!(reply, Reply::Smoothed { .. }), "{reply:?}");
                answered.push(job);
            }
        }
    }
    assert_eq!(answered, [first, gallery, third]);
    assert!(pool.take_smoothed(second).is_none());
}

/// #28's latency: with a worker kept for the view, a change of parameters is smoothed at once
/// while the guidance's terms and "Suggest all" keep the other workers busy, and the view
/// worker never takes their work.
#[test]
fn the_view_worker_smooths_at_once_while_the_others_are_busy() {
    let original = sample();
    let m = model(&original, None, 0);
    let (carrier, deliver, log) = Deferred::logged(2);
    let mut pool = Pool::with_view_worker(Box::new(carrier));
    assert_eq!(pool.workers(), 1, "one worker for the background");
    assert!(pool.has_view_worker());
    let requests: Vec<(Params, Vec<u32>)> = (1..4)
        .map(|i| (params(Filter::Taubin, 0), vec![i * 5]))
        .collect();
    pool.prefetch(&m, &requests);
    let structure = pool.suggest_structure(
        original.mesh().clone(),
        params(Filter::Hc, 10),
        None,
        crate::case::SuggestAllOptions {
            tau: 0.5,
            filter: None,
            search: crate::case::SuggestAllSearch::Local,
            max_volume_change: None,
        },
        Vec::new(),
    );
    let view = pool.smooth(&m, &params(Filter::Hc, 20), 0.5, true);
    let jobs = |worker: usize| -> Vec<String> {
        (log.borrow().iter())
            .filter(|(w, r)| {
                *w == worker && !matches!(r, Request::Hold { .. } | Request::Weights { .. })
            })
            .map(|(_, r)| {
                format!("{r:?}")
                    .split([' ', '{'])
                    .next()
                    .unwrap_or_default()
                    .to_string()
            })
            .collect()
    };
    assert_eq!(
        jobs(1),
        ["Smooth"],
        "the view's job went out at once, to its worker"
    );
    assert_eq!(
        jobs(0),
        ["Terms"],
        "the background's worker is busy with the guidance"
    );
    deliver.set(true);
    let mut smoothed = None;
    let mut suggested = None;
    for _ in 0..40 {
        pool.pump();
        smoothed = smoothed.or_else(|| pool.take_smoothed(view));
        suggested = suggested.or_else(|| pool.take_structure_reply(structure));
        let _ = pool.measure(&m, &requests[2].0, &requests[2].1);
    }
    assert!(matches!(smoothed, Some(Reply::Smoothed { .. })));
    assert!(matches!(suggested, Some(Reply::Suggested { .. })));
    assert_eq!(
        jobs(1),
        ["Smooth"],
        "nothing but the view's work on the view's worker"
    );
    assert!(
        jobs(0).contains(&"SuggestStructure".to_string()),
        "{:?}",
        jobs(0)
    );
}

#[test]
fn a_worker_without_a_model_says_so() {
    let mut worker = Worker::default();
    let reply = worker.handle(
        Request::Smooth {
            job: 3,
            params: params(Filter::Hc, 2),
            tau: 0.5,
        },
        &clock_ms,
        &mut |_| {},
    );
    assert!(
        matches!(reply, Some(Reply::Failed { job: 3, .. })),
        "{reply:?}"
    );
    assert!(decode::<Request>(b"\xff\xff\xff").is_err());
}

#[test]
fn the_view_worker_takes_structures_and_is_restarted_when_the_view_needs_it() {
    let original = sample();
    let m = model(&original, None, 0);
    let (mut carrier, deliver, log) = Deferred::logged(2);
    let restarts = carrier.restarting();
    let mut pool = Pool::with_view_worker(Box::new(carrier));
    let options = crate::case::SuggestAllOptions {
        tau: 0.5,
        filter: None,
        search: crate::case::SuggestAllSearch::Local,
        max_volume_change: None,
    };
    let structures: Vec<StructureJob> = (0..2)
        .map(|_| {
            let mesh = original.mesh().clone();
            pool.suggest_structure(mesh, params(Filter::Hc, 10), None, options, Vec::new())
        })
        .collect();
    let names = |worker: usize| -> Vec<String> {
        (log.borrow().iter())
            .filter(|(w, _)| *w == worker)
            .map(|(_, r)| {
                format!("{r:?}")
                    .split([' ', '{'])
                    .next()
                    .unwrap_or_default()
                    .to_string()
            })
            .collect()
    };
    assert_eq!(names(0), ["SuggestStructure"]);
    assert_eq!(
        names(1),
        ["SuggestStructure"],
        "the idle view worker took one"
    );
    // The view asks for a smoothing: no worker is free, so the view worker is restarted, given
    // the model again and the smoothing; its structure waits for the next free worker.
    let view = pool.smooth(&m, &params(Filter::Hc, 20), 0.5, true);
    assert_eq!(restarts.get(), 1);
    assert_eq!(
        names(1),
        [
            "SuggestStructure",
            "Hold",
            "Weights",
            "Hold",
            "Weights",
            "Smooth"
        ],
        "the model went to every worker, then to the restarted one"
    );
    deliver.set(true);
    let (mut smoothed, mut answers) = (None, vec![None, None]);
    for _ in 0..20 {
        pool.pump();
        smoothed = smoothed.or_else(|| pool.take_smoothed(view));
        for (answer, job) in answers.iter_mut().zip(&structures) {
            *answer = answer.take().or_else(|| pool.take_structure_reply(*job));
        }
    }
    assert!(
        matches!(smoothed, Some(Reply::Smoothed { .. })),
        "{smoothed:?}"
    );
    for answer in &answers {
        assert!(
            matches!(answer, Some(Reply::Suggested { .. })),
            "{answer:?}"
        );
    }
    assert_eq!((restarts.get(), pool.restarts()), (1, 1));
    assert!(!pool.busy());
}

/// Workers on this thread with a hook in front: before each request the hook may give a reply
/// of its own (first in the replies), and says whether the request reaches the worker.
struct Hooked<F: FnMut(usize, &Request) -> (Option<Reply>, bool)> {
    inner: InThread,
    hook: F,
    replies: Vec<(usize, Reply)>,
}

impl<F: FnMut(usize, &Request) -> (Option<Reply>, bool)> Hooked<F> {
    fn new(workers: usize, hook: F) -> Self {
        Self {
            inner: InThread::new(workers),
            hook,
            replies: Vec::new(),
        }
    }
}

impl<F: FnMut(usize, &Request) -> (Option<Reply>, bool)> Carrier for Hooked<F> {
    fn workers(&self) -> usize {
        self.inner.workers()
    }
    fn post(&mut self, worker: usize, request: &Request) {
        let (reply, goes_on) = (self.hook)(worker, request);
        self.replies.extend(reply.map(|r| (worker, r)));
        if goes_on {
            self.inner.post(worker, request);
        }
    }
    fn take_replies(&mut self) -> Vec<(usize, Reply)> {
        let mut replies = std::mem::take(&mut self.replies);
        replies.extend(self.inner.take_replies());
        replies
    }
    fn threaded(&self) -> bool {
        false
    }
}

#[test]
fn a_workers_memory_is_kept_as_it_told_without_ending_its_job() {
    let original = sample();
    let m = model(&original, None, 0);
    // Each worker tells its memory before each answer, as the page's do.
    let telling = Hooked::new(2, |worker, _: &Request| {
        let bytes = 1000 * (worker as u64 + 1);
        (Some(Reply::Memory { bytes }), true)
    });
    let mut pool = Pool::new(Box::new(telling));
    assert_eq!(pool.memory(), [None, None], "nothing told yet");
    let job = pool.smooth(&m, &params(Filter::Hc, 3), 0.5, false);
    assert!(matches!(
        pool.take_smoothed(job),
        Some(Reply::Smoothed { .. })
    ));
    assert_eq!(pool.memory()[0], Some(1000), "{:?}", pool.memory());
    assert!(!pool.busy(), "the answer, not the memory, ended the job");
}

#[test]
fn a_broken_worker_fails_its_job_instead_of_holding_it() {
    let original = sample();
    let m = model(&original, None, 0);
    // The worker traps in its first job, then works.
    let mut trapped = false;
    let trapping = Hooked::new(1, move |_, request: &Request| {
        let job = matches!(request, Request::Smooth { .. } | Request::Terms { .. });
        if job && !trapped {
            trapped = true;
            let why = "unreachable executed".to_string();
            return (Some(Reply::Broken { why }), false);
        }
        (None, true)
    });
    let mut pool = Pool::new(Box::new(trapping));
    let broken = pool.smooth(&m, &params(Filter::Hc, 3), 0.5, false);
    let reply = pool.take_smoothed(broken);
    assert!(
        matches!(&reply, Some(Reply::Failed { why, .. }) if why.contains("unreachable")),
        "{reply:?}"
    );
    assert!(!pool.busy(), "the worker is free again");
    let next = pool.smooth(&m, &params(Filter::Hc, 3), 0.5, false);
    assert!(matches!(
        pool.take_smoothed(next),
        Some(Reply::Smoothed { .. })
    ));
}

/// A model built in a worker is the one built here: its mesh, report, edges, topology and
/// the original's measures.
fn assert_same_model(model: &Model, here: &Model) {
    assert_eq!(model.mesh(), here.mesh());
    assert_eq!((&model.report, &model.edges), (&here.report, &here.edges));
    assert_eq!(model.topology(), here.topology());
    assert_eq!(
        (model.original.curvature(), model.original.volume()),
        (here.original.curvature(), here.original.volume())
    );
}

#[test]
fn an_opening_in_a_worker_equals_opening_here_and_tells_its_stages() {
    let (carrier, deliver) = Deferred::new(2);
    let mut pool = Pool::new(Box::new(carrier));
    let job = pool.load(
        "tube.ply",
        Input::Files(vec![NamedFile {
            name: "tube.ply".into(),
            bytes: SAMPLE.to_vec(),
        }]),
    );
    assert!(pool.take_loaded(job).is_none() && pool.load_stage(job).is_none());
    deliver.set(true);
    pool.pump();
    let stage = pool.load_stage(job).expect("the worker told its stages");
    assert_eq!((stage.stage, stage.stages), (3, 4));
    assert_eq!(stage.doing, "measuring the original");
    let Some(Reply::Loaded {
        model: Some(model),
        case: Some(case),
        stages,
        ..
    }) = pool.take_loaded(job)
    else {
        panic!("no model and case came back");
    };
    let here = Model::load("tube.ply", SAMPLE).unwrap();
    assert_eq!(*case, here.case, "the file's case of one");
    assert_eq!(case.structures[0].name, "tube");
    assert_eq!(model.name, "tube.ply");
    assert_same_model(&model, &here.model);
    let names: Vec<&str> = stages.iter().map(|(doing, _)| doing.as_str()).collect();
    assert_eq!(
        names,
        [
            "reading the file",
            "building the topology",
            "checking the mesh",
            "measuring the original"
        ]
    );
    assert!(stages.iter().all(|(_, ms)| *ms >= 0.0));
    assert!(!pool.busy());
}

#[test]
fn a_file_to_add_comes_back_as_its_case_alone_after_its_reading_stage() {
    let mut pool = Pool::in_thread(1);
    let job = pool.load("tube.ply", Input::Add(SAMPLE.to_vec()));
    let Some(Reply::Loaded {
        model,
        case: Some(case),
        stages,
        ..
    }) = pool.take_loaded(job)
    else {
        panic!("no case came back");
    };
    assert!(
        model.is_none(),
        "no model is built for a file added to a case"
    );
    assert_eq!(*case, Model::load("tube.ply", SAMPLE).unwrap().case);
    let names: Vec<&str> = stages.iter().map(|(doing, _)| doing.as_str()).collect();
    assert_eq!(names, ["reading the file"]);
}

#[test]
fn a_structure_built_in_a_worker_equals_one_built_here_and_tells_its_stages() {
    let here = Model::load("tube.ply", SAMPLE).unwrap().model;
    let (carrier, deliver) = Deferred::new(2);
    let mut pool = Pool::new(Box::new(carrier));
    let job = pool.load("case: tube", Input::Structure(here.mesh().clone()));
    assert!(
        pool.take_loaded(job).is_none(),
        "nothing before the worker ran"
    );
    deliver.set(true);
    pool.pump();
    let Some(Reply::Loaded {
        model: Some(model),
        case: None,
        stages,
        ..
    }) = pool.take_loaded(job)
    else {
        panic!("no model alone came back");
    };
    assert_eq!(model.name, "case: tube");
    assert_same_model(&model, &here);
    let names: Vec<&str> = stages.iter().map(|(doing, _)| doing.as_str()).collect();
    assert_eq!(
        names,
        [
            "building the topology",
            "checking the mesh",
            "measuring the original"
        ]
    );
}

#[test]
fn a_forgotten_opening_leaves_no_answer_in_the_pool() {
    let mesh = Model::load("tube.ply", SAMPLE)
        .unwrap()
        .model
        .mesh()
        .clone();
    let (carrier, deliver) = Deferred::new(1);
    let mut pool = Pool::new(Box::new(carrier));
    // Forgotten while its worker builds it: the answer is dropped as it comes.
    let job = pool.load("case: tube", Input::Structure(mesh.clone()));
    pool.forget_load(job);
    deliver.set(true);
    pool.pump();
    assert!(!pool.has_loaded(job) && pool.load_stage(job).is_none());
    assert!(!pool.busy());
    // Forgotten after it came: dropped at once.
    let job = pool.load("case: tube", Input::Structure(mesh));
    pool.pump();
    assert!(pool.has_loaded(job));
    pool.forget_load(job);
    assert!(!pool.has_loaded(job) && pool.take_loaded(job).is_none());
}

#[test]
fn a_newer_opening_supersedes_an_older_and_a_bad_file_fails_its_job() {
    let (carrier, deliver) = Deferred::new(1);
    let mut pool = Pool::new(Box::new(carrier));
    let first = pool.load(
        "first.ply",
        Input::Files(vec![NamedFile {
            name: "first.ply".into(),
            bytes: SAMPLE.to_vec(),
        }]),
    );
    let second = pool.load(
        "second.ply",
        Input::Files(vec![NamedFile {
            name: "second.ply".into(),
            bytes: b"ply\nrubbish".to_vec(),
        }]),
    );
    deliver.set(true);
    let mut answers = Vec::new();
    for _ in 0..4 {
        answers.extend(pool.take_loaded(first).map(|r| ("first", r)));
        answers.extend(pool.take_loaded(second).map(|r| ("second", r)));
    }
    assert_eq!(answers.len(), 1, "{answers:?}");
    let ("second", Reply::Failed { why, .. }) = &answers[0] else {
        panic!("{answers:?}");
    };
    assert!(why.contains("PLY") || why.contains("ply"), "{why}");
    assert!(!pool.busy());
}

#[test]
fn codes_without_a_modifier_cross_the_wire() {
    // Postcard is not self-describing: a field left out when empty would not decode.
    let codes = (crate::segmentation::standard_class("liver").expect("coded")).codes;
    assert_eq!(codes.modifier, None);
    let back = decode::<crate::io::StructureCodes>(&encode(&codes));
    assert_eq!(back, Ok(codes));
}

/// Messages are postcard, which is not self-describing: a field left out when written (serde's
/// `skip_serializing_if`) would make the rest unreadable.
#[test]
fn a_lesson_crosses_to_a_worker_and_back_with_and_without_planes() {
    use crate::case::{Camera, Lesson, Step};
    let step = |planes| Step {
        title: "slices".into(),
        caption: String::new(),
        titles: Default::default(),
        captions: Default::default(),
        camera: Camera {
            target: [1.0, 2.0, 3.0],
            yaw: 0.5,
            pitch: 0.1,
            distance: 90.0,
        },
        hidden: vec!["kidney".into()],
        opacity: Default::default(),
        selected: None,
        clip: None,
        planes,
        toward_segmentation: 0.25,
    };
    let lesson = Lesson {
        steps: vec![step(Some(crate::view::Planes::default())), step(None)],
        ..Default::default()
    };
    let back: Lesson = decode(&encode(&lesson)).expect("decodes");
    assert_eq!(back, lesson);
}
