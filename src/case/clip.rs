//! The cut and the image planes a case's reader sets and a lesson's tour step records: a plane
//! that cuts every structure to show what lies inside, and the image's three standard planes.
//! Both read the data's patient frame (RAS: +x the patient's right, +y anterior, +z superior).

use glam::Vec3;

/// The anatomical plane a clip lies in, by the axis it is perpendicular to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ClipAxis {
    /// Perpendicular to left-right (x).
    Sagittal,
    /// Perpendicular to anterior-posterior (y).
    Coronal,
    /// Perpendicular to inferior-superior (z).
    Axial,
}

impl ClipAxis {
    pub const ALL: [ClipAxis; 3] = [ClipAxis::Axial, ClipAxis::Coronal, ClipAxis::Sagittal];

    pub fn name(self) -> &'static str {
        match self {
            ClipAxis::Sagittal => "sagittal",
            ClipAxis::Coronal => "coronal",
            ClipAxis::Axial => "axial",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    fn unit(self) -> Vec3 {
        match self {
            ClipAxis::Sagittal => Vec3::X,
            ClipAxis::Coronal => Vec3::Y,
            ClipAxis::Axial => Vec3::Z,
        }
    }
}

/// A clipping plane across the scene: perpendicular to `axis`, at `at` (0 at the scene's low
/// end along it, 1 at its high end), cutting away what lies above it (right, anterior,
/// superior), or below it when `flip`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Clip {
    pub axis: ClipAxis,
    pub at: f32,
    pub flip: bool,
}

impl Clip {
    /// The plane `(n, d)` the shader cuts with (`n . p > d` is cut away) in a scene spanning
    /// `min..max`. A non-finite `at` counts as the middle.
    pub fn plane(&self, min: Vec3, max: Vec3) -> [f32; 4] {
        let n = self.axis.unit();
        let at = if self.at.is_finite() {
            self.at.clamp(0.0, 1.0)
        } else {
            0.5
        };
        let d = n.dot(min) + at * n.dot(max - min);
        if self.flip {
            [-n.x, -n.y, -n.z, -d]
        } else {
            [n.x, n.y, n.z, d]
        }
    }
}

/// The image's three standard planes shown together, as radiology viewers show them: each
/// at its place across the scene (0 at its low end, 1 at its high end) along x (sagittal),
/// y (coronal) and z (axial). They cut nothing.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Planes {
    pub sagittal: f32,
    pub coronal: f32,
    pub axial: f32,
}

impl Default for Planes {
    fn default() -> Self {
        Planes {
            sagittal: 0.5,
            coronal: 0.5,
            axial: 0.5,
        }
    }
}

impl Planes {
    /// Each plane `(n, d)` in a scene spanning `min..max`: sagittal, coronal, axial.
    pub fn planes(&self, min: Vec3, max: Vec3) -> [[f32; 4]; 3] {
        let at = [self.sagittal, self.coronal, self.axial];
        std::array::from_fn(|k| {
            let clip = Clip {
                axis: [ClipAxis::Sagittal, ClipAxis::Coronal, ClipAxis::Axial][k],
                at: at[k],
                flip: false,
            };
            clip.plane(min, max)
        })
    }
}
