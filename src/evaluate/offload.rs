//! Evaluators kept across calls and models: the GPU's, which holds the mesh on the device and
//! its runs in flight between the web app's frames. The guidance lends one the model of the
//! moment with every request ([`Offloaded`]), so one evaluator serves every job and model.

use super::{Evaluator, Request, Terms};
use crate::metrics::Original;
use crate::smooth::Params;

/// The model a request is for: its original, an id that changes when another model is opened,
/// and the weights with a version that changes when they do.
#[derive(Clone, Copy)]
pub struct ModelRef<'a> {
    pub original: &'a Original,
    pub id: u64,
    pub weights: Option<&'a [f32]>,
    pub weights_version: u64,
}

/// [`Evaluator::measure`] for a model lent with each request.
pub trait Offload {
    /// The terms of `params` after each count in `at` on `model`; `None` while the run is under
    /// way (ask again with the same request). A request that differs from the one under way
    /// abandons it. When the evaluator fails (a lost device) it answers NaN terms
    /// ([`super::failed_terms`]), which rank last, and [`Offload::failure`] says why.
    fn measure(&mut self, model: &ModelRef<'_>, params: &Params, at: &[u32]) -> Option<Vec<Terms>>;

    /// The requests that will follow the next one for `model` (see [`Evaluator::prefetch`]).
    fn prefetch(&mut self, _model: &ModelRef<'_>, _requests: &[Request]) {}

    /// Whether [`Offload::prefetch`] is of use.
    fn wants_prefetch(&self) -> bool {
        false
    }

    /// Whether a run is on the device and this thread has nothing to do for it until the next
    /// call (the browser delivers the results between frames).
    fn waiting(&self) -> bool;

    /// Why the evaluator stopped working, once it has.
    fn failure(&self) -> Option<String>;
}

/// An [`Offload`] lent one model: an [`Evaluator`] for the tasks.
pub struct Offloaded<'a> {
    pub offload: &'a mut dyn Offload,
    pub model: ModelRef<'a>,
}

impl Evaluator for Offloaded<'_> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        self.offload.measure(&self.model, params, at)
    }

    fn wants_prefetch(&self) -> bool {
        self.offload.wants_prefetch()
    }

    fn prefetch(&mut self, requests: &[Request]) {
        self.offload.prefetch(&self.model, requests);
    }
}
