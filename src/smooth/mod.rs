//! The CPU smoothing engine: the reference every other path is checked against, and the
//! fallback where WebGPU is missing. Definitions: ALGORITHMS.md (shared docs).
//!
//! Every filter is a Jacobi update (each step reads the previous step's positions), always starts
//! from the original positions, honours per-vertex weights (0 locks a vertex) and the optional
//! displacement bound `d_max` around the original position.
//!
//! Layout: `umbrella` (Laplace, Taubin), `hc`, `sinc` with `sinc_coefficients`; the shared
//! neighbourhood view and neighbour mean in `rings`; weights and the bound in `constraint`.
//! Every pass runs in parallel over vertices (rayon; on wasm32 without threads it runs on the
//! calling thread) on f32 buffers allocated once per run.

mod constraint;
mod hc;
mod params;
mod rings;
mod sinc;
mod sinc_coefficients;
mod umbrella;

pub use params::{shortest, Filter, ParamError, Params};
// The GPU engine evaluates the same windowed-sinc series.
pub(crate) use sinc_coefficients::sinc_coefficients;

use crate::mesh::{Mesh, Topology};
use constraint::{Constrain, Free, Limits};
use rings::Rings;

/// Watches a smoothing run. The local-error measure drifts its reference vertices after every
/// step; sweeps over iterations measure along one run instead of restarting.
pub trait StepObserver {
    /// After every position update (Taubin: twice per iteration; HC: once per iteration).
    /// Windowed sinc's running sums between terms are not meshes, so it reports its result
    /// once per degree (one step per neighbour pass) after the last term.
    fn after_step(&mut self, _positions: &[[f32; 3]]) {}
    /// After iteration `iteration` (1-based) of a filter whose k-iteration result is the result
    /// of smoothing with k iterations (Laplace, Taubin, HC). Windowed sinc's intermediate terms
    /// are not a shorter filter's result, so it reports only its final iteration.
    fn after_iteration(&mut self, _iteration: u32, _positions: &[[f32; 3]]) {}
}

/// An observer that watches nothing.
pub struct NoObserver;
impl StepObserver for NoObserver {}

/// Smooths `mesh` with `params` from its original positions and returns the new positions
/// (same vertex order). `weights`, when given, has one entry in [0, 1] per vertex.
///
/// Observer calls: Laplace and HC report `after_step` then `after_iteration` once per
/// iteration, Taubin `after_step` twice per iteration; windowed sinc reports `after_step` once
/// per term (`iterations` times) and `after_iteration(iterations, ..)` once at the end.
/// With zero iterations nothing is reported and the original positions come back.
///
/// Windowed sinc applies weights and `max_displacement` to its running estimate's total
/// displacement from the original (its recurrence must run unconstrained); the other filters
/// apply them after every step, as ALGORITHMS.md defines.
///
/// `params` should pass [`Params::validate`]; out-of-range values do not panic but give
/// results that mean little. `topology` must be built from `mesh`: if it describes a different
/// vertex count, nothing moves.
pub fn smooth(
    mesh: &Mesh,
    topology: &Topology,
    params: &Params,
    weights: Option<&[f32]>,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let original = &mesh.positions;
    let Some(rings) = Rings::new(topology, original.len()) else {
        return original.clone();
    };
    match Limits::new(weights, params.max_displacement, original) {
        None => run(rings, original, params, &Free, observer),
        Some(limits) => run(rings, original, params, &limits, observer),
    }
}

fn run<C: Constrain>(
    rings: Rings,
    original: &[[f32; 3]],
    p: &Params,
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let it = p.iterations;
    match p.filter {
        Filter::Laplace => umbrella::run(rings, original, &[p.lambda], it, constraint, observer),
        Filter::Taubin => {
            umbrella::run(rings, original, &[p.lambda, p.mu], it, constraint, observer)
        }
        Filter::Hc => hc::run(rings, original, p.alpha, p.beta, it, constraint, observer),
        Filter::Sinc => sinc::run(rings, original, p.passband, it, constraint, observer),
    }
}
