//! A carrier for tests that holds every request until told to deliver, as busy workers do.

use std::cell::Cell;
use std::rc::Rc;

use super::{Carrier, InThread, Reply, Request};

pub(crate) struct Deferred {
    inner: InThread,
    posted: Vec<(usize, Request)>,
    deliver: Rc<Cell<bool>>,
}

impl Deferred {
    /// `workers` workers on this thread, and the switch that lets their requests through.
    pub(crate) fn new(workers: usize) -> (Self, Rc<Cell<bool>>) {
        let deliver = Rc::new(Cell::new(false));
        let carrier = Self {
            inner: InThread::new(workers),
            posted: Vec::new(),
            deliver: deliver.clone(),
        };
        (carrier, deliver)
    }
}

impl Carrier for Deferred {
    fn workers(&self) -> usize {
        self.inner.workers()
    }

    fn post(&mut self, worker: usize, request: &Request) {
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
        false
    }
}
