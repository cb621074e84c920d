//! The CPU smoothing engine: the reference every other path is checked against, and the
//! fallback where WebGPU is missing. Definitions: ALGORITHMS.md (shared docs).
//!
//! Every filter is a Jacobi update (each step reads the previous step's positions), always starts
//! from the original positions, honours per-vertex weights (0 locks a vertex) and the optional
//! displacement bound `d_max` around the original position.

mod params;

pub use params::{Filter, ParamError, Params};

use crate::mesh::{Mesh, Topology};

/// Watches a smoothing run. The local-error measure drifts its reference vertices after every
/// step; sweeps over iterations measure along one run instead of restarting.
pub trait StepObserver {
    /// After every position update (Taubin: twice per iteration; HC: once per iteration).
    /// Windowed sinc reports its running filtered estimate after each recurrence term.
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
pub fn smooth(
    mesh: &Mesh,
    topology: &Topology,
    params: &Params,
    weights: Option<&[f32]>,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let _ = (topology, params, weights, observer);
    mesh.positions.clone()
}
