//! DICOM's JPEG 2000 transfer syntaxes (PS3.5 A.4.4: lossless only, and lossless or lossy):
//! each frame a JPEG 2000 codestream, decoded by the `hayro-jpeg2000` crate (pure Rust) into the
//! little-endian pixel data an uncompressed file would hold.
//!
//! The codestream's image and tile size marker (SIZ, which follows its start) is read here
//! first: the frame must be one grey component of the columns, rows and bits the DICOM header
//! declares, in no more tiles than its bytes can introduce, before the decoder sizes anything.
//! The crate also shifts every component by half its range as if unsigned, where a signed one
//! (CT's usual Pixel Representation) has no shift: the marker says which, and the shift is
//! taken back here. The decoder runs strict, so a codestream cut short is refused, not shown
//! half decoded.

use hayro_jpeg2000::{DecodeSettings, DecoderContext, Image};

use super::frames::{frame_by_frame, Declared, FrameShape};
use super::jpeg::ends_with_end_of_image;
use crate::io::{Format, LoadError};

/// Pixels a byte of JPEG 2000 may hold: a frame of one value codes in an empty packet a
/// resolution after its main header (512 x 512 in about 150 bytes). The decoder holds a few
/// 32-bit floats a pixel, so this also bounds its memory by the file's size.
const MOST_PIXELS_PER_BYTE: usize = 2048;
/// Bytes each tile takes at least: its tile-part header (SOT) and the start of its data (SOD).
const TILE_PART_BYTES: usize = 14;

/// What a codestream's SIZ marker says of its one component.
#[derive(Debug, PartialEq)]
struct SizeHeader {
    columns: u32,
    rows: u32,
    tiles: u64,
    components: u16,
    precision: u8,
    signed: bool,
    /// The component is sampled more coarsely than the image grid.
    subsampled: bool,
}

/// The frames `codestreams` (one each) hold, back to back, little endian; `size` is the
/// frame's columns and rows.
pub(in crate::io) fn decode(
    codestreams: &[&[u8]],
    shape: FrameShape,
    size: [usize; 2],
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    frame_by_frame(codestreams, "JPEG 2000", format, |stream, bad, out| {
        let header = size_header(stream).map_err(bad)?;
        let declared = Declared {
            columns: header.columns as usize,
            rows: header.rows as usize,
            components: header.components.into(),
            bits: header.precision.into(),
            subsampled: header.subsampled,
        };
        shape.check_declared(size, &declared).map_err(bad)?;
        let expansion = MOST_PIXELS_PER_BYTE * shape.bytes;
        shape.bytes_within(
            stream.len(),
            expansion,
            "bytes in a JPEG 2000 frame",
            format,
        )?;
        if header.tiles > (stream.len() / TILE_PART_BYTES) as u64 {
            return Err(bad(format!(
                "{} tiles declared in {} bytes, which hold at most {}",
                header.tiles,
                stream.len(),
                stream.len() / TILE_PART_BYTES
            )));
        }
        // Strict decoding would say only "invalid marker".
        if !ends_with_end_of_image(stream) {
            let cut = "the codestream ends without its end of codestream marker: it is cut short";
            return Err(bad(cut.into()));
        }
        let settings = DecodeSettings {
            resolve_palette_indices: false,
            strict: true,
            target_resolution: None,
        };
        let image = Image::new(stream, &settings).map_err(|e| bad(e.to_string()))?;
        let mut context = DecoderContext::default();
        let decoded = image.decode(&mut context).map_err(|e| bad(e.to_string()))?;
        let samples = match decoded.components() {
            [grey] if grey.samples().len() == shape.pixels => grey.samples(),
            other => {
                let count: usize = other.iter().map(|c| c.samples().len()).sum();
                return Err(bad(format!(
                    "decodes to {count} samples, not the frame's {} pixels",
                    shape.pixels
                )));
            }
        };
        out.reserve(shape.pixels * shape.bytes);
        let range = SampleRange::of(&header);
        for &s in samples {
            out.extend_from_slice(&range.stored(s).to_le_bytes()[..shape.bytes]);
        }
        Ok(())
    })
}

/// How a decoded sample becomes the stored value an uncompressed file would hold.
struct SampleRange {
    /// What the decoder added (half the range) and a signed component never had.
    shift: f32,
    lowest: i64,
    highest: i64,
}

impl SampleRange {
    fn of(header: &SizeHeader) -> Self {
        let half = 1i64 << (header.precision - 1);
        if header.signed {
            Self {
                shift: half as f32,
                lowest: -half,
                highest: half - 1,
            }
        } else {
            Self {
                shift: 0.0,
                lowest: 0,
                highest: 2 * half - 1,
            }
        }
    }

    /// Lossy frames decode to values between the integers and a little past the range.
    fn stored(&self, sample: f32) -> i64 {
        let v = (sample - self.shift).round();
        if v.is_nan() {
            return 0;
        }
        (v as i64).clamp(self.lowest, self.highest)
    }
}

