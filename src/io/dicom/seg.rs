//! DICOM Segmentation objects (SEG, one multi-frame file): BINARY, FRACTIONAL and LABELMAP
//! segmentations into a [`LabelMap`], each segment with its label, recommended display colour
//! (CIELab) and coded category, type and type modifier.
//!
//! The parsing is `dicom-object`'s (dicom-rs, pure Rust, builds for wasm32), after
//! [`super::lengths`] has checked every declared length against the bytes. What is read:
//! little-endian files (explicit or implicit VR), uncompressed, RLE Lossless or JPEG (decoded
//! in [`super::rle`] and [`super::jpeg`]). Refused with a reason: other objects than
//! SEG, other compressions, big-endian encodings. The grid comes from the functional groups
//! ([`super::seg_grid`]).

use dicom_core::Tag;
use dicom_dictionary_std::tags;
use dicom_object::mem::InMemDicomObject;

use super::frames::Frames;
use super::lengths;
use super::seg_grid::{self, FrameGeometry, Grid};
use crate::io::codes::{Code, StructureCodes};
use crate::io::label_map::{LabelMap, LabelMapOptions, Segment, DEFAULT_LEVEL};
use crate::io::{Format, LoadError, Location};

const FORMAT: Format = Format::DicomSeg;
const SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.4";
/// A LABELMAP segmentation's own SOP class (DICOM 2024b on).
const LABEL_MAP_SEGMENTATION_STORAGE: &str = "1.2.840.10008.5.1.4.1.1.66.7";

/// How a SEG stores its pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::io) enum Pixels {
    /// One bit a pixel, frames packed back to back, least significant bit first.
    Binary,
    /// One byte a pixel: the segment's share of the voxel, out of `max`; in the segment when
    /// `value >= threshold`.
    Fractional { threshold: u8 },
    /// LABELMAP: each pixel the number of its segment (0 none), in `bytes` (1 or 2) little
    /// endian; a frame holds every segment of its slice.
    Labels { bytes: usize },
}

impl Pixels {
    /// Bits a pixel.
    fn bits(self) -> usize {
        match self {
            Pixels::Binary => 1,
            Pixels::Fractional { .. } => 8,
            Pixels::Labels { bytes } => 8 * bytes,
        }
    }
}

pub(in crate::io) fn parse(bytes: &[u8], options: &LabelMapOptions) -> Result<LabelMap, LoadError> {
    // The pixels are read in place, not copied into the object.
    let (layout, object) = lengths::open(bytes, FORMAT)?;
    let sop_class = text(&object, tags::SOP_CLASS_UID).unwrap_or_default();
    if sop_class != SEGMENTATION_STORAGE && sop_class != LABEL_MAP_SEGMENTATION_STORAGE {
        return Err(LoadError::BadMagic {
            format: FORMAT,
            detail: format!(
                "SOP class '{sop_class}', not Segmentation Storage ({SEGMENTATION_STORAGE})"
            ),
        });
    }
    let rows = number(&object, tags::ROWS, "Rows")?;
    let columns = number(&object, tags::COLUMNS, "Columns")?;
    let frames = number(&object, tags::NUMBER_OF_FRAMES, "Number of Frames")?;
    let pixels = pixels(&object, options)?;
    let segments = segments(&object, matches!(pixels, Pixels::Labels { .. }))?;
    let per_frame = frame_geometry(&object, frames, &segments, pixels)?;
    let frames = Frames {
        count: frames,
        size: [columns, rows],
        bits: pixels.bits(),
    };
    let what = "bytes of pixel data for the frames declared";
    let data = layout.pixels(bytes, frames, what, FORMAT)?;
    let shared = first_item(&object, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE);
    let grid = Grid::place([columns, rows], shared, &per_frame)?;
    let numbers: Vec<u16> = segments.iter().map(segment_number).collect();
    let (layers, placed) = seg_grid::fill(&grid, &per_frame, &numbers, &data, pixels)?;
    Ok(LabelMap {
        dims: grid.dims,
        affine: grid.affine,
        layers,
        segments: (segments.into_iter().zip(placed))
            .map(|(mut segment, layer)| {
                segment.layer = layer;
                segment
            })
            .collect(),
        conventional: Vec::new(),
    })
}

