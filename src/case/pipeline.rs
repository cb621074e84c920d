//! Smoothing a case's structure with its own parameters (the suggestions of "Suggest all" are
//! in `suggest_all.rs`).

use super::{CaseStructure, Smoothed};
use crate::mesh::Topology;
use crate::metrics::{measure_vertices, smooth_drifting, Original};

/// Smooths a structure from its original with its parameters and weights and measures the
/// result (with the drifting reference, as every other caller does).
pub fn smooth_structure(structure: &mut CaseStructure) {
    let topology = Topology::build(&structure.original);
    let original = Original::new(&structure.original, &topology);
    let smoothed = smooth_on(structure, &original);
    structure.keep(smoothed);
}

fn smooth_on(structure: &CaseStructure, original: &Original) -> Smoothed {
    let weights = structure.weights.as_deref();
    let (positions, reference) = smooth_drifting(original, &structure.params, weights);
    measured(structure, original, positions, reference)
}

/// The structure's result from its smoothed `positions` and their drifting `reference`.
pub(super) fn measured(
    structure: &CaseStructure,
    original: &Original,
    positions: Vec<[f32; 3]>,
    reference: Vec<u32>,
) -> Smoothed {
    let (metrics, vertex) = measure_vertices(original, &positions, &reference, structure.tau);
    Smoothed {
        curvature: Some(vertex.gaussian_curvature),
        ..Smoothed::new(positions, metrics, Some(vertex.local_error))
    }
}
