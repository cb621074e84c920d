//! Playing a case's tour: a step as the view it shows (the same view a link restores), and the
//! camera's flight from where the student left it to the step's view.

use glam::Vec3;

use super::{CameraPose, ViewLink};
use crate::case::{Camera, Step};

/// How long the camera takes to reach a step's view (seconds): long enough to see where it
/// goes, short enough not to wait.
pub const FLIGHT_SECONDS: f64 = 0.8;

/// The view step shows, its structures found by name in `names` (the case's, in order); a
/// name the case lacks shows nothing (a lesson is checked against its case when read). Every
/// structure's opacity is set: those the step does not name are opaque, whatever the step
/// before made them.
pub fn step_view(step: &Step, names: &[&str]) -> ViewLink {
    let index = |name: &str| names.iter().position(|n| *n == name);
    let c = step.camera;
    ViewLink {
        camera: Some(CameraPose {
            yaw: c.yaw,
            pitch: c.pitch,
            distance: c.distance,
            target: Vec3::from(c.target),
        }),
        hidden: step.hidden.iter().filter_map(|n| index(n)).collect(),
        opacity: (names.iter().enumerate())
            .map(|(i, n)| (i, step.opacity.get(*n).copied().unwrap_or(1.0)))
            .collect(),
        selected: step.selected.as_deref().and_then(index),
        clip: step.clip,
        planes: step.planes,
        toward_segmentation: step.toward_segmentation,
    }
}

/// The view `link` shows (its camera required) as a tour step named `title`, its structures
/// named from `names` (the case's, in order); only structures less than opaque keep an
/// opacity.
pub fn recorded_step(
    link: &ViewLink,
    names: &[&str],
    title: &str,
    caption: &str,
) -> Result<Step, String> {
    let c = link.camera.ok_or("the view has no camera yet")?;
    let name = |i: usize| {
        (names.get(i).map(|n| n.to_string())).ok_or(format!("the case has no structure {i}"))
    };
    Ok(Step {
        title: title.to_string(),
        caption: caption.to_string(),
        titles: Default::default(),
        captions: Default::default(),
        camera: Camera {
            target: c.target.to_array(),
            yaw: c.yaw,
            pitch: c.pitch,
            distance: c.distance,
        },
        hidden: link
            .hidden
            .iter()
            .map(|&i| name(i))
            .collect::<Result<_, _>>()?,
        opacity: (link.opacity.iter())
            .filter(|(_, a)| *a < 1.0)
            .map(|&(i, a)| Ok((name(i)?, a)))
            .collect::<Result<_, String>>()?,
        selected: link.selected.map(name).transpose()?,
        clip: link.clip,
        planes: link.planes,
        toward_segmentation: link.toward_segmentation,
    })
}

/// The camera's way to a step's view, which gives way to the student's hand: once the camera
/// is not where the flight last put it (dragged, zoomed, turned to a standard side), the flight
/// is over.
#[derive(Clone, Copy, Debug)]
pub struct Flight {
    from: CameraPose,
    to: CameraPose,
    started_ms: f64,
    /// Where the flight last put the camera, as the view holds it.
    left: CameraPose,
    arrived: bool,
}

impl Flight {
    pub fn new(from: CameraPose, to: CameraPose, now_ms: f64) -> Self {
        Self {
            from,
            to,
            started_ms: now_ms,
            left: from,
            arrived: false,
        }
    }

    /// Where the camera, now at `at`, goes at `now_ms`; `None` once the flight has arrived or
    /// the camera was moved by another hand. The caller reports where it put it with
    /// [`Flight::left_at`].
    pub fn advance(&mut self, at: CameraPose, now_ms: f64) -> Option<CameraPose> {
        if self.arrived || at != self.left {
            return None;
        }
        let t = (now_ms - self.started_ms) / (1000.0 * FLIGHT_SECONDS);
        self.arrived = t >= 1.0;
        Some(flight(self.from, self.to, t))
    }

    /// The camera as the view holds it after being put where [`Flight::advance`] said.
    pub fn left_at(&mut self, pose: CameraPose) {
        self.left = pose;
    }

    /// Whether the last pose given was the step's view.
    pub fn arrived(&self) -> bool {
        self.arrived
    }
}

