//! What a search asks of the pool: the model and its weights sent to every worker once, and the
//! terms of parameter sets asked (and prefetched) by key.

use super::{Flight, Pool, Request, TermsKey};
use crate::evaluate::{failed_terms, ModelRef, Offload, Request as TermsRequest, Terms};
use crate::smooth::Params;

impl Pool {
    /// Sends the model and weights to every worker when they are not the ones sent last.
    pub(super) fn sync(&mut self, model: &ModelRef<'_>) {
        let want = (model.id, model.weights_version);
        if self.sent == Some(want) {
            return;
        }
        if self.sent.map(|s| s.0) != Some(model.id) {
            self.broadcast(&hold_request(model));
            // Whatever waits is for another model (an opening stays: it makes the next one).
            self.smooths.clear();
            self.in_flight
                .retain(|_, f| matches!(f, Flight::Load | Flight::Structure));
            self.smoothed.clear();
            self.terms.clear();
        }
        if self.sent.is_none_or(|s| s.1 != model.weights_version) {
            self.broadcast(&weights_request(model));
            self.terms.clear();
            self.asked = None;
            self.upcoming.clear();
        }
        self.sent = Some(want);
    }

    fn broadcast(&mut self, request: &Request) {
        for worker in 0..self.busy.len() {
            self.carrier.post(worker, request);
        }
    }

    pub(super) fn key(model: &ModelRef<'_>, params: &Params, at: &[u32]) -> TermsKey {
        let request: TermsRequest = (*params, at.to_vec());
        (
            model.id,
            model.weights_version,
            crate::worker::encode(&request),
        )
    }
}

impl Offload for Pool {
    fn measure(&mut self, model: &ModelRef<'_>, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        self.sync(model);
        let key = Self::key(model, params, at);
        self.asked = Some(key.clone());
        self.pump();
        let answer = self.terms.remove(&key);
        self.waiting = answer.is_none();
        match answer? {
            Ok(terms) => Some(terms),
            Err(why) => {
                self.failure = Some(why);
                Some(failed_terms(at.len()))
            }
        }
    }

    fn prefetch(&mut self, model: &ModelRef<'_>, requests: &[TermsRequest]) {
        self.sync(model);
        self.upcoming = requests
            .iter()
            .map(|(params, at)| Self::key(model, params, at))
            .collect();
        self.pump();
    }

    fn wants_prefetch(&self) -> bool {
        true
    }

    fn waiting(&self) -> bool {
        Pool::waiting(self)
    }

    fn failure(&self) -> Option<String> {
        self.failure.clone()
    }
}

/// The request that gives a worker the model to hold.
pub(super) fn hold_request(model: &ModelRef<'_>) -> Request {
    Request::Hold {
        model: model.id,
        mesh: model.original.mesh().clone(),
    }
}

/// The request that gives a worker the model's weights.
pub(super) fn weights_request(model: &ModelRef<'_>) -> Request {
    Request::Weights {
        model: model.id,
        version: model.weights_version,
        weights: model.weights.map(<[f32]>::to_vec),
    }
}
