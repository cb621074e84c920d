//! Where a case's labels go on the screen: each point projected through the camera, left out
//! when its structure is hidden, when it lies behind the eye or off the view, or when the
//! clipping plane cuts it away; its text set off outward from the view's centre, so that the
//! leader lines fan out rather than cross the model's middle.

use glam::{Vec2, Vec3};

use super::OrbitCamera;
use crate::case::Label;

/// How far a label's text sits from its point (points), along the way out from the centre.
const LEADER: f32 = 36.0;

/// A label as drawn: which one, its point and where its text goes (points in the view's
/// rectangle, from its top-left).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelSpot {
    pub index: usize,
    pub point: Vec2,
    pub text: Vec2,
}

/// The spots of `labels` seen by `camera` in a view of `size` points; `shown(name)` says
/// whether a structure is shown, `clip` is the plane `(n, d)` cutting away `n . p > d` (zero
/// for none).
pub fn label_spots(
    labels: &[Label],
    shown: impl Fn(&str) -> bool,
    camera: &OrbitCamera,
    size: Vec2,
    clip: [f32; 4],
) -> Vec<LabelSpot> {
    let to_clip = camera.view_proj(size.x / size.y);
    let n = Vec3::new(clip[0], clip[1], clip[2]);
    let centre = size / 2.0;
    let mut spots = Vec::new();
    for (index, label) in labels.iter().enumerate() {
        let p = Vec3::from(label.point);
        if !shown(&label.structure) || (n != Vec3::ZERO && n.dot(p) > clip[3]) {
            continue;
        }
        let c = to_clip * p.extend(1.0);
        if c.w <= 0.0 {
            continue;
        }
        let ndc = c.truncate() / c.w;
        if ndc.x.abs() > 1.0 || ndc.y.abs() > 1.0 || !(0.0..=1.0).contains(&ndc.z) {
            continue;
        }
        let point = Vec2::new((ndc.x + 1.0) / 2.0 * size.x, (1.0 - ndc.y) / 2.0 * size.y);
        let out = (point - centre).try_normalize().unwrap_or(Vec2::NEG_Y);
        spots.push(LabelSpot {
            index,
            point,
            text: point + out * LEADER,
        });
    }
    spots
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(structure: &str, point: [f32; 3]) -> Label {
        Label {
            structure: structure.into(),
            point,
            text: structure.into(),
            note: String::new(),
        }
    }

    #[test]
    fn labels_project_where_the_camera_sees_them_unless_hidden_cut_or_behind() {
        let camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 100.0,
            yaw: 0.0,
            pitch: 0.0,
            bounds_center: Vec3::ZERO,
            bounds_radius: 50.0,
            ..OrbitCamera::default()
        };
        // Yaw 0 looks from anterior (+y), superior (+z) up.
        let labels = [
            label("middle", [0.0, 0.0, 0.0]),
            label("up", [0.0, 0.0, 20.0]),
            label("hidden", [0.0, 0.0, 0.0]),
            label("behind the eye", [0.0, 150.0, 0.0]),
            label("cut", [10.0, 0.0, 0.0]),
        ];
        let size = Vec2::new(800.0, 600.0);
        let clip = [1.0, 0.0, 0.0, 5.0];
        let spots = label_spots(&labels, |s| s != "hidden", &camera, size, clip);
        let found: Vec<usize> = spots.iter().map(|s| s.index).collect();
        assert_eq!(found, [0, 1]);
        assert!(
            (spots[0].point - size / 2.0).length() < 1e-3,
            "{:?}",
            spots[0]
        );
        assert!(spots[1].point.y < 300.0 && (spots[1].point.x - 400.0).abs() < 1e-3);
        // The text sits outward: above a point above the centre.
        assert!(spots[1].text.y < spots[1].point.y);
        let unclipped = label_spots(&labels, |_| true, &camera, size, [0.0; 4]);
        assert_eq!(
            unclipped.len(),
            4,
            "only the one behind the eye is left out"
        );
    }
}
