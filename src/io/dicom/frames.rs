//! A DICOM file's frames of pixels once its lengths are checked ([`super::lengths`]):
//! what the header declares of them, and encapsulated (compressed) frames decoded by their codec
//! ([`super::rle`], [`super::jpeg`], [`super::jpegls`], [`super::jpeg2000`]), each refused when
//! it decodes to more than its bytes can hold or declares another frame than the header.

use super::lengths::Codec;
use super::{jpeg, jpeg2000, jpegls, rle};
use crate::io::{Format, LoadError};

/// The frames a file declares: how many, their columns and rows, and `bits` a pixel (1, 8, 16
/// or 32).
#[derive(Debug, Clone, Copy)]
pub(in crate::io) struct Frames {
    pub count: usize,
    pub size: [usize; 2],
    pub bits: usize,
}

impl Frames {
    pub(in crate::io) fn pixels(&self) -> usize {
        self.size[0].saturating_mul(self.size[1])
    }
}

/// What a compressed frame decodes to: how many pixels, and how many bytes a pixel.
#[derive(Debug, Clone, Copy)]
pub(in crate::io) struct FrameShape {
    pub pixels: usize,
    pub bytes: usize,
}

impl FrameShape {
    /// The frame's decoded bytes, refused when more than `expansion` times its `compressed`
    /// bytes could hold (`what` names the codec's frames): what bounds a decoder's memory by
    /// the file's size.
    pub(in crate::io) fn bytes_within(
        &self,
        compressed: usize,
        expansion: usize,
        what: &'static str,
        format: Format,
    ) -> Result<usize, LoadError> {
        let bytes = self.pixels.saturating_mul(self.bytes);
        let possible = compressed.saturating_mul(expansion);
        if bytes > possible {
            return Err(LoadError::CountTooLarge {
                format,
                what,
                claimed: bytes as u64,
                possible: possible as u64,
            });
        }
        Ok(bytes)
    }
}

/// What a compressed frame's own header (a JPEG frame header, a JPEG 2000 size marker) says.
pub(in crate::io) struct Declared {
    pub columns: usize,
    pub rows: usize,
    pub components: usize,
    pub bits: usize,
    /// A component sampled more coarsely than the frame.
    pub subsampled: bool,
}

impl FrameShape {
    /// Refuses a codestream that declares other than one grey component of the DICOM header's
    /// `size` (columns and rows) in bits its pixels hold.
    pub(in crate::io) fn check_declared(
        &self,
        size: [usize; 2],
        d: &Declared,
    ) -> Result<(), String> {
        let grey = d.components == 1 && !d.subsampled;
        if [d.columns, d.rows] == size && grey && d.bits <= 8 * self.bytes {
            return Ok(());
        }
        Err(format!(
            "{} x {} pixels of {} component(s) and {} bits, where the header declares {} x {} \
             grey pixels of {} bytes",
            d.columns, d.rows, d.components, d.bits, size[0], size[1], self.bytes
        ))
    }
}

/// Each of `codestreams` (one a frame) decoded by `frame` onto the pixels before it; `frame`
/// words an error about its codestream with the `bad` it is given, which names the frame
/// (`codec` says whose).
pub(in crate::io) fn frame_by_frame(
    codestreams: &[&[u8]],
    codec: &str,
    format: Format,
    mut frame: impl FnMut(&[u8], &dyn Fn(String) -> LoadError, &mut Vec<u8>) -> Result<(), LoadError>,
) -> Result<Vec<u8>, LoadError> {
    let mut out = Vec::new();
    for (index, stream) in codestreams.iter().enumerate() {
        let bad = |detail: String| LoadError::Unsupported {
            format,
            detail: format!("{codec} frame {}: {detail}", index + 1),
        };
        frame(stream, &bad, &mut out)?;
    }
    Ok(out)
}

/// Encapsulated frames, decoded: one fragment a frame, or for a single frame (JPEG, JPEG-LS,
/// JPEG 2000) all of them, in order.
pub(in crate::io) fn decode(
    codec: Codec,
    fragments: &[&[u8]],
    frames: Frames,
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    let refuse = |detail: String| LoadError::Unsupported { format, detail };
    if !frames.bits.is_multiple_of(8) || frames.bits == 0 {
        return Err(refuse(format!(
            "compressed pixels of {} bit(s) are not read",
            frames.bits
        )));
    }
    let joined;
    let streams = match (codec, frames.count) {
        (Codec::Jpeg | Codec::Jpeg2000 | Codec::JpegLs, 1) if fragments.len() > 1 => {
            joined = fragments.concat();
            vec![joined.as_slice()]
        }
        _ if fragments.len() == frames.count => fragments.to_vec(),
        _ => {
            return Err(refuse(format!(
                "{} fragments of compressed pixels for {} frames: one a frame is read",
                fragments.len(),
                frames.count
            )))
        }
    };
    let shape = FrameShape {
        pixels: frames.pixels(),
        bytes: frames.bits / 8,
    };
    match codec {
        Codec::Rle => rle::decode(&streams, shape, format),
        Codec::Jpeg => jpeg::decode(&streams, shape, frames.size, format),
        Codec::Jpeg2000 => jpeg2000::decode(&streams, shape, frames.size, format),
        Codec::JpegLs => jpegls::decode(&streams, shape, frames.size, format),
    }
}
