//! The view worker lent to "Suggest all": idle while nothing is dragged, it takes structures
//! too, and is restarted when the view needs it back.

use super::{Flight, Pool};
use crate::evaluate::ModelRef;
use crate::worker::Request;

impl Pool {
    /// The idle view worker takes a structure of "Suggest all" when its carrier can restart
    /// it: should the view need it meanwhile, it costs a restart instead of a wait for the
    /// structure. Returns whether it took one.
    pub(super) fn lend_view_worker(&mut self, worker: usize) -> bool {
        if !self.carrier.restartable() {
            return false;
        }
        let suggestion = (self.structure_jobs.iter())
            .position(|(_, r)| matches!(r, Request::SuggestStructure { .. }));
        let Some((job, request)) = suggestion.and_then(|i| self.structure_jobs.remove(i)) else {
            return false;
        };
        self.start(worker, job, Flight::Structure, &request);
        self.lent = Some((job, request));
        true
    }

    /// Takes the view worker back from the structure it was lent, when no other worker is
    /// free: restarts it and queues the structure again first (unless it was forgotten).
    /// Returns whether it did; the new worker then holds no model.
    pub(super) fn reclaim_view_worker(&mut self) -> bool {
        let Some(view) = self.view_worker else {
            return false;
        };
        let Some((job, request)) = self.lent.take() else {
            return false;
        };
        let lent_still = self.busy[view] == Some(job);
        let any_idle = self.busy.iter().any(Option::is_none);
        if !lent_still || any_idle || !self.carrier.restart(view) {
            self.lent = lent_still.then_some((job, request));
            return false;
        }
        self.busy[view] = None;
        self.memory[view] = None;
        self.restarts += 1;
        if self.in_flight.remove(&job).is_some() {
            self.structure_jobs.push_front((job, request));
        }
        true
    }

    /// Sends the model and weights the pool sent every worker to the restarted view worker.
    pub(super) fn send_model(&mut self, model: &ModelRef<'_>) {
        let Some(view) = self.view_worker else {
            return;
        };
        self.carrier.post(view, &super::terms::hold_request(model));
        self.carrier
            .post(view, &super::terms::weights_request(model));
    }
}
