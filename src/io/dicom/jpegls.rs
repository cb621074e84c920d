//! DICOM's JPEG-LS transfer syntaxes (PS3.5 A.4.3: lossless, and near-lossless): each frame a
//! JPEG-LS codestream, decoded by the `pure_jpegls` crate (pure Rust) into the little-endian
//! pixel data an uncompressed file would hold.
//!
//! The frame header (SOF55, laid out as JPEG's) is read here first: a grey frame of the rows,
//! columns and bits the DICOM header declares, long enough to hold them, is all that reaches
//! the decoder. The decoder checks the scan's parameters against the frame and refuses a scan
//! cut short or not followed by its end of image; its sums overflow, though, on a scan coded
//! with a preset RESET far from the default 64 (found by fuzzing): only the default is let
//! through, and a point transform, which it would ignore, is refused. Samples are the stored
//! values themselves (a signed stored value is coded as its bit pattern), so they go out as
//! they come.

use super::frames::{frame_by_frame, FrameShape};
use super::jpeg::{checked_frame_header, find_segment, FrameRules};
use crate::io::{Format, LoadError};

/// Pixels a byte of JPEG-LS may hold: run mode codes a line of one value in a bit or more, so
/// eight lines of 512 pixels a byte (a frame wider than that, all of one value, is refused).
const MOST_PIXELS_PER_BYTE: usize = 8 * 512;

/// The JPEG-LS frame header's marker, SOF55.
fn starts_ls_frame(marker: u8) -> bool {
    marker == 0xF7
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
        starts_frame: starts_ls_frame,
        expansion: MOST_PIXELS_PER_BYTE * shape.bytes,
        what: "bytes in a JPEG-LS frame",
    };
    frame_by_frame(codestreams, "JPEG-LS", format, |stream, bad, out| {
        let header = checked_frame_header(stream, &rules, shape, size, format, bad)?;
        check_presets_and_scan(stream).map_err(bad)?;
        let (columns, rows) = (u32::from(header.columns), u32::from(header.rows));
        let (samples, _, _) =
            jpegls::decode(stream, columns, rows).map_err(|e| bad(e.to_string()))?;
        if samples.len() != shape.pixels {
            return Err(bad(format!(
                "decodes to {} samples, not the frame's {} pixels",
                samples.len(),
                shape.pixels
            )));
        }
        out.reserve(shape.pixels * shape.bytes);
        for s in samples {
            out.extend_from_slice(&s.to_le_bytes()[..shape.bytes]);
        }
        Ok(())
    })
}

/// The statistics' reset the decoder is trusted with: the standard's default (ISO 14495-1
/// C.2.4.1.1), which CharLS and GDCM write.
const DEFAULT_RESET: u16 = 64;

/// Refuses a preset-parameters segment (LSE, ID 1) with another RESET than the default, and a
/// first scan header (SOS) with a point transform.
fn check_presets_and_scan(stream: &[u8]) -> Result<(), String> {
    const MISSING: &str = "no scan before the codestream's end";
    find_segment(stream, MISSING, |marker, segment| {
        let byte = |i: usize| segment.get(i).copied().ok_or_else(|| MISSING.to_string());
        let word = |i: usize| Ok::<_, String>(u16::from_be_bytes([byte(i)?, byte(i + 1)?]));
        match marker {
            0xF8 if byte(4)? == 1 => match word(13)? {
                DEFAULT_RESET => Ok(None),
                reset => Err(format!(
                    "a preset RESET of {reset}: only the default {DEFAULT_RESET} is read"
                )),
            },
            0xDA => {
                let components = usize::from(byte(4)?);
                match byte(4 + 2 * components + 3)? & 0x0F {
                    0 => Ok(Some(())),
                    bits => Err(format!("a point transform of {bits} bits")),
                }
            }
            _ => Ok(None),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A JPEG-LS codestream of `columns` x `rows` samples of `precision` bits, all `value`,
    /// as the crate's encoder writes it.
    fn uniform(columns: u32, rows: u32, value: u16) -> Vec<u8> {
        let samples = vec![value; (columns * rows) as usize];
        let mut stream = Vec::new();
        jpegls::encode(&samples, columns, rows, &mut stream).expect("encoded");
        stream
    }

    fn shape(columns: usize, rows: usize, bytes: usize) -> FrameShape {
        FrameShape {
            pixels: columns * rows,
            bytes,
        }
    }

    #[test]
    fn a_frame_decodes_to_its_stored_values_little_endian() {
        let samples: Vec<u16> = (0..24 * 20).map(|i| (i * 37 % 4096) as u16).collect();
        let mut stream = Vec::new();
        jpegls::encode(&samples, 24, 20, &mut stream).expect("encoded");
        let out = decode(&[&stream], shape(24, 20, 2), [24, 20], Format::DicomImage).unwrap();
        let back: Vec<u16> = (out.chunks_exact(2))
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect();
        assert_eq!(back, samples);
    }

    #[test]
    fn another_size_a_cut_scan_and_a_bomb_are_refused_by_frame() {
        let stream = uniform(24, 20, 7);
        let refused = |streams: &[&[u8]], size: [usize; 2]| {
            let error = decode(
                streams,
                shape(size[0], size[1], 2),
                size,
                Format::DicomImage,
            );
            error.unwrap_err().to_string()
        };
        let error = refused(&[&stream, &stream], [20, 24]);
        assert!(
            error.contains("frame 1") && error.contains("24 x 20"),
            "{error}"
        );
        let cut = &stream[..stream.len() - 4];
        let error = refused(&[&stream, cut], [24, 20]);
        assert!(error.contains("frame 2"), "{error}");
        // 512 x 512 of one value fits in a few hundred bytes; declared 64 times the rows, it
        // is refused before the decoder sizes anything.
        let wide = uniform(512, 512, 0);
        assert!(decode(&[&wide], shape(512, 512, 2), [512, 512], Format::DicomImage).is_ok());
        let mut tall = wide.clone();
        let at = tall.windows(2).position(|w| w == [0xFF, 0xF7]).unwrap();
        tall[at + 5..at + 7].copy_from_slice(&32768u16.to_be_bytes());
        let error = refused(&[&tall], [512, 32768]);
        assert!(error.contains("bytes in a JPEG-LS frame"), "{error}");
    }

    #[test]
    fn presets_other_than_the_default_reset_and_point_transforms_are_refused() {
        let stream = uniform(24, 20, 7);
        let sos = stream.windows(2).position(|w| w == [0xFF, 0xDA]).unwrap();
        let with_reset = |reset: u16| {
            let mut s = stream[..sos].to_vec();
            s.extend([0xFF, 0xF8, 0x00, 0x0D, 0x01, 0, 0, 0, 0, 0, 0, 0, 0]);
            s.extend(reset.to_be_bytes());
            s.extend(&stream[sos..]);
            s
        };
        let read = |s: &[u8]| decode(&[s], shape(24, 20, 1), [24, 20], Format::DicomImage);
        assert_eq!(read(&with_reset(64)).unwrap(), vec![7; 24 * 20]);
        let error = read(&with_reset(5)).unwrap_err().to_string();
        assert!(error.contains("a preset RESET of 5"), "{error}");
        let mut shifted = stream.clone();
        shifted[sos + 9] = 0x01;
        let error = read(&shifted).unwrap_err().to_string();
        assert!(error.contains("a point transform of 1 bits"), "{error}");
    }
}
