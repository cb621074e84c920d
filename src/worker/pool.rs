//! The asking side of the engine workers: the queue, which worker does what, and the answers.
//! Jobs are handed out one per worker at a time, so a job that a newer one supersedes while it
//! waits is simply never handed out; a worker is never interrupted, but for the view worker
//! lent to "Suggest all" (`view_worker`), restarted when the view needs it. The model and weights
//! go to every worker once (each holds the model), so a search's parameter sets spread over the
//! pool.

use std::collections::{HashMap, VecDeque};

use super::{InThread, Input, Reply, Request};

mod terms;
mod view_worker;
use crate::case::{Case, SuggestAllOptions};
use crate::evaluate::{ModelRef, Request as TermsRequest, Terms};
use crate::mesh::Mesh;
use crate::smooth::Params;

/// Carries requests to workers and brings their replies back.
pub trait Carrier {
    /// How many workers there are (at least one).
    fn workers(&self) -> usize;
    /// Sends `request` to worker `worker` (they do their requests in order).
    fn post(&mut self, worker: usize, request: &Request);
    /// The replies that arrived since the last call, with the worker each came from.
    fn take_replies(&mut self) -> Vec<(usize, Reply)>;
    /// Whether the workers run on other threads (else each request blocks its caller).
    fn threaded(&self) -> bool;
    /// Whether [`Self::restart`] can stop a worker in the middle of its job.
    fn restartable(&self) -> bool {
        false
    }
    /// Stops `worker` whatever it is doing and starts it afresh, holding nothing; no reply of
    /// the old one comes after. Returns whether it did.
    fn restart(&mut self, _worker: usize) -> bool {
        false
    }
}

/// A smoothing job: the model smoothed and measured (the view's result, a gallery pick).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SmoothJob(u64);

/// A job on a case's structures that needs no model held: one structure's part of "Suggest
/// all", or the checks between the structures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StructureJob(u64);

/// An opening: a file or structure made a model in a worker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadJob(u64);

/// How far an opening got: the stage under way (0-based) of `stages`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadStage {
    pub stage: u32,
    pub stages: u32,
    pub doing: String,
}

/// A terms request as a key: the model, its weights and the request's encoding.
type TermsKey = (u64, u64, Vec<u8>);

struct QueuedSmooth {
    job: u64,
    params: Params,
    tau: f64,
    /// Dropped from the queue by the next superseding job.
    supersedable: bool,
}

/// What a worker is doing.
enum Flight {
    Load,
    Smooth,
    Structure,
    Terms(TermsKey),
}

/// The engine workers seen from the page: the opening asked last (first), a queue of smoothing
/// jobs, and the guidance's terms requests (the one asked, then the ones it said come next),
/// handed out to idle workers.
pub struct Pool {
    carrier: Box<dyn Carrier>,
    /// The job each worker is doing.
    busy: Vec<Option<u64>>,
    /// The model and weights version every worker was sent.
    sent: Option<(u64, u64)>,
    next_job: u64,
    /// An opening not handed out yet.
    load: Option<(u64, Request)>,
    /// How many openings were asked for.
    openings: u64,
    /// How many times the view worker was taken back from a structure of "Suggest all".
    restarts: u64,
    loaded: HashMap<u64, Reply>,
    load_stages: HashMap<u64, LoadStage>,
    smooths: VecDeque<QueuedSmooth>,
    /// "Suggest all"'s structures not handed out yet, and their answers.
    structure_jobs: VecDeque<(u64, Request)>,
    suggested: HashMap<u64, Reply>,
    /// The terms request asked last and those to come, in order.
    asked: Option<TermsKey>,
    upcoming: Vec<TermsKey>,
    in_flight: HashMap<u64, Flight>,
    smoothed: HashMap<u64, Reply>,
    terms: HashMap<TermsKey, Result<Vec<Terms>, String>>,
    /// Whether the last terms request was not answered yet.
    waiting: bool,
    failure: Option<String>,
    /// The worker kept for the view's smoothing and openings, so a change of parameters never
    /// waits behind a guidance task or a structure of "Suggest all".
    view_worker: Option<usize>,
    /// Each worker's memory as it last told ([`Reply::Memory`]); none on this thread.
    memory: Vec<Option<u64>>,
    /// The structure of "Suggest all" lent to the view worker, and its request, to queue again
    /// when the view takes its worker back.
    lent: Option<(u64, Request)>,
}

