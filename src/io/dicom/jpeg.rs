//! DICOM's JPEG transfer syntaxes (baseline, extended and lossless, PS3.5 A.4.1): each frame a
//! JPEG codestream, decoded by the `jpeg-decoder` crate (image-rs, pure Rust) into the
//! little-endian pixel data an uncompressed file would hold.
//!
//! The frame header is read here first, because the crate sizes its buffers from it before
//! its own size limit applies, and its metadata call panics on a precision or component count
//! it does not take: a grey frame of the rows, columns and bits the DICOM header declares is
//! all that reaches the decoder, and only when the codestream is long enough to hold it.

use super::frames::{frame_by_frame, Declared, FrameShape};
use crate::io::{Format, LoadError};

/// Pixels a byte of JPEG can hold at most: an 8 x 8 block of one value codes in 2 bits.
const MOST_EXPANSION: usize = 256;

/// What a codestream's frame header (SOFn) says.
#[derive(Debug, PartialEq)]
pub(in crate::io) struct FrameHeader {
    pub precision: u8,
    pub rows: u16,
    pub columns: u16,
    pub components: u8,
}

/// Whether a marker starts a JPEG frame header: SOF0..SOF15 but DHT, JPG and DAC.
fn starts_jpeg_frame(marker: u8) -> bool {
    matches!(marker, 0xC0..=0xCF) && !matches!(marker, 0xC4 | 0xC8 | 0xCC)
}

/// The frames `codestreams` (one each) hold, back to back, little endian; `size` is the
/// frame's columns and rows.
pub(in crate::io) fn decode(
    codestreams: &[&[u8]],
    shape: FrameShape,
    size: [usize; 2],
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    let rules = FrameRules {
        starts_frame: starts_jpeg_frame,
        expansion: MOST_EXPANSION,
        what: "bytes in a JPEG frame",
    };
    frame_by_frame(codestreams, "JPEG", format, |stream, bad, out| {
        let header = checked_frame_header(stream, &rules, shape, size, format, bad)?;
        let bytes = if header.precision <= 8 { 1 } else { 2 };
        // The decoder's own word for a codestream cut short is an I/O error of its reader.
        if !ends_with_end_of_image(stream) {
            let cut = "the codestream ends without a JPEG end of image: it is cut short";
            return Err(bad(cut.into()));
        }
        let mut decoder = jpeg_decoder::Decoder::new(stream);
        decoder.set_max_decoding_buffer_size(shape.pixels);
        let pixels = decoder.decode().map_err(|e| bad(e.to_string()))?;
        if pixels.len() != shape.pixels * bytes {
            return Err(bad(format!(
                "decodes to {} bytes, not the frame's {}",
                pixels.len(),
                shape.pixels * bytes
            )));
        }
        match (bytes, shape.bytes) {
            (1, 2) => out.extend(pixels.iter().flat_map(|&v| [v, 0])),
            // The decoder gives 16-bit samples in the machine's order.
            _ if bytes == 2 => out.extend(
                (pixels.chunks_exact(2))
                    .flat_map(|p| u16::from_ne_bytes([p[0], p[1]]).to_le_bytes()),
            ),
            _ => out.extend_from_slice(&pixels),
        }
        Ok(())
    })
}

/// How a codec's frame header is found and how many pixels' bytes a byte of its codestream
/// may hold.
pub(in crate::io) struct FrameRules {
    pub starts_frame: fn(u8) -> bool,
    pub expansion: usize,
    /// What the bytes are called when there are too few.
    pub what: &'static str,
}

/// The frame header of `stream`, refused (in `bad`'s words) unless it declares the DICOM
/// header's frame (`shape`, `size`) in bytes that can hold it.
pub(in crate::io) fn checked_frame_header(
    stream: &[u8],
    rules: &FrameRules,
    shape: FrameShape,
    size: [usize; 2],
    format: Format,
    bad: &dyn Fn(String) -> LoadError,
) -> Result<FrameHeader, LoadError> {
    let header = frame_header(stream, rules.starts_frame).map_err(bad)?;
    let declared = Declared {
        columns: header.columns.into(),
        rows: header.rows.into(),
        components: header.components.into(),
        bits: header.precision.into(),
        subsampled: false,
    };
    shape.check_declared(size, &declared).map_err(bad)?;
    shape.bytes_within(stream.len(), rules.expansion, rules.what, format)?;
    Ok(header)
}

/// Whether a codestream ends with its end-of-image marker (JPEG 2000's end of codestream is the
/// same two bytes), before the zero byte DICOM may pad a fragment with to an even length.
pub(in crate::io) fn ends_with_end_of_image(stream: &[u8]) -> bool {
    let unpadded = stream.strip_suffix(&[0]).unwrap_or(stream);
    unpadded.ends_with(&[0xFF, 0xD9])
}

