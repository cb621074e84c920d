//! A DICOM image series (CT or MR, one slice a file, as scanners and PACS exports write them)
//! into an [`ImageVolume`]: the image a segmentation was drawn on.
//!
//! The parsing is `dicom-object`'s, after [`super::lengths`] has checked every declared
//! length against the file's bytes. What is read: single-frame, single-sample (grey) slices of
//! 8, 16 or 32 bits, little-endian, uncompressed (or the data set deflated), RLE Lossless, JPEG
//! (baseline, extended or lossless), JPEG-LS or JPEG 2000 ([`super::frames`]), each with
//! its own Rescale Slope and Intercept; where fewer bits are stored than allocated, only the stored
//! (low) ones are read, so that old files' overlay bits above them are not taken for values.
//! The slices are placed by Image Position (Patient) along the normal of their common Image
//! Orientation, whatever the files' order or Instance Numbers. Refused, with the file or the
//! reason named: slices of different series, sizes, orientations or pixel spacings; two slices
//! at one position; slices shifted within their plane (a gantry tilt); uneven slice spacing (a
//! slice missing); multi-frame (enhanced) objects, colour, MONOCHROME1, other compressions.
//! Nothing of the header but the geometry and the pixels is kept.

use std::borrow::Cow;

use dicom_core::Tag;
use dicom_dictionary_std::tags;
use dicom_object::mem::InMemDicomObject;

use super::frames::Frames;
use super::lengths;
use super::seg::{floats, text, whole_above_zero};
use super::seg_grid::{cross, dot, ras_affine};
use crate::io::image::{reduced_affine, ImageVolume};
use crate::io::intensity::IntensitySink;
use crate::io::label_map_checks::{check_affine, Sample, VoxelLayout};
use crate::io::voxels::Feed;
use crate::io::{Format, LoadError, Location};

const FORMAT: Format = Format::DicomImage;
const SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.4";
/// Directions and spacings this close are the same (DICOM writes them as decimal strings).
const SAME: f64 = 1e-4;
/// Slices shifted within their plane by more than this fraction of a pixel are refused.
const OFF_GRID: f64 = 0.01;

/// Why a series could not be read: one file's fault, or the files' together.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SeriesError {
    #[error("{name}: {error}")]
    File { name: String, error: LoadError },
    #[error("{0}")]
    Series(String),
}

/// One file of a series as read: its geometry and its pixels, still in the file's bytes.
struct Slice<'a> {
    name: &'a str,
    series: String,
    /// Columns, rows.
    size: [usize; 2],
    orientation: [f64; 6],
    /// Pixel Spacing: between rows, between columns.
    spacing: [f64; 2],
    /// Image Position (Patient), LPS millimetres.
    position: [f64; 3],
    thickness: Option<f64>,
    sample: Sample,
    /// Bits Stored, where fewer than the sample's.
    low_bits: Option<u32>,
    slope: f64,
    inter: f64,
    /// In the file's bytes where uncompressed.
    pixels: Cow<'a, [u8]>,
}