/// One worker on this thread.
impl Default for Pool {
    fn default() -> Self {
        Self::in_thread(1)
    }
}

impl Pool {
    pub fn new(carrier: Box<dyn Carrier>) -> Self {
        let workers = carrier.workers().max(1);
        Self {
            carrier,
            busy: vec![None; workers],
            memory: vec![None; workers],
            lent: None,
            sent: None,
            next_job: 0,
            load: None,
            openings: 0,
            restarts: 0,
            loaded: HashMap::new(),
            load_stages: HashMap::new(),
            smooths: VecDeque::new(),
            structure_jobs: VecDeque::new(),
            suggested: HashMap::new(),
            asked: None,
            upcoming: Vec::new(),
            in_flight: HashMap::new(),
            smoothed: HashMap::new(),
            terms: HashMap::new(),
            waiting: false,
            failure: None,
            view_worker: None,
        }
    }

    /// A pool whose last worker is kept for the view (its smoothing, openings): the others do
    /// the background's work (the guidance's terms, "Suggest all", checks) and, when idle, the
    /// view's too. Needs two workers at least, else it is [`Self::new`].
    pub fn with_view_worker(carrier: Box<dyn Carrier>) -> Self {
        let mut pool = Self::new(carrier);
        let workers = pool.busy.len();
        pool.view_worker = (workers >= 2).then_some(workers - 1);
        pool
    }

    /// A pool of `workers` on this thread.
    pub fn in_thread(workers: usize) -> Self {
        Self::new(Box::new(InThread::new(workers)))
    }

    /// The workers that do the background's work (all of them, but a view worker).
    pub fn workers(&self) -> usize {
        self.busy.len() - usize::from(self.view_worker.is_some())
    }

    /// Whether the workers run beside the caller's thread (else each job blocks it).
    pub fn threaded(&self) -> bool {
        self.carrier.threaded()
    }

    /// Each worker's memory in bytes as it last told (its peak), the view worker's last;
    /// `None` for a worker that has not told (workers on this thread never do).
    pub fn memory(&self) -> &[Option<u64>] {
        &self.memory
    }

    /// Whether a worker is kept for the view's smoothing and openings.
    pub fn has_view_worker(&self) -> bool {
        self.view_worker.is_some()
    }

    /// How many times the view worker was restarted to take it back from "Suggest all".
    pub fn restarts(&self) -> u64 {
        self.restarts
    }

    /// How many openings were asked of the workers.
    pub fn openings(&self) -> u64 {
        self.openings
    }

    /// Whether any worker is doing something or anything waits to be handed out.
    pub fn busy(&self) -> bool {
        self.busy.iter().any(Option::is_some)
            || !self.smooths.is_empty()
            || !self.structure_jobs.is_empty()
            || self.load.is_some()
    }

    /// Queues one structure's part of "Suggest all" (after the view's smoothing, before the
    /// guidance's terms): it needs no model held, so structures spread over the pool.
    pub fn suggest_structure(
        &mut self,
        mesh: Mesh,
        params: Params,
        weights: Option<Vec<f32>>,
        options: SuggestAllOptions,
        starts: Vec<Params>,
    ) -> StructureJob {
        let job = self.new_job();
        let request = Request::SuggestStructure {
            job,
            mesh,
            params,
            weights,
            options,
            starts,
        };
        self.structure_jobs.push_back((job, request));
        self.pump();
        StructureJob(job)
    }

    /// Queues the checks between `case`'s structures, as opened and as shown (with the
    /// structures' jobs).
    pub fn check_case(&mut self, mut case: Case) -> StructureJob {
        // The checks read the surfaces only: the image need not travel.
        case.image = None;
        let job = self.new_job();
        let request = Request::CheckCase {
            job,
            case: Box::new(case),
        };
        self.structure_jobs.push_back((job, request));
        self.pump();
        StructureJob(job)
    }

    /// The answer to `job` once it is there ([`Reply::Suggested`], [`Reply::Checked`] or
    /// [`Reply::Failed`]).
    pub fn take_structure_reply(&mut self, job: StructureJob) -> Option<Reply> {
        self.pump();
        self.suggested.remove(&job.0)
    }

    /// Drops `jobs` still waiting and stops waiting for those under way (cancel).
    pub fn forget_structures(&mut self, jobs: &[StructureJob]) {
        for job in jobs {
            self.structure_jobs.retain(|(j, _)| *j != job.0);
            self.in_flight.remove(&job.0);
            self.suggested.remove(&job.0);
        }
    }