/// Walks the marker segments after the start of image, giving `visit` each marker with the
/// bytes from it on, until `visit` answers (fill bytes and markers without a length are
/// stepped over); `missing` says what was sought when the codestream ends first.
pub(in crate::io) fn find_segment<T>(
    stream: &[u8],
    missing: &str,
    mut visit: impl FnMut(u8, &[u8]) -> Result<Option<T>, String>,
) -> Result<T, String> {
    if !stream.starts_with(&[0xFF, 0xD8]) {
        return Err("the codestream does not start with a JPEG start of image".into());
    }
    let mut at = 2;
    loop {
        let byte = |i: usize| stream.get(i).copied().ok_or_else(|| missing.to_string());
        if byte(at)? != 0xFF {
            return Err(format!("no JPEG marker at byte {at}"));
        }
        match byte(at + 1)? {
            0xFF => at += 1,
            0x01 | 0xD0..=0xD7 => at += 2,
            marker => {
                if let Some(found) = visit(marker, &stream[at..])? {
                    return Ok(found);
                }
                let length = u16::from_be_bytes([byte(at + 2)?, byte(at + 3)?]);
                at += 2 + length as usize;
            }
        }
    }
}

/// The first frame header before the first scan: the first marker segment `starts_frame` (a
/// JPEG-LS frame header has the same fields as JPEG's).
fn frame_header(stream: &[u8], starts_frame: fn(u8) -> bool) -> Result<FrameHeader, String> {
    const MISSING: &str = "no frame header before its end";
    find_segment(stream, MISSING, |marker, segment| {
        let byte = |i: usize| segment.get(i).copied().ok_or_else(|| MISSING.to_string());
        let word = |i: usize| Ok::<_, String>(u16::from_be_bytes([byte(i)?, byte(i + 1)?]));
        match marker {
            frame if starts_frame(frame) => Ok(Some(FrameHeader {
                precision: byte(4)?,
                rows: word(5)?,
                columns: word(7)?,
                components: byte(9)?,
            })),
            0xDA | 0xD9 => Err("a scan or the end before any frame header".into()),
            _ => Ok(None),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_header_is_found_past_other_segments() {
        let mut stream = vec![0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0xAA, 0xBB];
        stream.extend([
            0xFF, 0xC3, 0x00, 0x0B, 16, 0x00, 0x14, 0x00, 0x18, 1, 1, 0x11, 0,
        ]);
        let header = frame_header(&stream, starts_jpeg_frame).unwrap();
        let want = FrameHeader {
            precision: 16,
            rows: 20,
            columns: 24,
            components: 1,
        };
        assert_eq!(header, want);
        assert!(frame_header(&stream[..12], starts_jpeg_frame)
            .unwrap_err()
            .contains("before its end"));
        assert!(frame_header(b"GIF89a", starts_jpeg_frame)
            .unwrap_err()
            .contains("start of image"));
    }

    #[test]
    fn a_codestream_ends_with_its_end_of_image_padded_or_not() {
        assert!(ends_with_end_of_image(&[0xFF, 0xD8, 0x12, 0xFF, 0xD9]));
        assert!(ends_with_end_of_image(&[0xFF, 0xD8, 0xFF, 0xD9, 0x00]));
        assert!(!ends_with_end_of_image(&[0xFF, 0xD8, 0x12, 0x34]));
        assert!(!ends_with_end_of_image(&[
            0xFF, 0xD8, 0xFF, 0xD9, 0x00, 0x00
        ]));
        assert!(!ends_with_end_of_image(&[0xFF, 0xD9, 0x12]));
    }

    #[test]
    fn frames_unlike_the_header_or_too_short_are_refused() {
        let mut stream = vec![0xFF, 0xD8];
        stream.extend([
            0xFF, 0xC0, 0x00, 0x0B, 8, 0x00, 0x14, 0x00, 0x18, 3, 1, 0x11, 0,
        ]);
        let shape = FrameShape {
            pixels: 24 * 20,
            bytes: 1,
        };
        let e = decode(&[&stream], shape, [24, 20], Format::DicomImage).unwrap_err();
        assert!(e.to_string().contains("3 component(s)"), "{e}");
        stream[11] = 1;
        let e = decode(&[&stream], shape, [20, 24], Format::DicomImage).unwrap_err();
        assert!(e.to_string().contains("24 x 20 pixels"), "{e}");
        let big = [4000, 4000];
        stream[7..11].copy_from_slice(&[0x0F, 0xA0, 0x0F, 0xA0]);
        let huge = FrameShape {
            pixels: 4000 * 4000,
            bytes: 1,
        };
        assert!(matches!(
            decode(&[&stream], huge, big, Format::DicomImage),
            Err(LoadError::CountTooLarge { .. })
        ));
    }
}
