//! The standard views of anatomy, and what a page or a platform asks of the view: a standard
//! view, the cut and the image planes ([`Clip`], [`Planes`], which a case's lesson records).
//! All read the data's patient frame (RAS: +x the patient's right, +y anterior, +z superior),
//! which label maps and case glTFs open in.

use glam::Vec3;

use super::OrbitCamera;
use crate::case::{Clip, ClipAxis, Planes};

/// The standard views: the side of the patient the eye looks from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StandardView {
    Anterior,
    Posterior,
    Left,
    Right,
    Superior,
    Inferior,
}

impl StandardView {
    pub const ALL: [StandardView; 6] = [
        StandardView::Anterior,
        StandardView::Posterior,
        StandardView::Left,
        StandardView::Right,
        StandardView::Superior,
        StandardView::Inferior,
    ];

    /// Its letter, as radiology labels views: A P L R S I.
    pub fn letter(self) -> &'static str {
        match self {
            StandardView::Anterior => "A",
            StandardView::Posterior => "P",
            StandardView::Left => "L",
            StandardView::Right => "R",
            StandardView::Superior => "S",
            StandardView::Inferior => "I",
        }
    }

    pub fn from_letter(letter: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|v| v.letter().eq_ignore_ascii_case(letter))
    }

    /// From the target towards the eye, in RAS.
    pub fn direction(self) -> Vec3 {
        match self {
            StandardView::Anterior => Vec3::Y,
            StandardView::Posterior => -Vec3::Y,
            StandardView::Left => -Vec3::X,
            StandardView::Right => Vec3::X,
            StandardView::Superior => Vec3::Z,
            StandardView::Inferior => -Vec3::Z,
        }
    }

    /// `home` (the whole scene framed) seen from this side, the scene framed again.
    pub fn camera(self, home: &OrbitCamera) -> OrbitCamera {
        let mut camera = *home;
        camera.look_from(self.direction());
        let r = Vec3::splat(home.bounds_radius);
        camera.fit(home.bounds_center - r, home.bounds_center + r);
        camera
    }
}

/// What the page's `setView` asks: a side to look from, and a clip to set (`Some(None)`:
/// none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewRequest {
    pub from: Option<StandardView>,
    pub clip: Option<Option<Clip>>,
    pub planes: Option<Option<Planes>>,
    /// How far every structure is drawn back towards its segmentation (0 smoothed, 1 the
    /// segmentation).
    pub toward_segmentation: Option<f32>,
}

impl ViewRequest {
    /// `{from: "A", clip: {axis: "axial", at: 0.5, flip: false} | null, toward_segmentation:
    /// 0..1}`, every key optional
    /// (`at` defaults to the middle, `flip` to false). Unknown keys and values are refused,
    /// naming them.
    pub fn from_json(value: &serde_json::Value) -> Result<Self, String> {
        let object = value
            .as_object()
            .ok_or("setView takes an object: {from, clip}")?;
        let mut out = Self::default();
        for (key, v) in object {
            match key.as_str() {
                "from" => {
                    let letter = v.as_str().unwrap_or_default();
                    let side = StandardView::from_letter(letter)
                        .ok_or_else(|| format!("setView: from {v} is none of A P L R S I"))?;
                    out.from = Some(side);
                }
                "toward_segmentation" => match v.as_f64() {
                    Some(t) if (0.0..=1.0).contains(&t) => out.toward_segmentation = Some(t as f32),
                    _ => {
                        return Err(format!(
                            "setView: toward_segmentation {v} must be a number in [0, 1]"
                        ))
                    }
                },
                "clip" if v.is_null() => out.clip = Some(None),
                "clip" => out.clip = Some(Some(clip_from_json(v)?)),
                "planes" if v.is_null() => out.planes = Some(None),
                "planes" => out.planes = Some(Some(planes_from_json(v)?)),
                other => {
                    return Err(format!(
                        "setView: unknown key {other} (from, clip, planes, toward_segmentation)"
                    ))
                }
            }
        }
        Ok(out)
    }
}

fn clip_from_json(v: &serde_json::Value) -> Result<Clip, String> {
    let object = v
        .as_object()
        .ok_or("setView: clip takes {axis, at, flip} or null")?;
    let mut clip = Clip {
        axis: ClipAxis::Axial,
        at: 0.5,
        flip: false,
    };
    let mut axis = None;
    for (key, v) in object {
        match key.as_str() {
            "axis" => {
                let name = v.as_str().unwrap_or_default();
                axis = Some(ClipAxis::from_name(name).ok_or_else(|| {
                    format!("setView: clip axis {v} is none of axial, coronal, sagittal")
                })?);
            }
            "at" => match v.as_f64() {
                Some(at) if (0.0..=1.0).contains(&at) => clip.at = at as f32,
                _ => return Err(format!("setView: clip at {v} must be a number in [0, 1]")),
            },
            "flip" => {
                clip.flip = v
                    .as_bool()
                    .ok_or("setView: clip flip must be true or false")?
            }
            other => {
                return Err(format!(
                    "setView: unknown clip key {other} (axis, at, flip)"
                ))
            }
        }
    }
    clip.axis = axis.ok_or("setView: a clip needs its axis")?;
    Ok(clip)
}

