//! A walk over a DICOM file's element headers that checks every declared length against the
//! bytes left, before `dicom-object` parses it: that parser reserves each value's declared
//! length (up to 4 GiB) before reading it, so a lying length in a small file would otherwise
//! cost gigabytes. The walk also finds the transfer syntax and refuses the encodings the reader
//! does not take (big-endian, compressions other than RLE, JPEG, JPEG-LS and JPEG 2000); a
//! deflated file is walked once inflated ([`deflate`]). The walk reads headers exactly as dicom-rs does
//! (an unknown VR has a 32-bit length, as UN), so that every value it will allocate has been
//! measured; what the two would read differently is refused.

use std::borrow::Cow;
use std::ops::Range;

use super::deflate::{self, MetaGroup, DEFLATED_EXPLICIT_LE};
use super::frames::{decode, Frames};
use crate::io::{Format, LoadError};

const EXPLICIT_LE: &str = "1.2.840.10008.1.2.1";
const IMPLICIT_LE: &str = "1.2.840.10008.1.2";
const RLE_LOSSLESS: &str = "1.2.840.10008.1.2.5";
/// JPEG baseline, extended (8 and 12 bits), lossless and its first-order prediction.
const JPEG: [&str; 4] = [
    "1.2.840.10008.1.2.4.50",
    "1.2.840.10008.1.2.4.51",
    "1.2.840.10008.1.2.4.57",
    "1.2.840.10008.1.2.4.70",
];
/// JPEG 2000 lossless only, and lossless or lossy.
const JPEG_2000: [&str; 2] = ["1.2.840.10008.1.2.4.90", "1.2.840.10008.1.2.4.91"];
/// JPEG-LS lossless, and near-lossless.
const JPEG_LS: [&str; 2] = ["1.2.840.10008.1.2.4.80", "1.2.840.10008.1.2.4.81"];
const UNDEFINED: u32 = u32::MAX;

const ITEM: (u16, u16) = (0xFFFE, 0xE000);
const SEQUENCE_END: (u16, u16) = (0xFFFE, 0xE0DD);
const PIXEL_DATA: (u16, u16) = (0x7FE0, 0x0010);
const TRANSFER_SYNTAX: (u16, u16) = (0x0002, 0x0010);
const GROUP_LENGTH: (u16, u16) = (0x0002, 0x0000);

/// What the walk found: where the DICOM stream starts (after the 128-byte preamble, or at 0 when
/// a file has none) and where the last Pixel Data value lies, so that the pixels are read from
/// the file's bytes rather than copied into the parsed object. A deflated file's positions are
/// in its inflated bytes, which the layout holds.
pub(in crate::io) struct Layout {
    pub start: usize,
    pub pixel_data: Option<PixelData>,
    inflated: Option<Vec<u8>>,
}

/// The inflated data set by its length: a failing test prints the layout, not megabytes.
impl std::fmt::Debug for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Layout")
            .field("start", &self.start)
            .field("pixel_data", &self.pixel_data)
            .field("inflated_bytes", &self.inflated.as_ref().map(Vec::len))
            .finish()
    }
}

/// Where the pixels lie in the file.
#[derive(Debug, Clone, PartialEq)]
pub(in crate::io) enum PixelData {
    /// Uncompressed, one value.
    Native(Range<usize>),
    /// Compressed: each fragment after the offset table.
    Encapsulated {
        codec: Codec,
        fragments: Vec<Range<usize>>,
    },
}

/// How encapsulated pixels are compressed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::io) enum Codec {
    Rle,
    Jpeg,
    Jpeg2000,
    JpegLs,
}

/// The file's [`Layout`], once every element length has been checked.
impl Layout {
    /// The frames' pixel data, uncompressed: in place within `bytes` (the file walked), or
    /// decoded; refused when there is none, or less than `frames` declare (`what` says what
    /// the bytes are for).
    pub(in crate::io) fn pixels<'a>(
        self,
        bytes: &'a [u8],
        frames: Frames,
        what: &'static str,
        format: Format,
    ) -> Result<Cow<'a, [u8]>, LoadError> {
        let no_pixels = || LoadError::Unsupported {
            format,
            detail: "no Pixel Data".into(),
        };
        let inflated = self.inflated;
        match self.pixel_data.ok_or_else(no_pixels)? {
            PixelData::Native(range) => {
                // Checked: usize is 32 bits in the browser, and the sizes come from the file.
                let needed = (frames.count.checked_mul(frames.pixels()))
                    .and_then(|n| n.checked_mul(frames.bits))
                    .map_or(usize::MAX, |n| n.div_ceil(8));
                if range.len() < needed {
                    return Err(LoadError::CountTooLarge {
                        format,
                        what,
                        claimed: needed as u64,
                        possible: range.len() as u64,
                    });
                }
                Ok(match inflated {
                    Some(mut inflated) => {
                        inflated.truncate(range.end);
                        inflated.drain(..range.start);
                        Cow::Owned(inflated)
                    }
                    None => Cow::Borrowed(&bytes[range]),
                })
            }
            PixelData::Encapsulated { codec, fragments } => {
                let source = inflated.as_deref().unwrap_or(bytes);
                let fragments: Vec<&[u8]> = fragments.iter().map(|r| &source[r.clone()]).collect();
                decode(codec, &fragments, frames, format).map(Cow::Owned)
            }
        }
    }
}