/// The SIZ marker segment, which must follow the start of the codestream (ISO 15444-1 A.5.1).
fn size_header(stream: &[u8]) -> Result<SizeHeader, String> {
    if !stream.starts_with(&[0xFF, 0x4F, 0xFF, 0x51]) {
        return Err("no JPEG 2000 codestream: it does not open with SOC and SIZ markers".into());
    }
    let byte = |i: usize| {
        (stream.get(i).copied()).ok_or_else(|| "the SIZ marker is cut short".to_string())
    };
    let word = |i: usize| -> Result<u32, String> {
        Ok(u32::from_be_bytes([
            byte(i)?,
            byte(i + 1)?,
            byte(i + 2)?,
            byte(i + 3)?,
        ]))
    };
    let [xsiz, ysiz, x_offset, y_offset, tile_width, tile_height, tile_x, tile_y] =
        [8, 12, 16, 20, 24, 28, 32, 36].map(word);
    let (xsiz, ysiz, x_offset, y_offset) = (xsiz?, ysiz?, x_offset?, y_offset?);
    let (tile_width, tile_height, tile_x, tile_y) = (tile_width?, tile_height?, tile_x?, tile_y?);
    if x_offset >= xsiz || y_offset >= ysiz || tile_width == 0 || tile_height == 0 {
        return Err(format!(
            "the SIZ marker's image ({xsiz} x {ysiz} from {x_offset}, {y_offset}) or tiles \
             ({tile_width} x {tile_height}) are empty"
        ));
    }
    if tile_x > x_offset || tile_y > y_offset {
        return Err("the SIZ marker's first tile starts past the image".into());
    }
    let across = u64::from(xsiz - tile_x).div_ceil(u64::from(tile_width));
    let down = u64::from(ysiz - tile_y).div_ceil(u64::from(tile_height));
    let components = u16::from_be_bytes([byte(40)?, byte(41)?]);
    let ssiz = byte(42)?;
    Ok(SizeHeader {
        columns: xsiz - x_offset,
        rows: ysiz - y_offset,
        tiles: across * down,
        components,
        precision: (ssiz & 0x7F) + 1,
        signed: ssiz & 0x80 != 0,
        subsampled: (byte(43)?, byte(44)?) != (1, 1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A codestream's start: SOC, then SIZ for one component.
    fn siz(columns: u32, rows: u32, tile: u32, ssiz: u8) -> Vec<u8> {
        let mut s = vec![0xFF, 0x4F, 0xFF, 0x51, 0x00, 0x29, 0x00, 0x00];
        for v in [columns, rows, 0, 0, tile, tile, 0, 0] {
            s.extend(v.to_be_bytes());
        }
        s.extend([0x00, 0x01, ssiz, 0x01, 0x01]);
        s
    }

    #[test]
    fn the_size_marker_says_size_tiles_and_sign() {
        let header = size_header(&siz(24, 20, 8, 0x8F)).unwrap();
        let want = SizeHeader {
            columns: 24,
            rows: 20,
            tiles: 9,
            components: 1,
            precision: 16,
            signed: true,
            subsampled: false,
        };
        assert_eq!(header, want);
        let e = size_header(&siz(24, 20, 8, 0x8F)[..41]).unwrap_err();
        assert!(e.contains("cut short"), "{e}");
        assert!(size_header(b"\xFF\xD8\xFF\xC0")
            .unwrap_err()
            .contains("SOC"));
        let e = size_header(&siz(24, 20, 0, 0x07)).unwrap_err();
        assert!(e.contains("empty"), "{e}");
    }

    #[test]
    fn signed_samples_lose_the_decoders_shift_and_stay_in_range() {
        let signed = SampleRange::of(&size_header(&siz(2, 2, 2, 0x8F)).unwrap());
        assert_eq!(signed.stored(32768.0 - 1024.0), -1024);
        assert_eq!(signed.stored(32768.0 + 1023.4), 1023);
        assert_eq!(signed.stored(-5.0), -32768);
        let unsigned = SampleRange::of(&size_header(&siz(2, 2, 2, 0x07)).unwrap());
        assert_eq!(unsigned.stored(255.6), 255);
        assert_eq!(unsigned.stored(-0.7), 0);
        assert_eq!(unsigned.stored(f32::NAN), 0);
    }

    #[test]
    fn frames_unlike_the_header_or_with_too_many_tiles_are_refused() {
        let shape = FrameShape {
            pixels: 24 * 20,
            bytes: 2,
        };
        let mut stream = siz(24, 20, 24, 0x8F);
        stream.resize(64, 0);
        let e = decode(&[&stream], shape, [20, 24], Format::DicomImage).unwrap_err();
        assert!(e.to_string().contains("24 x 20 pixels"), "{e}");
        let one_byte = FrameShape { bytes: 1, ..shape };
        let e = decode(&[&stream], one_byte, [24, 20], Format::DicomImage).unwrap_err();
        assert!(e.to_string().contains("16 bits"), "{e}");
        let mut tiny_tiles = siz(24, 20, 1, 0x8F);
        tiny_tiles.resize(64, 0);
        let e = decode(&[&tiny_tiles], shape, [24, 20], Format::DicomImage).unwrap_err();
        assert!(
            e.to_string().contains("480 tiles declared in 64 bytes"),
            "{e}"
        );
    }
}
