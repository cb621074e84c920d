//! What the 3D view computes without a GPU: the orbit camera and its matrices, the side a mesh
//! is first shown from, the per-frame record the render shader reads, thumbnails drawn on
//! the CPU with the same camera and lights, picking (the triangle under the cursor and the
//! vertices under the brush), the window/level-style parameter drag, and the clipping plane
//! and standard views of a case, the link that restores a view, a tour's steps and where labels go.
//!
//! Free of egui and wgpu so that it builds and is unit-tested natively; the web app's
//! renderer (`app::viewer`, wasm32) uploads what this module computes.

mod camera;
mod clip;
mod labels;
mod link;
mod morph;
mod orientation;
mod param_drag;
mod pick;
mod pointing;
mod quiz;
mod slice;
pub mod thumbnail;
mod tour;
mod uniforms;

pub use crate::case::{Clip, ClipAxis, Planes};
pub use camera::{OrbitCamera, DEFAULT_FOV, ORBIT_RADIANS_PER_POINT, PITCH_LIMIT};
pub use clip::{StandardView, ViewRequest};
pub use labels::{label_spots, LabelSpot};
pub use link::{CameraPose, ViewLink, LINK_KEYS};
pub use morph::toward_original;
pub use orientation::{face_on_direction, first_view};
pub use param_drag::{
    default_drag_axes, drag_choices, drag_range, dragged_params, POINTS_PER_RANGE,
};
pub use pick::{
    brush_falloff, brush_footprint, moller_trumbore, pick_triangle, pick_triangle_where, Hit, Ray,
};
pub use pointing::{opaque_at, structure_at};
pub use quiz::{Answer, Question, QuizRun, CHOICES};
pub use slice::{SlicePlacement, SliceTexture, SliceUniforms};
pub use tour::{recorded_step, step_view, Flight, FLIGHT_SECONDS};
pub use uniforms::{ViewUniforms, BASE_COLOR_SRGB, OUTPUT_LINEAR, RENDER_SHADER, VERTEX_COLORS};