/// The camera `t` of the way (0 to 1, eased in and out) from `from` to `to`: turning the short
/// way round, and zooming at a steady rate (the distance geometrically).
fn flight(from: CameraPose, to: CameraPose, t: f64) -> CameraPose {
    let t = t.clamp(0.0, 1.0) as f32;
    let s = t * t * (3.0 - 2.0 * t);
    let tau = std::f32::consts::TAU;
    let turn = (to.yaw - from.yaw + std::f32::consts::PI).rem_euclid(tau) - std::f32::consts::PI;
    let ratio = to.distance / from.distance;
    let distance = match ratio.is_finite() && ratio > 0.0 {
        true => from.distance * ratio.powf(s),
        false => to.distance,
    };
    if s >= 1.0 {
        return to;
    }
    CameraPose {
        yaw: from.yaw + s * turn,
        pitch: from.pitch + s * (to.pitch - from.pitch),
        distance,
        target: from.target.lerp(to.target, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::{Clip, ClipAxis, Planes};

    fn pose(yaw: f32, distance: f32) -> CameraPose {
        CameraPose {
            yaw,
            pitch: 0.2,
            distance,
            target: Vec3::new(1.0, 2.0, 3.0),
        }
    }

    #[test]
    fn a_step_shows_its_structures_by_their_places_in_the_case() {
        let step = Step {
            title: "cut".into(),
            caption: String::new(),
            titles: Default::default(),
            captions: Default::default(),
            camera: Camera {
                target: [1.0, 2.0, 3.0],
                yaw: 0.5,
                pitch: -0.1,
                distance: 90.0,
            },
            hidden: vec!["kidney".into()],
            opacity: [("liver".to_string(), 0.25)].into_iter().collect(),
            selected: Some("tumour".into()),
            clip: Some(Clip {
                axis: ClipAxis::Coronal,
                at: 0.4,
                flip: true,
            }),
            planes: None,
            toward_segmentation: 0.5,
        };
        let view = step_view(&step, &["liver", "tumour", "kidney"]);
        assert_eq!(view.hidden, [2]);
        assert_eq!(view.opacity, [(0, 0.25), (1, 1.0), (2, 1.0)]);
        assert_eq!(view.selected, Some(1));
        assert_eq!(view.clip, step.clip);
        assert_eq!(view.toward_segmentation, 0.5);
        let camera = view.camera.expect("a camera");
        assert_eq!(
            (camera.yaw, camera.pitch, camera.distance),
            (0.5, -0.1, 90.0)
        );
        assert_eq!(camera.target, Vec3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn a_recorded_view_plays_back_as_the_same_view() {
        let names = ["liver", "tumour", "kidney"];
        let link = ViewLink {
            camera: Some(pose(1.0, 250.0)),
            hidden: vec![2],
            opacity: vec![(0, 0.4)],
            selected: Some(1),
            clip: Some(Clip {
                axis: ClipAxis::Sagittal,
                at: 0.3,
                flip: false,
            }),
            planes: None,
            toward_segmentation: 0.1,
        };
        let step = recorded_step(&link, &names, "inside", "The tumour.").expect("recorded");
        assert_eq!(step.hidden, ["kidney"]);
        assert_eq!(step.selected.as_deref(), Some("tumour"));
        let back = step_view(&step, &names);
        assert_eq!(back.opacity, [(0, 0.4), (1, 1.0), (2, 1.0)]);
        assert_eq!(
            ViewLink {
                opacity: link.opacity.clone(),
                ..back
            },
            link
        );
        let nowhere = ViewLink::default();
        assert!(recorded_step(&nowhere, &names, "x", "").is_err());
        let stale = ViewLink {
            hidden: vec![7],
            ..link.clone()
        };
        assert_eq!(
            recorded_step(&stale, &names, "x", "").expect_err("no structure 7"),
            "the case has no structure 7"
        );
        // The image's planes, shown instead of a clip, are recorded and shown again.
        let planes = Planes {
            sagittal: 0.2,
            coronal: 0.5,
            axial: 0.9,
        };
        let on_the_image = ViewLink {
            clip: None,
            planes: Some(planes),
            ..link
        };
        let step = recorded_step(&on_the_image, &names, "slices", "").expect("recorded");
        assert_eq!((step.clip, step.planes), (None, Some(planes)));
        assert_eq!(step_view(&step, &names).planes, Some(planes));
    }

    #[test]
    fn a_flight_arrives_once_and_gives_way_to_the_students_hand() {
        let (from, to) = (pose(0.0, 100.0), pose(1.0, 50.0));
        let ms = 1000.0 * FLIGHT_SECONDS;
        let mut f = Flight::new(from, to, 10.0);
        let half = f.advance(from, 10.0 + ms / 2.0).unwrap();
        assert!(half.yaw > 0.0 && half.yaw < 1.0 && !f.arrived());
        f.left_at(half);
        let end = f.advance(half, 10.0 + ms).unwrap();
        assert_eq!(end, to);
        assert!(f.arrived());
        f.left_at(end);
        assert_eq!(
            f.advance(end, 10.0 + 2.0 * ms),
            None,
            "arrived: nothing more"
        );

        let mut f = Flight::new(from, to, 0.0);
        let first = f.advance(from, ms / 4.0).unwrap();
        f.left_at(first);
        let dragged = CameraPose {
            yaw: first.yaw + 0.3,
            ..first
        };
        assert_eq!(
            f.advance(dragged, ms / 2.0),
            None,
            "the student's drag ends it"
        );
    }

    #[test]
    fn the_flight_starts_and_ends_at_its_poses_turning_the_short_way() {
        let (from, to) = (pose(3.0, 100.0), pose(-3.0, 400.0));
        assert_eq!(flight(from, to, 0.0), from);
        assert_eq!(flight(from, to, 1.0), to);
        assert_eq!(flight(from, to, 7.0), to);
        // From 3 to -3 radians the short way passes pi (0.28 rad), not 0 (6 rad).
        let half = flight(from, to, 0.5);
        assert!(
            (half.yaw - std::f32::consts::PI).abs() < 1e-5,
            "{}",
            half.yaw
        );
        // Half way in time, half way in zoom ratio: 100 -> 200 -> 400.
        assert!((half.distance - 200.0).abs() < 1e-3, "{}", half.distance);
        let early = flight(from, to, 0.1);
        assert!(
            early.yaw > 3.0 && early.yaw - 3.0 < 0.1 * 0.29,
            "eased in: {}",
            early.yaw
        );
    }
}
