//! Quality measures comparing a smoothed mesh with its original: volume, discrete Gaussian
//! curvature, the paper's local error with the drifting reference vertex, and the score S(tau).
//! Definitions: ALGORITHMS.md (shared docs), section "Quality measures".
//!
//! Use: build an [`Original`] once per loaded mesh; smooth with a [`DriftingReference`] as the
//! step observer; then [`measure`] the result (or [`measure_vertices`] for colour-coding).
//! [`TriangleBvh`] and [`exact_error`] give the exact distance the local error approximates.

mod curvature;
mod drift;
mod exact_distance;
mod local_error;
mod original;
mod prism_rows;
pub mod reference;
mod report;
mod roughness;
mod score;
mod stand_in;
#[cfg(target_arch = "x86_64")]
mod wide;

pub use curvature::{vertex_curvatures, VertexCurvature};
pub use drift::{identity, smooth_drifting, DriftState, DriftingReference};
pub use exact_distance::{point_segment_distance2, point_triangle_distance2, Closest, TriangleBvh};
pub(crate) use exact_distance::{Node as TreeNode, TreeShape};
pub use original::Original;
pub use report::{
    as_json_text, exact_distances, exact_error, measure, measure_shape, measure_vertices,
    ErrorSummary, Metrics, VertexMeasures,
};
pub use roughness::{roughness, roughness_ratio};
pub use score::ScoreTerms;

// What the GPU engine's measure pass shares with the CPU's.
#[cfg(feature = "gpu")]
pub(crate) use report::{metrics as metrics_from_sums, Sums};