fn planes_from_json(v: &serde_json::Value) -> Result<Planes, String> {
    let object =
        (v.as_object()).ok_or("setView: planes takes {sagittal, coronal, axial} or null")?;
    let mut planes = Planes::default();
    for (key, v) in object {
        let at = match v.as_f64() {
            Some(at) if (0.0..=1.0).contains(&at) => at as f32,
            _ => {
                return Err(format!(
                    "setView: planes {key} {v} must be a number in [0, 1]"
                ))
            }
        };
        match key.as_str() {
            "sagittal" => planes.sagittal = at,
            "coronal" => planes.coronal = at,
            "axial" => planes.axial = at,
            other => {
                return Err(format!(
                    "setView: unknown planes key {other} (sagittal, coronal, axial)"
                ))
            }
        }
    }
    Ok(planes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_lie_across_the_scene_each_along_its_axis() {
        let (min, max) = (Vec3::new(0.0, 10.0, -50.0), Vec3::new(100.0, 30.0, 50.0));
        let request = ViewRequest::from_json(&serde_json::json!({"planes": {"axial": 0.25}}))
            .expect("planes");
        let planes = request.planes.flatten().expect("set");
        assert_eq!(
            planes.planes(min, max),
            [
                [1.0, 0.0, 0.0, 50.0],
                [0.0, 1.0, 0.0, 20.0],
                [0.0, 0.0, 1.0, -25.0]
            ]
        );
        let off = ViewRequest::from_json(&serde_json::json!({"planes": null})).expect("off");
        assert_eq!(off.planes, Some(None));
        for bad in [
            serde_json::json!({"planes": {"axial": 2}}),
            serde_json::json!({"planes": {"oblique": 0.5}}),
        ] {
            assert!(ViewRequest::from_json(&bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_clip_cuts_above_its_place_along_its_axis_or_below_when_flipped() {
        let (min, max) = (Vec3::new(0.0, 10.0, -50.0), Vec3::new(100.0, 30.0, 50.0));
        let axial = Clip {
            axis: ClipAxis::Axial,
            at: 0.25,
            flip: false,
        };
        let [nx, ny, nz, d] = axial.plane(min, max);
        assert_eq!([nx, ny, nz, d], [0.0, 0.0, 1.0, -25.0]);
        let cut = |p: Vec3, [x, y, z, d]: [f32; 4]| Vec3::new(x, y, z).dot(p) > d;
        assert!(cut(Vec3::new(5.0, 20.0, 0.0), axial.plane(min, max)));
        assert!(!cut(Vec3::new(5.0, 20.0, -30.0), axial.plane(min, max)));
        let flipped = Clip {
            flip: true,
            ..axial
        };
        assert!(!cut(Vec3::new(5.0, 20.0, 0.0), flipped.plane(min, max)));
        assert!(cut(Vec3::new(5.0, 20.0, -30.0), flipped.plane(min, max)));
        let coronal = Clip {
            axis: ClipAxis::Coronal,
            at: f32::NAN,
            flip: false,
        };
        assert_eq!(coronal.plane(min, max), [0.0, 1.0, 0.0, 20.0]);
        let past = Clip { at: 7.0, ..axial };
        assert_eq!(past.plane(min, max)[3], 50.0, "clamped to the scene");
        for axis in ClipAxis::ALL {
            assert_eq!(ClipAxis::from_name(axis.name()), Some(axis));
        }
    }

    #[test]
    fn view_requests_read_from_json_and_refuse_what_they_do_not_know() {
        use serde_json::json;
        let r = ViewRequest::from_json(&json!({"from": "s", "clip": {"axis": "coronal"}})).unwrap();
        assert_eq!(r.from, Some(StandardView::Superior));
        let clip = Clip {
            axis: ClipAxis::Coronal,
            at: 0.5,
            flip: false,
        };
        assert_eq!(r.clip, Some(Some(clip)));
        let r =
            ViewRequest::from_json(&json!({"clip": null, "toward_segmentation": 0.25})).unwrap();
        assert_eq!((r.from, r.clip), (None, Some(None)));
        assert_eq!(r.toward_segmentation, Some(0.25));
        let r =
            ViewRequest::from_json(&json!({"clip": {"axis": "axial", "at": 0.2, "flip": true}}));
        assert_eq!(r.unwrap().clip.unwrap().unwrap().at, 0.2);
        for (bad, says) in [
            (json!({"from": "X"}), "none of A P L R S I"),
            (json!({"zoom": 2}), "unknown key zoom"),
            (json!({"clip": {"at": 0.5}}), "needs its axis"),
            (json!({"clip": {"axis": "axial", "at": 1.5}}), "in [0, 1]"),
            (json!({"clip": {"axis": "oblique"}}), "none of axial"),
            (
                json!({"clip": {"axis": "axial", "tilt": 3}}),
                "unknown clip key tilt",
            ),
            (json!([1]), "takes an object"),
            (json!({"toward_segmentation": 2}), "in [0, 1]"),
        ] {
            let e = ViewRequest::from_json(&bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn standard_views_look_from_their_side_and_frame_the_scene() {
        let mut home = OrbitCamera::default();
        home.fit(Vec3::new(-50.0, -80.0, -60.0), Vec3::new(50.0, 80.0, 60.0));
        for view in StandardView::ALL {
            let camera = view.camera(&home);
            let from = camera.direction();
            // The pitch limit keeps S and I a little off the vertical.
            assert!(from.dot(view.direction()) > 0.95, "{view:?}: {from}");
            assert_eq!(camera.target, home.target);
            assert!(camera.distance >= home.bounds_radius, "{view:?}");
            assert_eq!(StandardView::from_letter(view.letter()), Some(view));
        }
        let front = StandardView::Anterior.camera(&home);
        assert!(
            front.eye().y > home.target.y,
            "the eye in front of the patient"
        );
    }
}
