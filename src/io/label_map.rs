//! The label map as the parsers hand it over: a voxel grid of label codes, its affine into world
//! millimetres (RAS), and the segment names and colours the file carried; and how to read one.

use super::codes::StructureCodes;

/// How to read a label map.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LabelMapOptions {
    /// Threshold for images whose values are not whole numbers (float probability maps): voxels
    /// at or above it become label 1. `None`: 0.5, and float images holding only whole numbers
    /// stay label maps. `Some`: every float image (or one scaled by a fractional slope) is
    /// thresholded. Integer images ignore it.
    pub level: Option<f64>,
}

/// The level used when [`LabelMapOptions::level`] is `None`.
pub(super) const DEFAULT_LEVEL: f64 = 0.5;

/// The most distinct labels one layer can hold (codes are `u16`, code 0 is background).
pub const MAX_LABELS: usize = u16::MAX as usize;

/// Voxel index `(i, j, k)` to world RAS millimetres: `world = m * [i, j, k, 1]`, row-major rows
/// of a 3 x 4 matrix.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Affine(pub [[f64; 4]; 3]);

impl Affine {
    /// Axis-aligned grid with the given spacing and origin (voxel (0,0,0) at `origin`).
    pub fn scaled(spacing: [f64; 3], origin: [f64; 3]) -> Self {
        let mut m = [[0.0; 4]; 3];
        for r in 0..3 {
            m[r][r] = spacing[r];
            m[r][3] = origin[r];
        }
        Affine(m)
    }

    /// The world point of a (possibly fractional) voxel index.
    pub fn apply(&self, ijk: [f64; 3]) -> [f64; 3] {
        let m = &self.0;
        std::array::from_fn(|r| m[r][0] * ijk[0] + m[r][1] * ijk[1] + m[r][2] * ijk[2] + m[r][3])
    }

    /// The voxel index of a world point; `None` when the grid is degenerate.
    pub fn inverse_apply(&self, world: [f64; 3]) -> Option<[f64; 3]> {
        let m = &self.0;
        let det = self.determinant();
        if !det.is_normal() {
            return None;
        }
        let d: [f64; 3] = std::array::from_fn(|r| world[r] - m[r][3]);
        // Cramer's rule: the index is the solution of the linear part times it = d.
        let column = |c: usize| -> [f64; 3] { std::array::from_fn(|r| m[r][c]) };
        let (a, b, c) = (column(0), column(1), column(2));
        let det3 = |x: [f64; 3], y: [f64; 3], z: [f64; 3]| {
            x[0] * (y[1] * z[2] - y[2] * z[1]) - y[0] * (x[1] * z[2] - x[2] * z[1])
                + z[0] * (x[1] * y[2] - x[2] * y[1])
        };
        Some([
            det3(d, b, c) / det,
            det3(a, d, c) / det,
            det3(a, b, d) / det,
        ])
    }

    /// Length of each voxel axis in mm (the columns' norms).
    pub fn spacing(&self) -> [f64; 3] {
        let m = &self.0;
        std::array::from_fn(|c| (0..3).map(|r| m[r][c] * m[r][c]).sum::<f64>().sqrt())
    }

    /// Determinant of the linear part: negative when the grid is mirrored against RAS (its
    /// triangles must then be wound the other way to face outward).
    pub fn determinant(&self) -> f64 {
        let m = &self.0;
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }
}

/// One volume of labels. Voxels are stored as dense codes (`i` fastest, then `j`, then `k`) into
/// `values`, so that any integer label type costs two bytes a voxel.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelLayer {
    /// Per voxel, an index into `values`; code 0 is background.
    pub codes: Vec<u16>,
    /// The label value (as the file stores it, after `scl_slope`/`scl_inter`) of each code;
    /// `values[0]` is 0, the background.
    pub values: Vec<i64>,
}

/// A named segment the file declares (3D Slicer's `SegmentN_*` keys, a DICOM SEG's segments):
/// which layer and label value it occupies, its name, display colour and codes.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub layer: usize,
    pub value: i64,
    pub name: String,
    /// Display (sRGB) colour, each channel in [0, 1].
    pub color: Option<[f32; 3]>,
    /// What the segment is in standard codes, where the file says (DICOM SEG, Slicer's tags).
    pub codes: Option<StructureCodes>,
}

/// A segmentation on one voxel grid: one layer (NIfTI, a plain NRRD) or several (a `.seg.nrrd`
/// whose segments overlap), every layer the same size.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelMap {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    pub affine: Affine,
    pub layers: Vec<LabelLayer>,
    /// Segments the file names; empty when it names none (then a colour table or the default
    /// names apply).
    pub segments: Vec<Segment>,
    /// Names and colours the format's convention gives the labels present (FreeSurfer's colour
    /// table for MGH), used where neither the file nor the author's colour table names a label.
    pub conventional: Vec<Segment>,
}

impl LabelMap {
    pub fn voxel_count(&self) -> usize {
        self.dims.iter().product()
    }

    /// Voxel size along i, j, k in mm.
    pub fn spacing(&self) -> [f64; 3] {
        self.affine.spacing()
    }
}