/// A segment's number, which [`segments`] keeps as its value.
fn segment_number(segment: &Segment) -> u16 {
    u16::try_from(segment.value).unwrap_or(0)
}

fn unsupported(detail: String) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail,
    }
}

pub(in crate::io) fn text(object: &InMemDicomObject, tag: Tag) -> Option<String> {
    let element = object.element(tag).ok()?;
    let value = element.to_str().ok()?;
    let value = value.trim_matches(|c: char| c == '\0' || c.is_whitespace());
    (!value.is_empty()).then(|| value.to_string())
}

fn number(object: &InMemDicomObject, tag: Tag, name: &str) -> Result<usize, LoadError> {
    whole_above_zero(object, tag, name, FORMAT)
}

/// A whole number element above 0 (Rows, say), `name` naming it in the error `format` says.
pub(in crate::io) fn whole_above_zero(
    object: &InMemDicomObject,
    tag: Tag,
    name: &str,
    format: Format,
) -> Result<usize, LoadError> {
    let unsupported = |detail: String| LoadError::Unsupported { format, detail };
    let element = (object.element(tag).ok())
        .ok_or_else(|| unsupported(format!("no {name} ({:04X},{:04X})", tag.0, tag.1)))?;
    let value: u32 = (element.to_int().ok())
        .ok_or_else(|| unsupported(format!("{name} is not a whole number")))?;
    if value == 0 {
        return Err(unsupported(format!("{name} is 0")));
    }
    Ok(value as usize)
}

pub(in crate::io) fn items(object: &InMemDicomObject, tag: Tag) -> &[InMemDicomObject] {
    (object.element(tag).ok())
        .and_then(|e| e.items())
        .unwrap_or_default()
}

pub(in crate::io) fn first_item(object: &InMemDicomObject, tag: Tag) -> Option<&InMemDicomObject> {
    items(object, tag).first()
}

pub(in crate::io) fn floats(object: &InMemDicomObject, tag: Tag) -> Option<Vec<f64>> {
    let element = object.element(tag).ok()?;
    element.to_multi_float64().ok()
}

/// The pixel encoding the segmentation type and bit depth declare.
fn pixels(object: &InMemDicomObject, options: &LabelMapOptions) -> Result<Pixels, LoadError> {
    let kind = text(object, tags::SEGMENTATION_TYPE).unwrap_or_default();
    let bits = number(object, tags::BITS_ALLOCATED, "Bits Allocated")?;
    match (kind.as_str(), bits) {
        ("BINARY", 1) => Ok(Pixels::Binary),
        ("FRACTIONAL", 8) => {
            let max = number(
                object,
                tags::MAXIMUM_FRACTIONAL_VALUE,
                "Maximum Fractional Value",
            )?;
            let level = options.level.unwrap_or(DEFAULT_LEVEL);
            if !(0.0..=1.0).contains(&level) {
                return Err(unsupported(format!(
                    "the level {level} is not a fraction between 0 and 1"
                )));
            }
            let threshold = (level * max as f64).ceil().clamp(1.0, 255.0) as u8;
            Ok(Pixels::Fractional { threshold })
        }
        ("LABELMAP", 8 | 16) => Ok(Pixels::Labels { bytes: bits / 8 }),
        (kind, bits) => Err(unsupported(format!(
            "segmentation type '{kind}' with {bits} bits a pixel: BINARY (1 bit), FRACTIONAL \
             (8 bits) and LABELMAP (8 or 16 bits) are read"
        ))),
    }
}