/// The file parsed up to its pixels (which stay in `bytes`, where [`Layout::pixel_data`]
/// says), once [`check`] has measured every length; `format` names the file in errors.
pub(in crate::io) fn open(
    bytes: &[u8],
    format: Format,
) -> Result<(Layout, dicom_object::DefaultDicomObject), LoadError> {
    use dicom_object::file::{OpenFileOptions, ReadPreamble};
    let layout = check(bytes, format)?;
    let walked = layout.inflated.as_deref().unwrap_or(bytes);
    let object = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Never)
        .read_until(dicom_dictionary_std::tags::PIXEL_DATA)
        .from_reader(&walked[layout.start..])
        .map_err(|e| LoadError::Unsupported {
            format,
            detail: format!("the DICOM object does not parse: {e}"),
        })?;
    Ok((layout, object))
}

/// `format` is what the errors call the file (a SEG, or a slice of an image series).
pub(in crate::io) fn check(bytes: &[u8], format: Format) -> Result<Layout, LoadError> {
    let start = if bytes.get(128..132) == Some(b"DICM") {
        132
    } else if bytes.starts_with(b"DICM") {
        4
    } else {
        return Err(LoadError::BadMagic {
            format,
            detail: "no 'DICM' after a 128-byte preamble".into(),
        });
    };
    let mut walk = Walk {
        format,
        bytes,
        at: start,
        pixel_data: None,
    };
    let (syntax, meta) = walk.meta_group()?;
    if syntax == DEFLATED_EXPLICIT_LE {
        let explicit = deflate::as_explicit(bytes, &meta, format)?;
        let layout = check(&explicit, format)?;
        return Ok(Layout {
            inflated: Some(explicit),
            ..layout
        });
    }
    let (implicit, codec) = match syntax.as_str() {
        EXPLICIT_LE => (false, None),
        IMPLICIT_LE => (true, None),
        RLE_LOSSLESS => (false, Some(Codec::Rle)),
        jpeg if JPEG.contains(&jpeg) => (false, Some(Codec::Jpeg)),
        j2k if JPEG_2000.contains(&j2k) => (false, Some(Codec::Jpeg2000)),
        jls if JPEG_LS.contains(&jls) => (false, Some(Codec::JpegLs)),
        other => return Err(unsupported_syntax(other, format)),
    };
    walk.data_set(implicit, codec)?;
    Ok(Layout {
        start: start - 4,
        pixel_data: walk.pixel_data,
        inflated: None,
    })
}

fn unsupported_syntax(uid: &str, format: Format) -> LoadError {
    let what = match uid {
        "1.2.840.10008.1.2.2" => "explicit VR big endian",
        _ => "a compressed or unknown encoding",
    };
    LoadError::Unsupported {
        format,
        detail: format!(
            "transfer syntax {uid} ({what}): uncompressed and deflated little-endian, RLE \
             Lossless, JPEG, JPEG-LS and JPEG 2000 files are read"
        ),
    }
}

struct Walk<'a> {
    format: Format,
    bytes: &'a [u8],
    at: usize,
    pixel_data: Option<PixelData>,
}

struct Header {
    tag: (u16, u16),
    len: u32,
    /// Whether the value is a sequence (or an item) whose content is more elements.
    nested: bool,
}