    /// Queues opening `input` as a model named `name`, ahead of every other job. It supersedes
    /// an opening still waiting or under way (whose answer is then dropped).
    pub fn load(&mut self, name: &str, input: Input) -> LoadJob {
        // Every opening waiting or in flight is superseded.
        let waiting = self.load.as_ref().map(|(job, _)| *job);
        let in_flight = (self.in_flight.iter())
            .filter(|(_, f)| matches!(f, Flight::Load))
            .map(|(job, _)| *job);
        let superseded: Vec<u64> = waiting.into_iter().chain(in_flight).collect();
        for job in superseded {
            self.forget_load(LoadJob(job));
        }
        self.loaded.clear();
        let job = self.new_job();
        let name = name.to_string();
        self.load = Some((job, Request::Load { job, name, input }));
        self.openings += 1;
        self.pump();
        if self.load.is_some() && self.reclaim_view_worker() {
            // The new worker holds no model: the next model goes to every worker again.
            self.sent = None;
            self.pump();
        }
        LoadJob(job)
    }

    /// Stops waiting for `job` (an opening no longer wanted): dropped if it still waits, its
    /// answer dropped when it comes, or now if it came.
    pub fn forget_load(&mut self, job: LoadJob) {
        if self.load.as_ref().is_some_and(|(j, _)| *j == job.0) {
            self.load = None;
        }
        if matches!(self.in_flight.get(&job.0), Some(Flight::Load)) {
            self.in_flight.remove(&job.0);
        }
        self.loaded.remove(&job.0);
        self.load_stages.remove(&job.0);
    }

    /// The answer to `job` once it is there ([`Reply::Loaded`] or [`Reply::Failed`]).
    pub fn take_loaded(&mut self, job: LoadJob) -> Option<Reply> {
        self.pump();
        let reply = self.loaded.remove(&job.0);
        if reply.is_some() {
            self.load_stages.remove(&job.0);
        }
        reply
    }

    /// Whether `job`'s reply came (as of the last pump), to be taken with [`Self::take_loaded`].
    pub fn has_loaded(&self, job: LoadJob) -> bool {
        self.loaded.contains_key(&job.0)
    }

    /// The stage `job` is at, once its worker began it.
    pub fn load_stage(&self, job: LoadJob) -> Option<&LoadStage> {
        self.load_stages.get(&job.0)
    }

    /// Queues smoothing `model` with `params` and measuring the result at `tau`. A
    /// `supersedable` job replaces the supersedable ones still waiting (the view's result for
    /// older parameters).
    pub fn smooth(
        &mut self,
        model: &ModelRef<'_>,
        params: &Params,
        tau: f64,
        supersedable: bool,
    ) -> SmoothJob {
        self.sync(model);
        if supersedable {
            self.smooths.retain(|s| !s.supersedable);
        }
        let job = self.new_job();
        self.smooths.push_back(QueuedSmooth {
            job,
            params: *params,
            tau,
            supersedable,
        });
        self.pump();
        if !self.smooths.is_empty() && self.reclaim_view_worker() {
            self.send_model(model);
            self.pump();
        }
        SmoothJob(job)
    }

    /// The reply to `job` once it is there ([`Reply::Smoothed`] or [`Reply::Failed`]).
    pub fn take_smoothed(&mut self, job: SmoothJob) -> Option<Reply> {
        self.pump();
        let reply = self.smoothed.remove(&job.0);
        self.waiting = reply.is_none();
        reply
    }

    /// Whether the last answer asked of the pool (terms or a smoothing) is still to come.
    pub fn waiting(&self) -> bool {
        self.waiting
    }

    /// Whether `job` is waiting, under way, or answered and not taken yet.
    pub fn pending(&self, job: SmoothJob) -> bool {
        self.smooths.iter().any(|s| s.job == job.0)
            || self.in_flight.contains_key(&job.0)
            || self.smoothed.contains_key(&job.0)
    }

    /// Stops waiting for `job` (its reply, should it come, is dropped).
    pub fn forget(&mut self, job: SmoothJob) {
        self.smooths.retain(|s| s.job != job.0);
        self.in_flight.remove(&job.0);
        self.smoothed.remove(&job.0);
    }

    /// Forgets that an answer is awaited (a caller about to ask again).
    pub fn clear_waiting(&mut self) {
        self.waiting = false;
    }