/// Reads the slices `files` (name, bytes) as one image, reduced by the smallest whole factor
/// that leaves at most `max_voxels` voxels.
pub fn load_image_series(
    files: &[(&str, &[u8])],
    max_voxels: usize,
) -> Result<ImageVolume, SeriesError> {
    let mut slices = (files.iter())
        .map(|&(name, bytes)| {
            read_slice(name, bytes).map_err(|error| SeriesError::File {
                name: name.to_string(),
                error,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let first = slices
        .first()
        .ok_or_else(|| series("no slice given".into()))?;
    alike(first, &slices)?;
    let axes = axes(first)?;
    slices.sort_by(|a, b| dot(a.position, axes[2]).total_cmp(&dot(b.position, axes[2])));
    let step = slice_step(&slices, &axes)?;
    let first = &slices[0];
    let (columns, rows) = (first.size[0], first.size[1]);
    let spacing = [first.spacing[1], first.spacing[0], step];
    let affine = ras_affine(axes, spacing, slices[0].position);
    let at = Location::Item("slice", 1);
    check_affine(&affine, FORMAT, at, "the slice geometry").map_err(series_of)?;
    let layout = VoxelLayout {
        dims: [columns, rows, slices.len()],
        layers: 1,
        interleaved: false,
        sample: first.sample,
        big_endian: false,
        slope: 1.0,
        inter: 0.0,
    };
    layout.data_bytes(FORMAT).map_err(series_of)?;
    let mut sink = IntensitySink::new(&layout, FORMAT, max_voxels).map_err(series_of)?;
    let plane = columns * rows * first.sample.size();
    for slice in &slices {
        sink.rescale(slice.slope, slice.inter);
        let pixels = &slice.pixels[..plane];
        match slice.low_bits {
            Some(bits) => sink.feed(&only_stored(pixels, slice.sample, bits)),
            None => sink.feed(pixels),
        }
        .map_err(series_of)?;
    }
    let factor = sink.factor();
    let (dims, values) = sink.finish(FORMAT).map_err(series_of)?;
    Ok(ImageVolume {
        dims,
        affine: reduced_affine(&affine, factor),
        values,
        source_dims: layout.dims,
        source_affine: affine,
    })
}

fn series(detail: String) -> SeriesError {
    SeriesError::Series(detail)
}

fn series_of(error: LoadError) -> SeriesError {
    SeriesError::Series(error.to_string())
}

fn unsupported(detail: String) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail,
    }
}

fn read_slice<'a>(name: &'a str, bytes: &'a [u8]) -> Result<Slice<'a>, LoadError> {
    let (layout, object) = lengths::open(bytes, FORMAT)?;
    if text(&object, tags::SOP_CLASS_UID).as_deref() == Some(SEGMENTATION_STORAGE) {
        return Err(unsupported(
            "a segmentation (DICOM SEG), not an image: open it as the case's structures".into(),
        ));
    }
    let frames = whole(&object, tags::NUMBER_OF_FRAMES).unwrap_or(1);
    if frames != 1 {
        return Err(unsupported(format!(
            "a multi-frame image ({frames} frames): meshsmooth reads a series of one slice a file"
        )));
    }
    let samples = whole(&object, tags::SAMPLES_PER_PIXEL).unwrap_or(1);
    let photometric = text(&object, tags::PHOTOMETRIC_INTERPRETATION).unwrap_or_default();
    if samples != 1 || photometric != "MONOCHROME2" {
        return Err(unsupported(format!(
            "{samples} samples a pixel, photometric interpretation '{photometric}': only grey \
             images (MONOCHROME2) are read"
        )));
    }
    let size = [
        whole_above_zero(&object, tags::COLUMNS, "Columns", FORMAT)?,
        whole_above_zero(&object, tags::ROWS, "Rows", FORMAT)?,
    ];
    let sample = sample_of(&object)?;
    let low_bits = stored_bits(&object, sample)?;
    let frame = Frames {
        count: 1,
        size,
        bits: 8 * sample.size(),
    };
    let what = "bytes of pixel data for the rows and columns declared";
    let pixels = layout.pixels(bytes, frame, what, FORMAT)?;
    let scale = |tag, default| match floats(&object, tag) {
        None => Ok(default),
        Some(v) if v.len() == 1 && v[0].is_finite() => Ok(v[0]),
        Some(v) => Err(unsupported(format!(
            "the rescale value {v:?} is not one finite number"
        ))),
    };
    Ok(Slice {
        name,
        series: text(&object, tags::SERIES_INSTANCE_UID).unwrap_or_default(),
        size,
        orientation: numbers(
            &object,
            tags::IMAGE_ORIENTATION_PATIENT,
            "Image Orientation",
        )?,
        spacing: numbers(&object, tags::PIXEL_SPACING, "Pixel Spacing")?,
        position: numbers(&object, tags::IMAGE_POSITION_PATIENT, "Image Position")?,
        thickness: floats(&object, tags::SLICE_THICKNESS).and_then(|v| v.first().copied()),
        sample,
        low_bits,
        slope: scale(tags::RESCALE_SLOPE, 1.0)?,
        inter: scale(tags::RESCALE_INTERCEPT, 0.0)?,
        pixels,
    })
}

/// A whole number element, `None` when absent or not a number.
fn whole(object: &InMemDicomObject, tag: Tag) -> Option<usize> {
    let value: u32 = object.element(tag).ok()?.to_int().ok()?;
    Some(value as usize)
}

/// `N` finite numbers of a decimal-string element (a direction, a spacing, a position).
fn numbers<const N: usize>(
    object: &InMemDicomObject,
    tag: Tag,
    name: &str,
) -> Result<[f64; N], LoadError> {
    (floats(object, tag))
        .and_then(|v| <[f64; N]>::try_from(v).ok())
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .ok_or_else(|| unsupported(format!("no {name} of {N} finite numbers")))
}

fn sample_of(object: &InMemDicomObject) -> Result<Sample, LoadError> {
    let bits = whole(object, tags::BITS_ALLOCATED).unwrap_or(0);
    let signed = whole(object, tags::PIXEL_REPRESENTATION) == Some(1);
    Ok(match (bits, signed) {
        (8, false) => Sample::U8,
        (8, true) => Sample::I8,
        (16, false) => Sample::U16,
        (16, true) => Sample::I16,
        (32, false) => Sample::U32,
        (32, true) => Sample::I32,
        _ => {
            return Err(unsupported(format!(
                "{bits} bits allocated a pixel: 8, 16 or 32 are read"
            )))
        }
    })
}

/// Bits Stored where fewer than the sample's bits, the value in the low ones (High Bit one
/// below Bits Stored, as CT and MR write them; other placements are refused).
fn stored_bits(object: &InMemDicomObject, sample: Sample) -> Result<Option<u32>, LoadError> {
    let allocated = 8 * sample.size();
    let stored = whole(object, tags::BITS_STORED).unwrap_or(allocated);
    let high = whole(object, tags::HIGH_BIT).unwrap_or(stored.wrapping_sub(1));
    if stored == 0 || stored > allocated || high + 1 != stored {
        return Err(unsupported(format!(
            "{stored} bits stored of {allocated}, high bit {high}: the value must fill the low \
             bits"
        )));
    }
    Ok((stored < allocated).then_some(stored as u32))
}

/// `pixels` with only each sample's low `bits` kept, sign-extended from them where the sample
/// is signed.
fn only_stored(pixels: &[u8], sample: Sample, bits: u32) -> Vec<u8> {
    let width = sample.size();
    let signed = matches!(sample, Sample::I8 | Sample::I16 | Sample::I32);
    let unused = 64 - bits;
    let mut out = Vec::with_capacity(pixels.len());
    for chunk in pixels.chunks_exact(width) {
        let mut word = [0u8; 8];
        word[..width].copy_from_slice(chunk);
        let raised = u64::from_le_bytes(word) << unused;
        let value = match signed {
            true => ((raised as i64) >> unused) as u64,
            false => raised >> unused,
        };
        out.extend_from_slice(&value.to_le_bytes()[..width]);
    }
    out
}

/// Refuses slices that cannot be one image: another series, size, orientation, spacing or
/// pixel type than the first's.
fn alike(first: &Slice, slices: &[Slice]) -> Result<(), SeriesError> {
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= SAME);
    for s in slices {
        let differs = if s.series != first.series {
            "belong to different series: give the files of one series"
        } else if s.size != first.size {
            "have different numbers of rows or columns"
        } else if !close(&s.orientation, &first.orientation) {
            "are not parallel (their Image Orientation differs)"
        } else if !close(&s.spacing, &first.spacing) {
            "have different pixel spacings"
        } else if s.sample != first.sample {
            "store their pixels differently (bits or sign)"
        } else {
            continue;
        };
        return Err(series(format!("{} and {} {differs}", first.name, s.name)));
    }
    Ok(())
}

/// The unit `i, j, k` axes (LPS): along a row, down a column, and their normal.
fn axes(first: &Slice) -> Result<[[f64; 3]; 3], SeriesError> {
    let o = first.orientation;
    let unit = |v: [f64; 3]| {
        let n = dot(v, v).sqrt();
        (n > 0.5 && n < 1.5).then(|| v.map(|c| c / n))
    };
    let (Some(row), Some(column)) = (unit([o[0], o[1], o[2]]), unit([o[3], o[4], o[5]])) else {
        return Err(series(format!(
            "{}: the Image Orientation {o:?} is not two unit directions",
            first.name
        )));
    };
    if dot(row, column).abs() > 1e-3 || !first.spacing.iter().all(|&s| s > 0.0) {
        return Err(series(format!(
            "{}: the row and column directions are not perpendicular, or a pixel spacing is not \
             above 0",
            first.name
        )));
    }
    Ok([row, column, cross(row, column)])
}

/// The distance between slices (`slices` sorted along the normal), after refusing two at one
/// position, a slice shifted within the plane and uneven spacing.
fn slice_step(slices: &[Slice], axes: &[[f64; 3]; 3]) -> Result<f64, SeriesError> {
    let lowest = &slices[0];
    let pixel = [lowest.spacing[1], lowest.spacing[0]];
    for s in slices {
        let d: [f64; 3] = std::array::from_fn(|a| s.position[a] - lowest.position[a]);
        let off = (dot(d, axes[0]) / pixel[0])
            .abs()
            .max((dot(d, axes[1]) / pixel[1]).abs());
        if off > OFF_GRID {
            return Err(series(format!(
                "{} lies {off:.2} pixels off {}'s column of slices within the slice plane (a \
                 gantry tilt or a reformatted series): such slices are not read",
                s.name, lowest.name
            )));
        }
    }
    let height = |s: &Slice| dot(s.position, axes[2]);
    let gaps: Vec<(f64, usize)> = (slices.windows(2).enumerate())
        .map(|(i, w)| (height(&w[1]) - height(&w[0]), i))
        .collect();
    if let Some(&(_, i)) = gaps.iter().find(|(g, _)| *g < 1e-3) {
        return Err(series(format!(
            "{} and {} lie at the same position",
            slices[i].name,
            slices[i + 1].name
        )));
    }
    let Some(step) = gaps.iter().map(|g| g.0).min_by(f64::total_cmp) else {
        let thickness = lowest.thickness.filter(|t| t.is_finite() && *t > 0.0);
        return Ok(thickness.unwrap_or(pixel[0].min(pixel[1])));
    };
    if let Some(&(gap, i)) = gaps.iter().find(|(g, _)| (g - step).abs() > 0.01 * step) {
        return Err(series(format!(
            "the slices are not evenly spaced: {} and {} lie {gap:.3} mm apart, others {step:.3} \
             mm (a slice missing?)",
            slices[i].name,
            slices[i + 1].name
        )));
    }
    // The mean gap: positions are rounded decimal strings.
    let span = height(&slices[slices.len() - 1]) - height(lowest);
    Ok(span / (slices.len() - 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_stored_bits_are_kept_signed_values_extended_from_them() {
        let le = |v: &[u16]| v.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
        // -1000 in 12 bits is 0xC18; an overlay bit above it is dropped either way.
        let pixels = le(&[0xAC18, 0x03E8, 0x07FF, 0x0800]);
        let signed = le(&[0xFC18, 0x03E8, 0x07FF, 0xF800]);
        assert_eq!(only_stored(&pixels, Sample::I16, 12), signed);
        let unsigned = le(&[0x0C18, 0x03E8, 0x07FF, 0x0800]);
        assert_eq!(only_stored(&pixels, Sample::U16, 12), unsigned);
        assert_eq!(only_stored(&[0xF3, 0x1C], Sample::I8, 4), [0x03, 0xFC]);
    }
}
