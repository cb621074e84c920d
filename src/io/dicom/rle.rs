//! DICOM RLE Lossless (PS3.5 Annex G): each frame one fragment, a 64-byte header of segment
//! offsets, then one PackBits segment per byte of a sample, the most significant byte's first.
//! Decoded here into the little-endian pixel data an uncompressed file would hold.
//!
//! Written by hand rather than taken from dicom-rs's RLE adapter: that adapter trusts the
//! header's segment count (allocating up to 16 GiB for a lying one) and panics on a fragment
//! shorter than its header; these files come from users and must be refused with a reason,
//! within memory the file's size bounds.

use super::frames::FrameShape;
use crate::io::{Format, LoadError};

const HEADER: usize = 64;
/// A PackBits replicate run: two bytes for at most 128.
const MOST_EXPANSION: usize = 64;

/// The frames `fragments` (one each) hold, back to back, little endian.
pub(in crate::io) fn decode(
    fragments: &[&[u8]],
    shape: FrameShape,
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    let what = "bytes in an RLE frame";
    for fragment in fragments {
        shape.bytes_within(fragment.len(), MOST_EXPANSION, what, format)?;
    }
    let frame_bytes = shape.pixels.saturating_mul(shape.bytes);
    // Grown a frame at a time, so that a file broken further on has not cost every frame.
    let mut out = Vec::new();
    let mut plane = vec![0u8; shape.pixels];
    for (index, fragment) in fragments.iter().enumerate() {
        let segments = segments(fragment, shape.bytes)
            .map_err(|detail| bad(format, format!("RLE frame {}: {detail}", index + 1)))?;
        let base = out.len();
        out.resize(base + frame_bytes, 0);
        for (high_first, segment) in segments.iter().enumerate() {
            if !unpack(segment, &mut plane) {
                return Err(bad(
                    format,
                    format!(
                        "RLE frame {}: segment {} holds fewer than the frame's {} pixels",
                        index + 1,
                        high_first + 1,
                        shape.pixels
                    ),
                ));
            }
            let byte = base + shape.bytes - 1 - high_first;
            for (pixel, value) in plane.iter().enumerate() {
                out[byte + pixel * shape.bytes] = *value;
            }
        }
    }
    Ok(out)
}

fn bad(format: Format, detail: String) -> LoadError {
    LoadError::Unsupported { format, detail }
}

/// The fragment's segments by its header, which must declare one a byte of the sample.
fn segments(fragment: &[u8], bytes: usize) -> Result<Vec<&[u8]>, String> {
    let word = |i: usize| -> Option<usize> {
        let b = fragment.get(4 * i..4 * i + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let count = word(0).ok_or("the fragment is shorter than the RLE header")?;
    if count != bytes {
        return Err(format!(
            "{count} segments for samples of {bytes} byte(s) (one segment a byte is read)"
        ));
    }
    if fragment.len() < HEADER {
        return Err("the fragment is shorter than the RLE header".into());
    }
    let mut starts: Vec<usize> = (1..=count).filter_map(word).collect();
    starts.push(fragment.len());
    if starts[0] != HEADER || starts.windows(2).any(|w| w[0] > w[1]) {
        return Err(format!(
            "segment offsets {starts:?} are out of order or off the fragment"
        ));
    }
    Ok(starts.windows(2).map(|w| &fragment[w[0]..w[1]]).collect())
}

/// PackBits: a byte n in 0..=127 copies the next n + 1 bytes, -127..=-1 repeats the next byte
/// 1 - n times, -128 is nothing. Fills `out`, ignoring what the segment holds beyond (an
/// encoder's padding); false when the segment ends first.
fn unpack(segment: &[u8], out: &mut [u8]) -> bool {
    let (mut at, mut filled) = (0, 0);
    while filled < out.len() {
        let Some(&header) = segment.get(at) else {
            return false;
        };
        let n = header as i8;
        at += 1;
        let left = out.len() - filled;
        if n >= 0 {
            let run = n as usize + 1;
            let Some(literal) = segment.get(at..at + run) else {
                return false;
            };
            let take = run.min(left);
            out[filled..filled + take].copy_from_slice(&literal[..take]);
            at += run;
            filled += take;
        } else if n != -128 {
            let Some(&value) = segment.get(at) else {
                return false;
            };
            let take = (1 - n as isize).unsigned_abs().min(left);
            out[filled..filled + take].fill(value);
            at += 1;
            filled += take;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fragment(segments: &[&[u8]]) -> Vec<u8> {
        let mut header = vec![0u8; HEADER];
        header[..4].copy_from_slice(&(segments.len() as u32).to_le_bytes());
        let mut at = HEADER;
        let mut body = Vec::new();
        for (i, s) in segments.iter().enumerate() {
            header[4 + 4 * i..8 + 4 * i].copy_from_slice(&(at as u32).to_le_bytes());
            body.extend_from_slice(s);
            at += s.len();
        }
        header.extend(body);
        header
    }

    #[test]
    fn runs_and_literals_of_both_bytes_make_little_endian_pixels() {
        // High bytes: 0x01 three times, then 0x02; low bytes: literal 10 20, then 30 twice.
        let high: &[u8] = &[0xFE, 0x01, 0x00, 0x02];
        let low: &[u8] = &[0x01, 10, 20, 0x80, 0xFF, 30];
        let shape = FrameShape {
            pixels: 4,
            bytes: 2,
        };
        let one = fragment(&[high, low]);
        let out = decode(&[&one, &one], shape, Format::DicomImage).unwrap();
        let frame = [10, 1, 20, 1, 30, 1, 30, 2];
        assert_eq!(out, [frame, frame].concat());
    }

    #[test]
    fn lying_headers_and_short_segments_are_refused() {
        let shape = FrameShape {
            pixels: 4,
            bytes: 1,
        };
        let short = fragment(&[&[0xFE, 7]]);
        let error = decode(&[&short], shape, Format::DicomSeg).unwrap_err();
        assert!(error.to_string().contains("fewer than"), "{error}");
        let mut many = fragment(&[&[0xFD, 7]]);
        many[..4].copy_from_slice(&u32::MAX.to_le_bytes());
        let error = decode(&[&many], shape, Format::DicomSeg).unwrap_err();
        assert!(error.to_string().contains("4294967295 segments"), "{error}");
        let error = decode(&[&[1, 0, 0, 0]], shape, Format::DicomSeg).unwrap_err();
        assert!(error.to_string().contains("shorter"), "{error}");
        let huge = FrameShape {
            pixels: 1 << 30,
            bytes: 1,
        };
        let good = fragment(&[&[0xFD, 7]]);
        assert!(matches!(
            decode(&[&good], huge, Format::DicomSeg),
            Err(LoadError::CountTooLarge { .. })
        ));
        assert_eq!(decode(&[&good], shape, Format::DicomSeg).unwrap(), [7; 4]);
    }
}