    /// Forgets the terms requests asked and to come: the guidance has no job.
    pub fn clear_guidance(&mut self) {
        self.asked = None;
        self.upcoming.clear();
        self.waiting = false;
    }

    fn new_job(&mut self) -> u64 {
        self.next_job += 1;
        self.next_job
    }

    /// Collects the replies and hands out work to the idle workers.
    pub fn pump(&mut self) {
        loop {
            for (worker, reply) in self.carrier.take_replies() {
                self.receive(worker, reply);
            }
            let mut idle: Vec<usize> = (0..self.busy.len())
                .filter(|&w| self.busy[w].is_none())
                .collect();
            // The view's jobs go to the view worker first, leaving the others to the rest.
            idle.sort_by_key(|&w| Some(w) != self.view_worker);
            // One job per pass: a worker on this thread answers at once, and frees itself.
            if !idle.into_iter().any(|worker| self.hand_out(worker)) {
                return;
            }
        }
    }

    fn receive(&mut self, worker: usize, reply: Reply) {
        if let Reply::Memory { bytes } = reply {
            if let Some(slot) = self.memory.get_mut(worker) {
                *slot = Some(bytes);
            }
            return;
        }
        if let Reply::Progress {
            job,
            stage,
            stages,
            doing,
        } = reply
        {
            if self.in_flight.contains_key(&job) {
                let stage = LoadStage {
                    stage,
                    stages,
                    doing,
                };
                self.load_stages.insert(job, stage);
            }
            return;
        }
        let doing = self.busy.get_mut(worker).and_then(Option::take);
        // A broken worker's job fails; the worker stays, and fails again if it cannot go on.
        let (job, reply) = match reply {
            Reply::Broken { why } => match doing {
                Some(job) => (job, Reply::Failed { job, why }),
                None => return,
            },
            other => match other.job() {
                Some(job) => (job, other),
                None => return,
            },
        };
        if self.lent.as_ref().is_some_and(|(lent, _)| *lent == job) {
            self.lent = None;
        }
        match self.in_flight.remove(&job) {
            Some(Flight::Load) => {
                self.loaded.insert(job, reply);
            }
            Some(Flight::Smooth) => {
                self.smoothed.insert(job, reply);
            }
            Some(Flight::Structure) => {
                self.suggested.insert(job, reply);
            }
            Some(Flight::Terms(key)) => {
                let answer = match reply {
                    Reply::Terms { terms, .. } => Ok(terms),
                    Reply::Failed { why, .. } => Err(why),
                    _ => Err("a smoothing answered a terms request".into()),
                };
                self.terms.insert(key, answer);
            }
            // Superseded or for another model.
            None => {}
        }
    }

    /// Gives `worker` the next job: an opening first, then a smoothing, then a structure of
    /// "Suggest all" or checks (the view worker only a structure, and only when it can be
    /// restarted), then the terms asked, then those to come. Returns whether there was one.
    fn hand_out(&mut self, worker: usize) -> bool {
        if let Some((job, request)) = self.load.take() {
            self.start(worker, job, Flight::Load, &request);
            return true;
        }
        if let Some(s) = self.smooths.pop_front() {
            let request = Request::Smooth {
                job: s.job,
                params: s.params,
                tau: s.tau,
            };
            self.start(worker, s.job, Flight::Smooth, &request);
            return true;
        }
        if self.view_worker == Some(worker) {
            return self.lend_view_worker(worker);
        }
        if let Some((job, request)) = self.structure_jobs.pop_front() {
            self.start(worker, job, Flight::Structure, &request);
            return true;
        }
        let in_flight: Vec<&TermsKey> = self
            .in_flight
            .values()
            .filter_map(|f| match f {
                Flight::Terms(k) => Some(k),
                Flight::Load | Flight::Smooth | Flight::Structure => None,
            })
            .collect();
        let next = self
            .asked
            .iter()
            .chain(&self.upcoming)
            .find(|k| !self.terms.contains_key(*k) && !in_flight.contains(k))
            .cloned();
        let Some(key) = next else {
            return false;
        };
        let Ok((params, at)) = super::decode::<TermsRequest>(&key.2) else {
            return false;
        };
        let job = self.new_job();
        let request = Request::Terms { job, params, at };
        self.start(worker, job, Flight::Terms(key), &request);
        true
    }

    fn start(&mut self, worker: usize, job: u64, flight: Flight, request: &Request) {
        self.busy[worker] = Some(job);
        self.in_flight.insert(job, flight);
        self.carrier.post(worker, request);
    }
}
