//! meshsmooth: visually guided smoothing of anatomical surface meshes.
//!
//! Data flows one way: bytes -> [`io`] (parse, weld) -> [`mesh`] (indexed mesh, CSR topology,
//! report) -> [`smooth`] (CPU reference) -> [`metrics`] -> [`simplify`] -> [`export`]. The
//! command-line tool (native) and the web app (wasm32) sit on top and own no algorithm. [`view`] is the 3D view's
//! camera and shading record, kept apart from the app so it is tested natively.

/// Whether this build is the author's (the `authoring` feature) or the student's viewer alone.
/// Tested where the two part, as a constant: the branch a build cannot take is compiled but
/// left out of its binary, with all it alone calls (readers, smoothing, search, writers).
pub const AUTHORING: bool = cfg!(feature = "authoring");

pub mod case;
pub mod evaluate;
pub mod export;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod model;
pub mod segmentation;
pub mod session;
pub mod simplify;
pub mod smooth;
pub mod srgb;
pub mod suggest;
pub mod view;
pub mod worker;

#[cfg(all(not(target_arch = "wasm32"), feature = "cli"))]
pub mod cli;

#[cfg(all(target_arch = "wasm32", feature = "web-app"))]
pub mod app;
