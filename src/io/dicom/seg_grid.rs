//! A DICOM SEG's voxel grid from its functional groups, and its frames placed on it.
//!
//! Columns run along the first voxel axis, rows along the second, slices along the normal of
//! the image plane (row direction x column direction). A SEG stores only frames that hold some
//! of a segment, so the slice positions may skip empty slices: the grid spans the lowest to the
//! highest position, every gap a whole multiple of the slice spacing: Spacing Between Slices
//! where the file declares it, else the smallest gap. Segments that overlap go to separate
//! layers.

use dicom_dictionary_std::tags;
use dicom_object::mem::InMemDicomObject;

use super::seg::{first_item, floats, Pixels};
use crate::io::label_map::{Affine, LabelLayer, MAX_LABELS};
use crate::io::label_map_checks::{check_affine, MAX_LAYERS, MAX_VOXEL_BYTES};
use crate::io::{Format, LoadError, Location};

const FORMAT: Format = Format::DicomSeg;

/// Positions closer than this (mm) along the normal are one slice; DICOM's decimal strings
/// carry far more precision, and no voxel is this thin.
const SAME_SLICE: f64 = 1e-3;
/// How far (as a fraction of a voxel) a frame may sit off the grid and still be placed on it.
const OFF_GRID: f64 = 0.01;
/// The most voxels (all layers together) a SEG's grid may hold beyond what its frames cover:
/// frames may skip slices, so the grid is not bounded by the pixel data, and a lying position
/// or spacing must not cost gigabytes. Empty slices between segments, 63 for each frame, and
/// this many voxels more, are allowed.
const SPARE_VOXELS: usize = 1 << 24;
const SLICES_PER_FRAME: usize = 64;

/// What the per-frame functional groups say of one frame.
#[derive(Debug, Clone, Copy)]
pub(in crate::io) struct FrameGeometry {
    /// Image Position (Patient), LPS millimetres.
    pub position: [f64; 3],
    pub segment: u16,
    /// The frame's own Plane Orientation, when it has one.
    pub orientation: Option<[f64; 6]>,
}

/// The grid and where each frame lies on it.
#[derive(Debug)]
pub(in crate::io) struct Grid {
    pub dims: [usize; 3],
    /// Voxel index to RAS millimetres.
    pub affine: Affine,
    /// Each frame's slice index.
    slices: Vec<usize>,
    /// The most voxels its layers may hold together (see [`SPARE_VOXELS`]).
    budget: usize,
}

/// A frame's Plane Orientation (Patient), if it has one.
pub(in crate::io) fn orientation_of(group: &InMemDicomObject) -> Option<[f64; 6]> {
    let plane = first_item(group, tags::PLANE_ORIENTATION_SEQUENCE)?;
    <[f64; 6]>::try_from(floats(plane, tags::IMAGE_ORIENTATION_PATIENT)?).ok()
}

fn error(detail: String) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail,
    }
}

