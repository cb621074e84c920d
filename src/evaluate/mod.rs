//! What an engine that smooths and measures answers: the score [`Terms`] of a parameter set
//! after given iteration counts, through the [`Evaluator`] interface (or [`Offload`], for an
//! evaluator kept across models).
//!
//! It sits below both the engines ([`crate::gpu`]'s evaluator, the CPU one in
//! [`crate::suggest`]) and the searches that use them ([`crate::suggest`]), so an engine
//! implements it without depending on the search logic.

mod offload;
mod terms;

pub use offload::{ModelRef, Offload, Offloaded};
pub use terms::{failed_terms, terms_of, unchanged_terms, Goal, Rank, Terms};

pub(crate) use terms::same;

use crate::smooth::{Filter, Params};

/// Smooths and measures. Implementations: the real engine ([`crate::smooth`] plus
/// [`crate::metrics`]) and synthetic functions in tests.
pub trait Evaluator {
    /// Smooths with `params` (its `iterations` field is ignored) and returns the terms after each
    /// iteration count in `at` (ascending, distinct; 0 means the unchanged mesh), in that order.
    ///
    /// For filters whose k-iteration result is a prefix of a longer run (all but windowed sinc)
    /// this is one run measured along the way; callers pass sinc one count at a time.
    ///
    /// `None` means the run is under way but not finished: the caller asks again, with the same
    /// request, later. Evaluators that spread a run over several calls (the web app's frames)
    /// use it; the others always answer.
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>>;

    /// [`Self::measure`], where the evaluator may leave out the local error (which needs the
    /// drifting reference along the run and about half of each measure): such terms hold a
    /// mean error of 0, below the true one, and the flag beside them is `false`. Their score is
    /// then a lower bound of the true score (the other terms are exact), which lets a search
    /// rule parameter sets out before measuring them fully
    /// ([`GridMinimum`](crate::suggest::GridMinimum)). By default every answer is exact.
    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        let terms = self.measure(params, at)?;
        Some(terms.into_iter().map(|t| (t, true)).collect())
    }

    /// Whether this evaluator does better knowing the requests to come ([`Self::prefetch`]):
    /// one that answers a frame later (the GPU's) batches them.
    fn wants_prefetch(&self) -> bool {
        false
    }

    /// The requests the caller will make after the next one, in order, as far as it knows
    /// them. Only a hint: what is asked later is answered either way.
    fn prefetch(&mut self, _requests: &[Request]) {}
}

/// An evaluator lent by reference (to wrap it, as [`Memoized`](crate::suggest::Memoized) does).
impl<E: Evaluator + ?Sized> Evaluator for &mut E {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        (**self).measure(params, at)
    }

    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        (**self).measure_bounds(params, at)
    }

    fn wants_prefetch(&self) -> bool {
        (**self).wants_prefetch()
    }

    fn prefetch(&mut self, requests: &[Request]) {
        (**self).prefetch(requests)
    }
}

/// One [`Evaluator::measure`] request: parameters and iteration counts.
pub type Request = (Params, Vec<u32>);

/// Whether the k-iteration result of `filter` is the state after k iterations of a longer run.
/// Windowed sinc's iteration count is the degree of its polynomial, so each count is its own run.
pub fn is_cumulative(filter: Filter) -> bool {
    filter != Filter::Sinc
}
