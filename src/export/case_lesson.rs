//! The lesson in the case glTF, where other viewers find it too: each tour step a perspective
//! camera node (at the top of the scene, since the root's scale would scale a camera's view)
//! and each label a node at its point under its structure's node, named by its text. Each
//! node's `extras` hold the step's or label's full state, which is what a reader restores; the
//! quiz sits in the scene's record.

use glam::{Mat3, Quat, Vec3};
use serde_json::{json, Value};

use super::case_gltf::SceneFrame;
use super::compressed::Lattice;
use crate::case::{Label, Step, CASE_KEY};
use crate::view::DEFAULT_FOV;

const METRES_PER_MM: f32 = 0.001;

/// The near plane of a step's camera, in metres (one millimetre), or millimetres in the
/// data's own frame.
const ZNEAR_METRES: f32 = 0.001;

/// RAS millimetres to the file's frame: glTF's metres with +Y up (superior), +Z anterior and
/// -X right, or the data's own millimetres.
fn to_frame(frame: SceneFrame) -> (Mat3, f32) {
    match frame {
        SceneFrame::Gltf => (Mat3::from_cols(-Vec3::X, Vec3::Z, Vec3::Y), METRES_PER_MM),
        SceneFrame::Millimetres => (Mat3::IDENTITY, 1.0),
    }
}

/// A step's camera (`cameras[camera]`) and its node.
pub(super) fn step_camera(step: &Step, camera: usize, frame: SceneFrame) -> (Value, Value) {
    let (turn, scale) = to_frame(frame);
    let c = &step.camera;
    let eye = turn * Vec3::from(c.eye()) * scale;
    let forward = -(turn * Vec3::from(c.direction())).normalize();
    let up = turn * Vec3::Z;
    let right = forward.cross(up).normalize();
    let rotation = Quat::from_mat3(&Mat3::from_cols(right, right.cross(forward), -forward));
    let znear = match frame {
        SceneFrame::Gltf => ZNEAR_METRES,
        SceneFrame::Millimetres => 1.0,
    };
    let lens = json!({
        "name": step.title,
        "type": "perspective",
        "perspective": { "yfov": DEFAULT_FOV, "znear": znear },
    });
    let node = json!({
        "name": step.title,
        "camera": camera,
        "translation": eye.to_array(),
        "rotation": rotation.normalize().to_array(),
        "extras": { CASE_KEY: { "step": step } },
    });
    (lens, node)
}

/// A label's node, to go under its structure's node: at its point in that node's frame
/// (millimetres, or the structure's quantization lattice).
pub(super) fn label_node(label: &Label, lattice: Option<Lattice>) -> Value {
    let p = label.point;
    let local = match lattice {
        Some(l) => [0, 1, 2].map(|k| (p[k] - l.offset[k]) / l.step),
        None => p,
    };
    json!({
        "name": label.text,
        "translation": local,
        "extras": { CASE_KEY: { "text_label": label } },
    })
}
