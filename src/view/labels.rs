//! Where a case's labels go on the screen: each point projected through the camera, left out
//! when its structure is hidden, when it lies behind the eye or off the view, or when the
//! clipping plane cuts it away; faded when a surface lies between it and the eye (its side
//! turned away, or another structure in front); its text set off outward from the view's
//! centre, so that the leader lines fan out rather than cross the model's middle.

use glam::{Vec2, Vec3};

use super::{OrbitCamera, Ray};
use crate::case::Label;

/// How far a label's text sits from its point (points), along the way out from the centre.
const LEADER: f32 = 36.0;

/// A surface nearer the eye than its label's point by less than this share of the point's
/// distance does not hide it (depth along a grazing ray is imprecise).
const ON_ITS_SURFACE: f32 = 0.01;

/// The label's own structure hides its point only where it lies this much nearer (mm): the
/// point was placed on one of the structure's surfaces (smoothed, slid back, the
/// segmentation's), which lie up to a voxel or two apart.
const OWN_SURFACE_MM: f32 = 5.0;

/// A label as drawn: which one, its point and where its text goes (points in the view's
/// rectangle, from its top-left).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelSpot {
    pub index: usize,
    pub point: Vec2,
    pub text: Vec2,
    /// A surface lies between the point and the eye.
    pub faded: bool,
}

/// The spots of `labels` seen by `camera` in a view of `size` points; `shown(name)` says
/// whether a structure is shown, `clip` is the plane `(n, d)` cutting away `n . p > d` (zero
/// for none), and `nearest(ray, structure)` how far along a ray the first opaque surface the
/// view shows lies, and whether it is `structure`'s.
pub fn label_spots(
    labels: &[Label],
    shown: impl Fn(&str) -> bool,
    (camera, nearest): (&OrbitCamera, impl Fn(&Ray, &str) -> Option<(f32, bool)>),
    size: Vec2,
    clip: [f32; 4],
) -> Vec<LabelSpot> {
    let eye = camera.eye();
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
        let far = (p - eye).length();
        let ray = Ray {
            origin: eye,
            direction: (p - eye) / far,
        };
        let faded = nearest(&ray, &label.structure).is_some_and(|(d, own)| {
            let allowed = far * ON_ITS_SURFACE + if own { OWN_SURFACE_MM } else { 0.0 };
            d < far - allowed
        });
        spots.push(LabelSpot {
            index,
            point,
            text: point + out * LEADER,
            faded,
        });
    }
    spots
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(structure: &str, point: [f32; 3]) -> Label {
        Label::new(structure, point, structure)
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
        let nothing = |_: &Ray, _: &str| None;
        let spots = label_spots(&labels, |s| s != "hidden", (&camera, nothing), size, clip);
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
        let unclipped = label_spots(&labels, |_| true, (&camera, nothing), size, [0.0; 4]);
        assert_eq!(
            unclipped.len(),
            4,
            "only the one behind the eye is left out"
        );
        assert!(unclipped.iter().all(|s| !s.faded));
    }

    #[test]
    fn a_label_behind_a_surface_fades_one_on_it_does_not() {
        let camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 100.0,
            bounds_center: Vec3::ZERO,
            bounds_radius: 50.0,
            ..OrbitCamera::default()
        };
        let labels = [label("on", [0.0, 0.0, 0.0])];
        let size = Vec2::new(800.0, 600.0);
        let far = (camera.eye() - Vec3::ZERO).length();
        let at = |d: f32, own: bool| {
            let nearest = |_: &Ray, _: &str| Some((d, own));
            label_spots(&labels, |_| true, (&camera, nearest), size, [0.0; 4])[0].faded
        };
        assert!(!at(far - 0.5, false), "a surface at the point");
        assert!(at(far - 3.0, false), "another structure in front of it");
        assert!(
            !at(far - 3.0, true),
            "its own surface, a voxel off the point"
        );
        assert!(at(far - 20.0, true), "its own structure, turned away");
        assert!(!at(far + 10.0, false), "a surface behind it");
    }
}