/// Voxel index to RAS millimetres for a grid whose `i, j, k` axes run along `axes` (unit, LPS)
/// `spacing` apart, voxel 0 at `origin` (LPS): DICOM's patient frame is LPS.
pub(in crate::io) fn ras_affine(
    axes: [[f64; 3]; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
) -> Affine {
    Affine(std::array::from_fn(|r| {
        // LPS to RAS: the first two world axes change sign.
        let sign = if r < 2 { -1.0 } else { 1.0 };
        [
            sign * axes[0][r] * spacing[0],
            sign * axes[1][r] * spacing[1],
            sign * axes[2][r] * spacing[2],
            sign * origin[r],
        ]
    }))
}

pub(in crate::io) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(in crate::io) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(v: [f64; 3], what: &str) -> Result<[f64; 3], LoadError> {
    let n = dot(v, v).sqrt();
    if !(n > 0.5 && n < 1.5) {
        return Err(error(format!(
            "the {what} direction {v:?} is not a unit vector"
        )));
    }
    Ok(v.map(|c| c / n))
}

impl Grid {
    /// Places the frames of a `[columns, rows]` image: orientation and pixel spacing from the
    /// shared functional groups (else the first frame's), slices from the frames' positions.
    pub(in crate::io) fn place(
        size: [usize; 2],
        shared: Option<&InMemDicomObject>,
        frames: &[FrameGeometry],
    ) -> Result<Grid, LoadError> {
        let [row, column] = plane_directions(shared, frames)?;
        let normal = cross(row, column);
        let measures = shared.and_then(|s| first_item(s, tags::PIXEL_MEASURES_SEQUENCE));
        let spacing = measures
            .and_then(|m| floats(m, tags::PIXEL_SPACING))
            .and_then(|v| <[f64; 2]>::try_from(v).ok())
            .ok_or_else(|| error("no Pixel Spacing in the shared functional groups".into()))?;
        // Pixel Spacing is (between rows, between columns).
        let (along_row, along_column) = (spacing[1], spacing[0]);
        let between = measures.and_then(|m| floats(m, tags::SPACING_BETWEEN_SLICES));
        let thickness = measures.and_then(|m| floats(m, tags::SLICE_THICKNESS));
        let first = frames.first().ok_or_else(|| error("no frames".into()))?;
        let lowest = (frames.iter())
            .min_by(|a, b| dot(a.position, normal).total_cmp(&dot(b.position, normal)))
            .unwrap_or(first);
        let origin = lowest.position;
        check_in_plane(frames, origin, [row, column], [along_row, along_column])?;
        let heights: Vec<f64> = (frames.iter())
            .map(|f| dot(f.position, normal) - dot(origin, normal))
            .collect();
        let fallback = (between.as_deref().and_then(|v| v.first().copied()))
            .or(thickness.as_deref().and_then(|v| v.first().copied()));
        let step = slice_step(&heights, fallback, along_row.min(along_column))?;
        let slices: Vec<usize> = heights
            .iter()
            .map(|h| (h / step).round() as usize)
            .collect();
        let count = slices.iter().max().map_or(1, |k| k + 1);
        let dims = [size[0], size[1], count];
        let plane = size[0] * size[1];
        let budget = (frames.len() * plane).saturating_mul(SLICES_PER_FRAME) + SPARE_VOXELS;
        if plane.saturating_mul(count) > budget {
            return Err(error(format!(
                "{} frames span {count} slices of {} x {} pixels: the slice positions or spacing \
                 cannot be right",
                frames.len(),
                size[0],
                size[1]
            )));
        }
        let affine = ras_affine(
            [row, column, normal],
            [along_row, along_column, step],
            origin,
        );
        let location = Location::Item("frame", 1);
        check_affine(&affine, FORMAT, location, "the plane geometry")?;
        Ok(Grid {
            dims,
            affine,
            slices,
            budget,
        })
    }
}

/// The frames' row and column directions: the shared functional groups' plane orientation, else
/// the first frame's; every frame that states its own must agree.
fn plane_directions(
    shared: Option<&InMemDicomObject>,
    frames: &[FrameGeometry],
) -> Result<[[f64; 3]; 2], LoadError> {
    let orientation = shared
        .and_then(orientation_of)
        .or_else(|| frames.first().and_then(|f| f.orientation))
        .ok_or_else(|| error("no Plane Orientation (Image Orientation (Patient))".into()))?;
    for (index, frame) in frames.iter().enumerate() {
        let differs = (frame.orientation).is_some_and(|o| {
            o.iter()
                .zip(&orientation)
                .any(|(a, b)| (a - b).abs() > 1e-4)
        });
        if differs {
            return Err(error(format!(
                "frame {}: its plane orientation differs from the others'; frames of one \
                     segmentation must be parallel",
                index + 1
            )));
        }
    }
    let row = unit([orientation[0], orientation[1], orientation[2]], "row")?;
    let column = unit([orientation[3], orientation[4], orientation[5]], "column")?;
    if dot(row, column).abs() > 1e-3 {
        return Err(error(
            "the row and column directions are not perpendicular".into(),
        ));
    }
    Ok([row, column])
}

/// Refuses a frame shifted within the image plane from `origin` by more than [`OFF_GRID`]
/// pixels: the frames of one grid differ only along its normal.
fn check_in_plane(
    frames: &[FrameGeometry],
    origin: [f64; 3],
    [row, column]: [[f64; 3]; 2],
    [along_row, along_column]: [f64; 2],
) -> Result<(), LoadError> {
    for (index, frame) in frames.iter().enumerate() {
        let d: [f64; 3] = std::array::from_fn(|a| frame.position[a] - origin[a]);
        let off = (dot(d, row) / along_row)
            .abs()
            .max((dot(d, column) / along_column).abs());
        if off > OFF_GRID {
            return Err(error(format!(
                "frame {}: its position is shifted within the image plane from the lowest \
                     frame's by {off:.3} pixels",
                index + 1
            )));
        }
    }
    Ok(())
}

/// The slice spacing: `declared` (Spacing Between Slices), else the smallest gap between
/// distinct heights; every gap must be a whole multiple of it, since a frame between slices
/// has no voxel to go to. With a single slice, `declared` (else the in-plane pixel size) only
/// sets the voxel's thickness.
fn slice_step(heights: &[f64], declared: Option<f64>, pixel: f64) -> Result<f64, LoadError> {
    let mut distinct: Vec<f64> = heights.to_vec();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup_by(|a, b| (*a - *b).abs() < SAME_SLICE);
    let gaps: Vec<f64> = distinct.windows(2).map(|w| w[1] - w[0]).collect();
    let declared = declared.filter(|d| d.is_finite() && *d > SAME_SLICE);
    let smallest = gaps.iter().copied().min_by(f64::total_cmp);
    let Some(step) = declared.or(smallest) else {
        return Ok(pixel);
    };
    if let Some(odd) = gaps.iter().find(|g| !whole_multiple(**g, step)) {
        return Err(error(format!(
            "the slice positions are not evenly spaced: a gap of {odd:.4} mm between slices \
             {step:.4} mm apart"
        )));
    }
    Ok(step)
}

fn whole_multiple(gap: f64, step: f64) -> bool {
    (gap / step - (gap / step).round()).abs() < OFF_GRID
}

/// Writes every frame's pixels into label layers, one code per segment; a segment goes to the
/// first layer where it overlaps no other (3D Slicer's rule for overlapping segments). Returns
/// the layers and each segment's layer, in the order of `segments`.
pub(in crate::io) fn fill(
    grid: &Grid,
    frames: &[FrameGeometry],
    segments: &[u16],
    data: &[u8],
    pixels: Pixels,
) -> Result<(Vec<LabelLayer>, Vec<usize>), LoadError> {
    if let Pixels::Labels { bytes } = pixels {
        return fill_labels(grid, frames.len(), segments, data, bytes);
    }
    let plane = grid.dims[0] * grid.dims[1];
    let voxels = plane * grid.dims[2];
    let mut layers: Vec<LabelLayer> = Vec::new();
    let mut placed = Vec::with_capacity(segments.len());
    for &segment in segments {
        let mine: Vec<usize> = (0..frames.len())
            .filter(|&f| frames[f].segment == segment)
            .collect();
        let overlaps = |layer: &LabelLayer| {
            mine.iter().any(|&f| {
                let base = grid.slices[f] * plane;
                in_segment(data, pixels, f * plane, plane, |p| {
                    layer.codes[base + p] != 0
                })
            })
        };
        let free = layers
            .iter()
            .position(|l| l.values.len() < MAX_LABELS + 1 && !overlaps(l));
        let index = match free {
            Some(index) => index,
            None => {
                layers.push(new_layer(voxels, layers.len(), grid.budget)?);
                layers.len() - 1
            }
        };
        let layer = &mut layers[index];
        let code = layer.values.len() as u16;
        layer.values.push(i64::from(segment));
        for &f in &mine {
            let base = grid.slices[f] * plane;
            in_segment(data, pixels, f * plane, plane, |p| {
                layer.codes[base + p] = code;
                false
            });
        }
        placed.push(index);
    }
    Ok((layers, placed))
}

/// A LABELMAP's frames into one layer: each pixel's segment number to its segment's code.
/// Segments cannot overlap in a label map, so every segment is in layer 0.
fn fill_labels(
    grid: &Grid,
    frames: usize,
    segments: &[u16],
    data: &[u8],
    bytes: usize,
) -> Result<(Vec<LabelLayer>, Vec<usize>), LoadError> {
    if segments.len() > MAX_LABELS {
        return Err(error(format!(
            "{} segments: a label map holds at most {MAX_LABELS}",
            segments.len()
        )));
    }
    let plane = grid.dims[0] * grid.dims[1];
    let mut layer = new_layer(plane * grid.dims[2], 0, grid.budget)?;
    // Segment number to code: 0 stays background, an undeclared number is refused.
    let mut code_of = vec![None; 1 << (8 * bytes)];
    code_of[0] = Some(0u16);
    for (index, &number) in segments.iter().enumerate() {
        code_of[usize::from(number)] = Some(index as u16 + 1);
        layer.values.push(i64::from(number));
    }
    for f in 0..frames {
        let base = grid.slices[f] * plane;
        for p in 0..plane {
            let at = (f * plane + p) * bytes;
            let number = match bytes {
                1 => usize::from(data[at]),
                _ => usize::from(u16::from_le_bytes([data[at], data[at + 1]])),
            };
            let code = code_of[number].ok_or_else(|| {
                error(format!(
                    "frame {}: pixel value {number} is no segment the Segment Sequence declares",
                    f + 1
                ))
            })?;
            if code != 0 {
                layer.codes[base + p] = code;
            }
        }
    }
    Ok((vec![layer], vec![0; segments.len()]))
}

fn new_layer(voxels: usize, existing: usize, budget: usize) -> Result<LabelLayer, LoadError> {
    let total = (voxels as u128) * (existing as u128 + 1);
    if existing >= MAX_LAYERS || total * 2 > u128::from(MAX_VOXEL_BYTES) || total > budget as u128 {
        return Err(error(format!(
            "{voxels} voxels in {} layer(s) of overlapping segments: more than a label map may \
             hold",
            existing + 1
        )));
    }
    let mut codes = Vec::new();
    codes
        .try_reserve_exact(voxels)
        .map_err(|_| error(format!("cannot allocate {voxels} voxels")))?;
    codes.resize(voxels, 0u16);
    Ok(LabelLayer {
        codes,
        values: vec![0],
    })
}

/// Calls `visit` with each of `count` pixels from pixel `first` that is in the segment, until it
/// returns true (then returns true). Binary frames skip zero bytes eight pixels at a time: most
/// of a frame is outside its segment.
fn in_segment(
    data: &[u8],
    pixels: Pixels,
    first: usize,
    count: usize,
    mut visit: impl FnMut(usize) -> bool,
) -> bool {
    match pixels {
        Pixels::Binary => {
            let mut p = 0;
            while p < count {
                let bit = first + p;
                let byte = data[bit / 8];
                if bit.is_multiple_of(8) && byte == 0 && p + 8 <= count {
                    p += 8;
                    continue;
                }
                if byte & (1 << (bit % 8)) != 0 && visit(p) {
                    return true;
                }
                p += 1;
            }
            false
        }
        Pixels::Fractional { threshold } => {
            (0..count).any(|p| data[first + p] >= threshold && visit(p))
        }
        // A label map's frames are not one segment's: `fill_labels` reads them.
        Pixels::Labels { .. } => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skipped_slices_keep_the_spacing_and_uneven_ones_are_refused() {
        assert_eq!(slice_step(&[0.0, 1.5, 6.0, 7.5], None, 1.0), Ok(1.5));
        assert_eq!(slice_step(&[0.0, 3.0, 6.0], Some(1.5), 1.0), Ok(1.5));
        // A frame between the declared slices has nowhere to go.
        assert!(slice_step(&[0.0, 2.0, 4.0], Some(1.5), 1.0).is_err());
        assert_eq!(slice_step(&[2.0, 2.0], None, 0.8), Ok(0.8));
        assert!(slice_step(&[0.0, 1.0, 2.5], None, 1.0).is_err());
    }
}
