//! A link that restores a view of a case: the camera, which structures are hidden, their
//! opacity, the one selected, the clipping plane or the image's three planes and the slide
//! towards the segmentation, as query parameters beside the page's `?case=URL`. A teacher sends the link; a student opens
//! the case as the teacher saw it.
//!
//! `cam=yaw,pitch,distance,x,y,z&hide=0,3&opacity=1:0.5&select=2&clip=sagittal,0.5,flip&toward=0.3`,
//! or `planes=sagittal,coronal,axial` (each plane's place, 0 to 1) in place of `clip` (angles in
//! radians, lengths in the case's units; structures by index). Each part is
//! optional: what a link leaves out stays as the page opens it.

use glam::Vec3;

use super::{Clip, ClipAxis, OrbitCamera, Planes, PITCH_LIMIT};

/// Where the camera is: what [`OrbitCamera`] holds that the user moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    pub target: Vec3,
}

impl CameraPose {
    pub fn of(camera: &OrbitCamera) -> Self {
        Self {
            yaw: camera.yaw,
            pitch: camera.pitch,
            distance: camera.distance,
            target: camera.target,
        }
    }

    /// `camera` moved to this pose, keeping its lens and the scene's bounds.
    pub fn applied_to(&self, camera: &OrbitCamera) -> OrbitCamera {
        OrbitCamera {
            yaw: self.yaw,
            pitch: self.pitch.clamp(-PITCH_LIMIT, PITCH_LIMIT),
            distance: self.distance,
            target: self.target,
            ..*camera
        }
    }
}

/// A view of a case, as a link carries it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewLink {
    pub camera: Option<CameraPose>,
    pub hidden: Vec<usize>,
    /// Structures drawn less than opaque, with their opacity.
    pub opacity: Vec<(usize, f32)>,
    pub selected: Option<usize>,
    pub clip: Option<Clip>,
    /// The image's three standard planes, shown together instead of a clip.
    pub planes: Option<Planes>,
    pub toward_segmentation: f32,
}

/// The query keys a link sets.
pub const LINK_KEYS: [&str; 7] = [
    "cam", "hide", "opacity", "select", "clip", "planes", "toward",
];

impl ViewLink {
    /// The query parameters (without `?`), parts at their defaults left out.
    pub fn to_query(&self) -> String {
        let list = |items: Vec<String>| items.join(",");
        let mut parts = Vec::new();
        if let Some(c) = self.camera {
            let t = c.target;
            let numbers = [c.yaw, c.pitch, c.distance, t.x, t.y, t.z];
            parts.push(format!("cam={}", list(numbers.map(short).to_vec())));
        }
        if !self.hidden.is_empty() {
            parts.push(format!(
                "hide={}",
                list(self.hidden.iter().map(usize::to_string).collect())
            ));
        }
        if !self.opacity.is_empty() {
            let items = (self.opacity.iter()).map(|(i, a)| format!("{i}:{}", short(*a)));
            parts.push(format!("opacity={}", list(items.collect())));
        }
        if let Some(i) = self.selected {
            parts.push(format!("select={i}"));
        }
        if let Some(c) = self.clip {
            let flip = if c.flip { ",flip" } else { "" };
            parts.push(format!("clip={},{}{flip}", c.axis.name(), short(c.at)));
        }
        if let Some(p) = self.planes {
            let at = [p.sagittal, p.coronal, p.axial].map(short);
            parts.push(format!("planes={}", list(at.to_vec())));
        }
        if self.toward_segmentation > 0.0 {
            parts.push(format!("toward={}", short(self.toward_segmentation)));
        }
        parts.join("&")
    }

    /// The link in a page's query string (`?a=b&...`, as `location.search` reads), or `None`
    /// when it sets none of [`LINK_KEYS`]; an error naming the part that does not read.
    pub fn from_query(search: &str) -> Result<Option<Self>, String> {
        let mut link = Self::default();
        let mut any = false;
        for pair in search.trim_start_matches('?').split('&') {
            let Some((key, value)) = pair.split_once('=') else {
                continue;
            };
            if !LINK_KEYS.contains(&key) {
                continue;
            }
            any = true;
            let value = decoded(value);
            link.read(key, &value)
                .map_err(|why| format!("the link's {key}={value}: {why}"))?;
        }
        Ok(any.then_some(link))
    }

    fn read(&mut self, key: &str, value: &str) -> Result<(), String> {
        let items: Vec<&str> = value.split(',').filter(|s| !s.is_empty()).collect();
        match key {
            "cam" => {
                let n = numbers(&items)?;
                let [yaw, pitch, distance, x, y, z] = n[..] else {
                    return Err(
                        "six numbers: yaw, pitch, distance, and the target's x, y, z".into(),
                    );
                };
                if distance <= 0.0 {
                    return Err("the distance must be above 0".into());
                }
                let target = Vec3::new(x, y, z);
                self.camera = Some(CameraPose {
                    yaw,
                    pitch,
                    distance,
                    target,
                });
            }
            "hide" => self.hidden = items.iter().map(|s| index(s)).collect::<Result<_, _>>()?,
            "opacity" => {
                self.opacity = (items.iter())
                    .map(|item| {
                        let (i, a) = item.split_once(':').ok_or("index:opacity pairs")?;
                        let a = number(a)?;
                        if !(0.0..=1.0).contains(&a) {
                            return Err(format!("opacity {a} is not in [0, 1]"));
                        }
                        Ok((index(i)?, a))
                    })
                    .collect::<Result<_, String>>()?;
            }
            "select" => self.selected = Some(index(value)?),
            "clip" => {
                let (axis, at, flip) = match items[..] {
                    [axis, at] => (axis, at, false),
                    [axis, at, "flip"] => (axis, at, true),
                    _ => return Err("axis,at or axis,at,flip".into()),
                };
                let axis = ClipAxis::from_name(axis)
                    .ok_or_else(|| format!("{axis} is none of axial, coronal, sagittal"))?;
                let at = number(at)?.clamp(0.0, 1.0);
                self.clip = Some(Clip { axis, at, flip });
            }
            "planes" => {
                let [sagittal, coronal, axial] = numbers(&items)?[..] else {
                    return Err("three places from 0 to 1: sagittal, coronal, axial".into());
                };
                let at = |x: f32| x.clamp(0.0, 1.0);
                self.planes = Some(Planes {
                    sagittal: at(sagittal),
                    coronal: at(coronal),
                    axial: at(axial),
                });
            }
            "toward" => self.toward_segmentation = number(value)?.clamp(0.0, 1.0),
            _ => {}
        }
        Ok(())
    }
}

