//! The engine workers on the calling thread, for the native tests and callers.

use super::{Carrier, Reply, Request, Worker};

/// Workers on the calling thread: each request is done as it is posted. The native tests and
/// the CLI-like callers use it; the page has real workers.
pub struct InThread {
    workers: Vec<Worker>,
    replies: Vec<(usize, Reply)>,
}

impl InThread {
    pub fn new(workers: usize) -> Self {
        Self {
            workers: (0..workers.max(1)).map(|_| Worker::default()).collect(),
            replies: Vec::new(),
        }
    }

    /// Starts `worker` afresh, holding nothing, its replies not taken yet dropped (a test
    /// carrier's restart: a job here is done the moment it is posted).
    #[cfg(test)]
    pub(crate) fn restart(&mut self, worker: usize) {
        self.workers[worker] = Worker::default();
        self.replies.retain(|(w, _)| *w != worker);
    }
}

impl Carrier for InThread {
    fn workers(&self) -> usize {
        self.workers.len()
    }

    fn post(&mut self, worker: usize, request: &Request) {
        // Through the wire format, as the page's messages go.
        let request = match super::decode::<Request>(&super::encode(request)) {
            Ok(request) => request,
            Err(why) => return self.replies.push((worker, Reply::Broken { why })),
        };
        let mut told = Vec::new();
        let reply = self.workers[worker].handle(request, &super::clock_ms, &mut |r| told.push(r));
        // As the page does: a reply that does not decode breaks the worker's job.
        let wired = (told.iter().chain(&reply))
            .map(|r| super::decode(&super::encode(r)).unwrap_or_else(|why| Reply::Broken { why }));
        self.replies.extend(wired.map(|r| (worker, r)));
    }

    fn take_replies(&mut self) -> Vec<(usize, Reply)> {
        std::mem::take(&mut self.replies)
    }

    fn threaded(&self) -> bool {
        false
    }
}