/// The segments the Segment Sequence declares, by number (the value): name, colour and codes
/// (the layer is set once the voxels are placed). A label map's segment 0, its background, is
/// left out.
fn segments(object: &InMemDicomObject, labels: bool) -> Result<Vec<Segment>, LoadError> {
    let mut out: Vec<Segment> = Vec::new();
    for (index, item) in items(object, tags::SEGMENT_SEQUENCE).iter().enumerate() {
        let number = (item.element(tags::SEGMENT_NUMBER).ok())
            .and_then(|e| e.to_int::<u16>().ok())
            .filter(|&n| n > 0 || labels)
            .ok_or_else(|| LoadError::Syntax {
                format: FORMAT,
                location: Location::Item("segment", index + 1),
                detail: "no Segment Number from 1 to 65535".into(),
            })?;
        if number == 0 {
            continue;
        }
        if out.iter().any(|s| segment_number(s) == number) {
            return Err(unsupported(format!(
                "segment number {number} is declared twice"
            )));
        }
        let name = text(item, tags::SEGMENT_LABEL).unwrap_or_else(|| format!("Segment {number}"));
        let color = (item.element(tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE).ok())
            .and_then(|e| e.to_multi_int::<u16>().ok())
            .and_then(|v| <[u16; 3]>::try_from(v).ok())
            .map(cielab_to_srgb);
        let segment = Segment {
            layer: 0,
            value: i64::from(number),
            name,
            color,
            codes: segment_codes(item),
        };
        out.push(segment);
    }
    if out.is_empty() {
        return Err(unsupported(
            "the Segment Sequence declares no segment".into(),
        ));
    }
    out.sort_by_key(|s| s.value);
    Ok(out)
}

fn segment_codes(item: &InMemDicomObject) -> Option<StructureCodes> {
    let category = code(first_item(
        item,
        tags::SEGMENTED_PROPERTY_CATEGORY_CODE_SEQUENCE,
    )?)?;
    let kind_item = first_item(item, tags::SEGMENTED_PROPERTY_TYPE_CODE_SEQUENCE)?;
    let modifier = first_item(
        kind_item,
        tags::SEGMENTED_PROPERTY_TYPE_MODIFIER_CODE_SEQUENCE,
    )
    .and_then(code);
    Some(StructureCodes {
        category,
        kind: code(kind_item)?,
        modifier,
    })
}

/// A code sequence item: scheme, value (short, long or URN) and meaning.
fn code(item: &InMemDicomObject) -> Option<Code> {
    let value = text(item, tags::CODE_VALUE)
        .or_else(|| text(item, tags::LONG_CODE_VALUE))
        .or_else(|| text(item, tags::URN_CODE_VALUE))?;
    Some(Code {
        scheme: text(item, tags::CODING_SCHEME_DESIGNATOR).unwrap_or_default(),
        value,
        meaning: text(item, tags::CODE_MEANING).unwrap_or_default(),
    })
}

/// Each frame's position and segment, from the per-frame functional groups.
fn frame_geometry(
    object: &InMemDicomObject,
    frames: usize,
    segments: &[Segment],
    pixels: Pixels,
) -> Result<Vec<FrameGeometry>, LoadError> {
    let groups = items(object, tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE);
    if groups.len() != frames {
        return Err(unsupported(format!(
            "{frames} frames declared but {} per-frame functional groups",
            groups.len()
        )));
    }
    // A file of one segment may name it once, in the shared groups.
    let shared = first_item(object, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE);
    let only = shared.and_then(segment_of).or(match segments {
        [only] => Some(segment_number(only)),
        _ => None,
    });
    // A label map's frame holds every segment of its slice: it refers to none.
    let labels = matches!(pixels, Pixels::Labels { .. });
    (groups.iter().enumerate())
        .map(|(index, group)| {
            let at = |detail: &str| LoadError::Syntax {
                format: FORMAT,
                location: Location::Item("frame", index + 1),
                detail: detail.to_string(),
            };
            let position = first_item(group, tags::PLANE_POSITION_SEQUENCE)
                .and_then(|p| floats(p, tags::IMAGE_POSITION_PATIENT))
                .and_then(|v| <[f64; 3]>::try_from(v).ok())
                .ok_or_else(|| at("no Image Position (Patient) of three numbers"))?;
            if position.iter().any(|v| !v.is_finite()) {
                return Err(at("Image Position (Patient) is not finite"));
            }
            let segment = match labels {
                true => 0,
                false => (segment_of(group).or(only))
                    .ok_or_else(|| at("no Referenced Segment Number"))?,
            };
            if !labels && !segments.iter().any(|s| segment_number(s) == segment) {
                return Err(at(&format!("segment {segment} is not declared")));
            }
            let orientation = seg_grid::orientation_of(group);
            Ok(FrameGeometry {
                position,
                segment,
                orientation,
            })
        })
        .collect()
}