/// The shortest text that reads back to `x` exactly.
fn short(x: f32) -> String {
    format!("{x}")
}

fn number(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("{s} is not a number"))
}

fn numbers(items: &[&str]) -> Result<Vec<f32>, String> {
    items.iter().map(|s| number(s)).collect()
}

fn index(s: &str) -> Result<usize, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("{s} is not a structure's index"))
}

/// `value` with its `%XX` escapes decoded (browsers escape `,` and `:` in copied links).
fn decoded(value: &str) -> String {
    let bytes = value.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = (bytes[i] == b'%')
            .then(|| value.get(i + 1..i + 3))
            .flatten()
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match hex {
            Some(b) => {
                out.push(b);
                i += 3;
            }
            None => {
                out.push(if bytes[i] == b'+' { b' ' } else { bytes[i] });
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn full() -> ViewLink {
        ViewLink {
            camera: Some(CameraPose {
                yaw: 0.5123457,
                pitch: -0.25,
                distance: 312.75,
                target: Vec3::new(-12.5, 3.0e-7, 1045.125),
            }),
            hidden: vec![0, 3],
            opacity: vec![(1, 0.5), (2, 0.25)],
            selected: Some(2),
            clip: Some(Clip {
                axis: ClipAxis::Sagittal,
                at: 0.4,
                flip: true,
            }),
            planes: None,
            toward_segmentation: 0.3,
        }
    }

    #[test]
    fn a_link_reads_back_the_view_it_was_made_of() {
        let link = full();
        let query = link.to_query();
        assert_eq!(
            query,
            "cam=0.5123457,-0.25,312.75,-12.5,0.0000003,1045.125&hide=0,3&opacity=1:0.5,2:0.25\
             &select=2&clip=sagittal,0.4,flip&toward=0.3"
        );
        let back = ViewLink::from_query(&format!("?mode=viewer&case=a.glb&{query}"));
        assert_eq!(back, Ok(Some(link)));
        // As a browser may have escaped it.
        let escaped = query.replace(',', "%2C").replace(':', "%3A");
        assert_eq!(ViewLink::from_query(&escaped), Ok(Some(full())));
    }

    #[test]
    fn the_images_planes_read_back_in_place_of_a_clip() {
        let link = ViewLink {
            clip: None,
            planes: Some(Planes {
                sagittal: 0.25,
                coronal: 0.5,
                axial: 0.875,
            }),
            ..full()
        };
        let query = link.to_query();
        assert!(
            query.ends_with("&select=2&planes=0.25,0.5,0.875&toward=0.3"),
            "{query}"
        );
        assert_eq!(ViewLink::from_query(&query), Ok(Some(link)));
        let beyond = ViewLink::from_query("?planes=-1,0.5,2").unwrap().unwrap();
        assert_eq!(
            beyond.planes.map(|p| [p.sagittal, p.axial]),
            Some([0.0, 1.0])
        );
    }

    #[test]
    fn a_page_without_a_link_has_none_and_defaults_are_left_out() {
        assert_eq!(ViewLink::from_query("?mode=viewer&case=a.glb"), Ok(None));
        assert_eq!(ViewLink::from_query(""), Ok(None));
        assert_eq!(ViewLink::default().to_query(), "");
        let only = ViewLink::from_query("?select=1").unwrap().unwrap();
        assert_eq!(only.selected, Some(1));
        assert_eq!((only.camera, only.clip), (None, None));
    }

    #[test]
    fn a_broken_link_says_which_part() {
        for (query, says) in [
            ("cam=1,2,3", "the link's cam=1,2,3: six numbers"),
            ("cam=1,2,0,0,0,0", "the distance must be above 0"),
            ("cam=1,2,NaN,0,0,0", "NaN is not a number"),
            ("hide=liver", "liver is not a structure's index"),
            ("opacity=1:2", "opacity 2 is not in [0, 1]"),
            ("opacity=1", "index:opacity pairs"),
            ("clip=oblique,0.5", "oblique is none of axial"),
            ("clip=axial", "axis,at"),
            ("toward=much", "much is not a number"),
            ("planes=0.5,0.5", "three places from 0 to 1"),
        ] {
            let e = ViewLink::from_query(query).unwrap_err();
            assert!(e.contains(says), "{query}: {e}");
        }
    }

    #[test]
    fn a_pose_moves_the_camera_and_keeps_its_lens() {
        let camera = OrbitCamera::default();
        let pose = full().camera.unwrap();
        let moved = pose.applied_to(&camera);
        assert_eq!(CameraPose::of(&moved), pose);
        assert_eq!(
            (moved.fov, moved.bounds_radius),
            (camera.fov, camera.bounds_radius)
        );
        let steep = CameraPose { pitch: 3.0, ..pose }.applied_to(&camera);
        assert_eq!(steep.pitch, PITCH_LIMIT);
    }
}
