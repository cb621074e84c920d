//! A carrier for tests that holds every request until told to deliver, as busy workers do.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use super::{Carrier, InThread, Reply, Request};

pub(crate) struct Deferred {
    inner: InThread,
    posted: Vec<(usize, Request)>,
    deliver: Rc<Cell<bool>>,
    log: Log,
    threaded: bool,
    /// Restarts so far, when it can restart a worker ([`Self::restarting`]).
    restarts: Option<Rc<Cell<usize>>>,
}

/// Which worker was sent which request, in order.
pub(crate) type Log = Rc<RefCell<Vec<(usize, Request)>>>;

impl Deferred {
    /// `workers` workers on this thread, and the switch that lets their requests through.
    pub(crate) fn new(workers: usize) -> (Self, Rc<Cell<bool>>) {
        let (carrier, deliver, _) = Self::logged(workers);
        (carrier, deliver)
    }

    /// [`Self::new`], with the log of every request posted.
    pub(crate) fn logged(workers: usize) -> (Self, Rc<Cell<bool>>, Log) {
        let deliver = Rc::new(Cell::new(false));
        let log = Log::default();
        let carrier = Self {
            inner: InThread::new(workers),
            posted: Vec::new(),
            deliver: deliver.clone(),
            log: log.clone(),
            threaded: false,
            restarts: None,
        };
        (carrier, deliver, log)
    }

    /// Can restart a worker as the page's can: its requests not yet delivered are dropped
    /// and it starts afresh. Returns the count of restarts.
    pub(crate) fn restarting(&mut self) -> Rc<Cell<usize>> {
        self.restarts.get_or_insert_with(Rc::default).clone()
    }

    /// Says it runs in workers of its own, as the page's do: their replies come between
    /// frames, and the page steps the engine then; the session builds a large structure's
    /// model in them.
    pub(crate) fn in_workers(mut self) -> Self {
        self.threaded = true;
        self
    }
}

impl Carrier for Deferred {
    fn workers(&self) -> usize {
        self.inner.workers()
    }

    fn post(&mut self, worker: usize, request: &Request) {
        self.log.borrow_mut().push((worker, request.clone()));
        self.posted.push((worker, request.clone()));
    }

    fn take_replies(&mut self) -> Vec<(usize, Reply)> {
        if !self.deliver.get() {
            return Vec::new();
        }
        for (w, r) in std::mem::take(&mut self.posted) {
            self.inner.post(w, &r);
        }
        self.inner.take_replies()
    }

    fn threaded(&self) -> bool {
        self.threaded
    }

    fn restartable(&self) -> bool {
        self.restarts.is_some()
    }

    fn restart(&mut self, worker: usize) -> bool {
        let Some(restarts) = &self.restarts else {
            return false;
        };
        restarts.set(restarts.get() + 1);
        self.posted.retain(|(w, _)| *w != worker);
        self.inner.restart(worker);
        true
    }
}