fn segment_of(group: &InMemDicomObject) -> Option<u16> {
    let identification = first_item(group, tags::SEGMENT_IDENTIFICATION_SEQUENCE)?;
    let number = identification
        .element(tags::REFERENCED_SEGMENT_NUMBER)
        .ok()?;
    number.to_int::<u16>().ok()
}

/// DICOM's scaled CIELab (PS3.3 C.10.7.1.1: L* 0..100, a* and b* -128..127 mapped onto
/// 0..65535; D65 white) to display sRGB in [0, 1].
pub(in crate::io) fn cielab_to_srgb(lab: [u16; 3]) -> [f32; 3] {
    let l = f64::from(lab[0]) * 100.0 / 65535.0;
    let a = f64::from(lab[1]) * 255.0 / 65535.0 - 128.0;
    let b = f64::from(lab[2]) * 255.0 / 65535.0 - 128.0;
    let f_inverse = |t: f64| {
        let delta = 6.0 / 29.0;
        if t > delta {
            t * t * t
        } else {
            3.0 * delta * delta * (t - 4.0 / 29.0)
        }
    };
    let fy = (l + 16.0) / 116.0;
    let white = [0.950_47, 1.0, 1.088_83];
    let xyz = [
        white[0] * f_inverse(fy + a / 500.0),
        white[1] * f_inverse(fy),
        white[2] * f_inverse(fy - b / 200.0),
    ];
    let linear = [
        3.240_454_2 * xyz[0] - 1.537_138_5 * xyz[1] - 0.498_531_4 * xyz[2],
        -0.969_266 * xyz[0] + 1.876_010_8 * xyz[1] + 0.041_556 * xyz[2],
        0.055_643_4 * xyz[0] - 0.204_025_9 * xyz[1] + 1.057_225_2 * xyz[2],
    ];
    linear.map(|c| crate::srgb::from_linear(c.clamp(0.0, 1.0) as f32))
}

/// Whether bytes look like a DICOM file ('DICM' after the 128-byte preamble).
pub(in crate::io) fn is_dicom(bytes: &[u8]) -> bool {
    bytes.get(128..132) == Some(b"DICM")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cielab_white_black_and_a_red_come_back_as_srgb() {
        let white = cielab_to_srgb([65535, 32896, 32896]);
        assert!(white.iter().all(|&c| (c - 1.0).abs() < 2e-3), "{white:?}");
        let black = cielab_to_srgb([0, 32896, 32896]);
        assert!(black.iter().all(|&c| c.abs() < 1e-3), "{black:?}");
        // sRGB (221, 130, 101) is L* 63.57, a* 32.18, b* 30.73 (D65).
        let lab: [f64; 3] = [
            63.57 / 100.0 * 65535.0,
            (32.18 + 128.0) / 255.0 * 65535.0,
            (30.73 + 128.0) / 255.0 * 65535.0,
        ];
        let rgb = cielab_to_srgb(lab.map(|v| v.round() as u16)).map(|c| c * 255.0);
        for (got, want) in rgb.iter().zip([221.0, 130.0, 101.0]) {
            assert!((got - want).abs() < 2.0, "{rgb:?}");
        }
    }
}