impl Walk<'_> {
    fn u16_at(&self, at: usize) -> Result<u16, LoadError> {
        let b = self.bytes.get(at..at + 2).ok_or_else(|| self.truncated())?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32_at(&self, at: usize) -> Result<u32, LoadError> {
        let b = self.bytes.get(at..at + 4).ok_or_else(|| self.truncated())?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn truncated(&self) -> LoadError {
        LoadError::Truncated {
            format: self.format,
            offset: self.bytes.len(),
            detail: format!("an element header at byte {} is cut off", self.at),
        }
    }

    /// The file meta group (always explicit VR little endian); returns the transfer syntax.
    /// Its elements are those within the length (0002,0000) declares, whatever their group:
    /// so dicom-rs reads them, and the data set starts where it says.
    fn meta_group(&mut self) -> Result<(String, MetaGroup), LoadError> {
        let group_start = self.at;
        let first = self.header(false)?;
        if first.tag != GROUP_LENGTH || first.len != 4 {
            return Err(self.bad("the file meta group does not open with its length (0002,0000)"));
        }
        let value = self.value(&first)?;
        let declared = u32::from_le_bytes([value[0], value[1], value[2], value[3]]);
        let end = self.at.saturating_add(declared as usize);
        let mut syntax = None;
        let mut syntax_element = 0..0;
        while self.at < end {
            let element_start = self.at;
            let header = self.header(false)?;
            if header.nested {
                return Err(self.bad("a sequence in the file meta group"));
            }
            let value = self.value(&header)?;
            if header.tag == TRANSFER_SYNTAX {
                let text = String::from_utf8_lossy(value);
                syntax = Some(text.trim_end_matches(['\0', ' ']).to_string());
                syntax_element = element_start..self.at;
            }
        }
        let syntax = syntax
            .ok_or_else(|| self.bad("no transfer syntax (0002,0010) in the file meta group"))?;
        let meta = MetaGroup {
            group: group_start..self.at,
            syntax: syntax_element,
        };
        Ok((syntax, meta))
    }

    /// `codec`: how the pixels are compressed, if they are (then encapsulated).
    fn data_set(&mut self, implicit: bool, codec: Option<Codec>) -> Result<(), LoadError> {
        // A sequence's value is items (PS3.5 7.5): dicom-rs reads what follows a sequence's
        // header as an item's, so anything else would be read differently from this walk.
        let mut items_next = false;
        while self.at < self.bytes.len() {
            let header = self.header(implicit)?;
            if std::mem::take(&mut items_next) && header.tag.0 != 0xFFFE {
                return Err(self.bad(&format!(
                    "a sequence holds ({:04X},{:04X}) where an item should start",
                    header.tag.0, header.tag.1
                )));
            }
            items_next = header.nested && header.tag != ITEM && header.len != 0;
            if header.tag == PIXEL_DATA && (header.len == UNDEFINED) != codec.is_some() {
                let detail = match codec {
                    Some(_) => "compressed pixel data that is not encapsulated",
                    None => "encapsulated pixel data in an uncompressed transfer syntax",
                };
                return Err(self.bad(detail));
            }
            if let (PIXEL_DATA, Some(codec)) = (header.tag, codec) {
                let fragments = self.fragments()?;
                self.pixel_data = Some(PixelData::Encapsulated { codec, fragments });
            } else if !header.nested {
                let start = self.at;
                self.value(&header)?;
                if header.tag == PIXEL_DATA {
                    self.pixel_data = Some(PixelData::Native(start..self.at));
                }
            } else if header.len != UNDEFINED {
                self.room_for(header.len)?;
            }
        }
        Ok(())
    }

    /// The fragments of encapsulated pixel data, after its offset table, up to the delimiter.
    fn fragments(&mut self) -> Result<Vec<Range<usize>>, LoadError> {
        let mut items = Vec::new();
        loop {
            let tag = (self.u16_at(self.at)?, self.u16_at(self.at + 2)?);
            let len = self.u32_at(self.at + 4)?;
            self.at += 8;
            match tag {
                SEQUENCE_END => break,
                ITEM if len != UNDEFINED => {
                    self.room_for(len)?;
                    items.push(self.at..self.at + len as usize);
                    self.at += len as usize;
                }
                _ => return Err(self.bad("the encapsulated pixel data holds other than items")),
            }
        }
        if items.is_empty() {
            return Err(self.bad("encapsulated pixel data without its offset table"));
        }
        items.remove(0);
        Ok(items)
    }

    /// Reads an element header at the cursor and steps past it (not past its value).
    fn header(&mut self, implicit: bool) -> Result<Header, LoadError> {
        let tag = (self.u16_at(self.at)?, self.u16_at(self.at + 2)?);
        if tag.0 == 0xFFFE {
            // Items and delimiters have no VR in any syntax; a delimiter has no value.
            let len = self.u32_at(self.at + 4)?;
            if !matches!(tag.1, 0xE000 | 0xE00D | 0xE0DD) {
                return Err(self.bad(&format!(
                    "(FFFE,{:04X}) is not an item or a delimiter",
                    tag.1
                )));
            }
            self.at += 8;
            return Ok(Header {
                tag,
                len: if tag == ITEM { len } else { 0 },
                nested: tag == ITEM,
            });
        }
        if implicit {
            let len = self.u32_at(self.at + 4)?;
            self.at += 8;
            let vr = dictionary_vr(tag);
            let nested = len == UNDEFINED || vr == Some(dicom_core::VR::SQ);
            if let Some(vr) = vr {
                self.whole_values(tag, vr.to_string().as_bytes(), len)?;
            }
            return Ok(Header { tag, len, nested });
        }
        let vr = self.bytes.get(self.at + 4..self.at + 6).unwrap_or_default();
        // PS3.5 7.1.2: these have a 16-bit length; every other VR, known or not, a 32-bit one.
        const SHORT: [&[u8]; 21] = [
            b"AE", b"AS", b"AT", b"CS", b"DA", b"DS", b"DT", b"FL", b"FD", b"IS", b"LO", b"LT",
            b"PN", b"SH", b"SL", b"SS", b"ST", b"TM", b"UI", b"UL", b"US",
        ];
        let long = !SHORT.contains(&vr);
        let len = if long {
            let len = self.u32_at(self.at + 8)?;
            self.at += 12;
            len
        } else {
            let len = u32::from(self.u16_at(self.at + 6)?);
            self.at += 8;
            len
        };
        self.whole_values(tag, vr, len)?;
        if vr != b"SQ" && len == UNDEFINED && tag != PIXEL_DATA {
            // dicom-rs reads such a value as a sequence in implicit VR; this walk does not.
            return Err(self.bad(&format!(
                "({:04X},{:04X}) has an undefined length but is not a sequence",
                tag.0, tag.1
            )));
        }
        Ok(Header {
            tag,
            len,
            nested: vr == b"SQ",
        })
    }

    /// Refuses a value of binary numbers (`vr`) whose length is not a whole number of them:
    /// dicom-rs reads the whole ones and steps on by the length without reading the rest, so
    /// its reading would go out of step with this walk (a fuzzed file had it then allocate
    /// gigabytes). The pixels are not read by dicom-rs.
    fn whole_values(&self, tag: (u16, u16), vr: &[u8], len: u32) -> Result<(), LoadError> {
        let size = match vr {
            b"US" | b"SS" | b"OW" => 2,
            b"UL" | b"SL" | b"FL" | b"AT" | b"OL" | b"OF" => 4,
            b"FD" | b"OD" | b"SV" | b"UV" | b"OV" => 8,
            _ => return Ok(()),
        };
        if len == UNDEFINED || len.is_multiple_of(size) || tag == PIXEL_DATA {
            return Ok(());
        }
        Err(self.bad(&format!(
            "({:04X},{:04X}) holds {len} bytes, not a whole number of {}'s {size} bytes",
            tag.0,
            tag.1,
            String::from_utf8_lossy(vr)
        )))
    }

    /// Steps past a value of defined length, returning it.
    fn value(&mut self, header: &Header) -> Result<&[u8], LoadError> {
        if header.len == UNDEFINED {
            return Err(self.bad(&format!(
                "element ({:04X},{:04X}) has an undefined length but is not a sequence",
                header.tag.0, header.tag.1
            )));
        }
        self.room_for(header.len)?;
        let start = self.at;
        self.at += header.len as usize;
        Ok(&self.bytes[start..self.at])
    }

    fn room_for(&self, len: u32) -> Result<(), LoadError> {
        let left = self.bytes.len() - self.at.min(self.bytes.len());
        if len as usize > left {
            return Err(LoadError::CountTooLarge {
                format: self.format,
                what: "bytes in an element",
                claimed: u64::from(len),
                possible: left as u64,
            });
        }
        Ok(())
    }

    fn bad(&self, detail: &str) -> LoadError {
        LoadError::Unsupported {
            format: self.format,
            detail: format!("byte {}: {detail}", self.at),
        }
    }
}

/// The VR the standard dictionary gives a tag, as dicom-rs reads it in implicit VR (whose files
/// do not say).
fn dictionary_vr(tag: (u16, u16)) -> Option<dicom_core::VR> {
    use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
    let entry = dicom_dictionary_std::StandardDataDictionary.by_tag(dicom_core::Tag(tag.0, tag.1));
    entry.map(|e| e.vr().relaxed())
}

#[cfg(test)]
#[path = "lengths_tests.rs"]
mod tests;
