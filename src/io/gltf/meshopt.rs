//! `EXT_meshopt_compression`: buffer views whose bytes are compressed in another buffer. Each
//! one read is decoded (with `meshopt-rs`, the pure-Rust port of meshoptimizer) into a buffer of
//! its own, appended after the file's buffers, so accessors read it like any other.
//!
//! Memory stays bounded by the file: a view's decoded size is its declared `count` times
//! `byteStride`, which must equal its `byteLength`, and is checked against the least number of
//! compressed bytes the codec needs for it (a 64th of it for attributes, a byte per triangle)
//! before anything is allocated; the compressed bytes must lie inside their buffer.

use std::borrow::Cow;

use ::gltf::json::Root;
use meshopt_rs::index::buffer::decode_index_buffer;
use meshopt_rs::vertex::buffer::decode_vertex_buffer;
use meshopt_rs::vertex::filter::{
    decode_filter_exp, decode_filter_oct_16, decode_filter_oct_8, decode_filter_quat,
};
use serde::Deserialize;

use super::super::{Format, LoadError, Location};

pub(super) const NAME: &str = "EXT_meshopt_compression";

/// The attribute codec's groups: 16 elements, 2 header bits each per byte of an element.
const GROUP: u64 = 16;
const TAIL: u64 = 32;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
}

/// What the decoder applies to decoded attributes, as the extension defines it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Filter {
    None,
    /// Unit vectors as octahedral x, y with 1.0 in z, 8 or 16 bits each (strides 4 and 8).
    Octahedral,
    /// Rotations as three components and the index of the fourth, 16 bits each (stride 8).
    Quaternion,
    /// Floats as a 24-bit mantissa and an 8-bit exponent (strides of whole 4 bytes).
    Exponential,
}

/// A view's compressed form, as its extension object declares it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Compressed {
    buffer: usize,
    offset: u64,
    length: u64,
    stride: usize,
    count: u64,
    mode: Mode,
    filter: Filter,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct RawView {
    buffer: u64,
    #[serde(default)]
    byte_offset: u64,
    byte_length: u64,
    byte_stride: u64,
    count: u64,
    mode: String,
    #[serde(default)]
    filter: Option<String>,
}

/// The parts of the document the `gltf` crate drops: the views' and buffers' extensions.
#[derive(Deserialize, Default)]
struct Extensions {
    #[serde(default, rename = "bufferViews")]
    views: Vec<Holder>,
    #[serde(default)]
    buffers: Vec<Holder>,
}

#[derive(Deserialize, Default)]
struct Holder {
    #[serde(default)]
    extensions: Option<serde_json::Map<String, serde_json::Value>>,
}

impl Holder {
    fn meshopt(&self) -> Option<&serde_json::Value> {
        self.extensions.as_ref()?.get(NAME)
    }
}

/// Which views of a document are compressed, and which buffers are fallbacks without data.
#[derive(Debug, Default)]
pub(super) struct Compression {
    views: Vec<Option<Compressed>>,
    fallback: Vec<bool>,
    /// The file's own buffers: decoded view `v` is buffer `real + v`.
    real: usize,
}

fn syntax(format: Format, what: &'static str, index: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format,
        location: Location::Item(what, index),
        detail,
    }
}

impl Compression {
    /// Reads the extension objects of `json` (already validated as `root`).
    pub(super) fn parse(json: &[u8], root: &Root, format: Format) -> Result<Self, LoadError> {
        let real = root.buffers.len();
        let uses = root.extensions_used.iter().any(|e| e == NAME);
        if !uses {
            return Ok(Compression {
                views: vec![None; root.buffer_views.len()],
                fallback: vec![false; real],
                real,
            });
        }
        let raw: Extensions = serde_json::from_slice(json).unwrap_or_default();
        let fallback = (0..real)
            .map(|i| {
                let ext = raw.buffers.get(i).and_then(Holder::meshopt);
                ext.and_then(|e| e.get("fallback")?.as_bool()) == Some(true)
            })
            .collect();
        let views = (0..root.buffer_views.len())
            .map(|i| match raw.views.get(i).and_then(Holder::meshopt) {
                Some(ext) => compressed(ext, root, i, format).map(Some),
                None => Ok(None),
            })
            .collect::<Result<_, _>>()?;
        Ok(Compression {
            views,
            fallback,
            real,
        })
    }

    /// The buffer a view's elements are read from: its decoded buffer where it is compressed.
    pub(super) fn source(&self, view: usize) -> Option<usize> {
        self.views.get(view)?.map(|_| self.real + view)
    }

    /// How many buffers readers index: the file's, then one per view.
    pub(super) fn buffer_count(&self) -> usize {
        self.real + self.views.len()
    }

    pub(super) fn is_fallback(&self, buffer: usize) -> bool {
        self.fallback.get(buffer).copied().unwrap_or(false)
    }

    /// The file's buffers that the decoded buffers in `needed` read from, marked in `needed`.
    pub(super) fn mark_sources(&self, needed: &mut [bool]) {
        for (v, c) in self.views.iter().enumerate() {
            if let (Some(c), Some(true)) = (c, needed.get(self.real + v).copied()) {
                if let Some(flag) = needed.get_mut(c.buffer) {
                    *flag = true;
                }
            }
        }
    }

    /// Decodes each view marked in `needed` into its buffer, appended to `buffers` (the file's).
    pub(super) fn decode<'a>(
        &self,
        buffers: &mut Vec<Option<Cow<'a, [u8]>>>,
        needed: &[bool],
        format: Format,
    ) -> Result<(), LoadError> {
        buffers.truncate(self.real);
        for (v, c) in self.views.iter().enumerate() {
            let decoded = match (c, needed.get(self.real + v).copied()) {
                (Some(c), Some(true)) => Some(Cow::Owned(decode_view(c, buffers, v, format)?)),
                _ => None,
            };
            buffers.push(decoded);
        }
        Ok(())
    }
}

/// Reads and checks one view's extension object against the view and the buffers.
fn compressed(
    ext: &serde_json::Value,
    root: &Root,
    index: usize,
    format: Format,
) -> Result<Compressed, LoadError> {
    let err = |detail: String| syntax(format, "buffer view", index, format!("{NAME}: {detail}"));
    let raw = RawView::deserialize(ext).map_err(|e| err(e.to_string()))?;
    let view = &root.buffer_views[index];
    let (mode, filter) = mode_of(&raw, index, format)?;
    let stride = raw.byte_stride;
    let stride_ok = match mode {
        Mode::Attributes => stride > 0 && stride % 4 == 0 && stride <= 256,
        Mode::Triangles => (stride == 2 || stride == 4) && raw.count % 3 == 0,
    };
    let filter_ok = match filter {
        Filter::None | Filter::Exponential => true,
        Filter::Octahedral => stride == 4 || stride == 8,
        Filter::Quaternion => stride == 8,
    };
    if !stride_ok || !filter_ok {
        return Err(err(format!(
            "byteStride {stride} with count {} does not suit mode {} and filter {}",
            raw.count,
            raw.mode,
            raw.filter.as_deref().unwrap_or("NONE")
        )));
    }
    if let Some(own) = view.byte_stride.filter(|s| s.0 as u64 != stride) {
        return Err(err(format!(
            "byteStride {stride} differs from the view's {}",
            own.0
        )));
    }
    if raw.count.checked_mul(stride) != Some(view.byte_length.0) {
        return Err(err(format!(
            "{} elements of {stride} bytes are not the view's byteLength {}",
            raw.count, view.byte_length.0
        )));
    }
    let buffer = usize::try_from(raw.buffer).unwrap_or(usize::MAX);
    let declared = root
        .buffers
        .get(buffer)
        .ok_or_else(|| err(format!("buffer {} does not exist", raw.buffer)))?
        .byte_length
        .0;
    if raw
        .byte_offset
        .checked_add(raw.byte_length)
        .is_none_or(|end| end > declared)
    {
        return Err(err(format!(
            "compressed bytes {}..+{} lie past the end of buffer {buffer} ({declared} bytes)",
            raw.byte_offset, raw.byte_length
        )));
    }
    let least = least_compressed(mode, raw.count, stride);
    if raw.byte_length < least {
        return Err(err(format!(
            "{} bytes cannot hold {} compressed elements of {stride} bytes (at least {least})",
            raw.byte_length, raw.count
        )));
    }
    Ok(Compressed {
        buffer,
        offset: raw.byte_offset,
        length: raw.byte_length,
        stride: stride as usize,
        count: raw.count,
        mode,
        filter,
    })
}

/// The view's mode and filter, when they are ones read here (`INDICES` is not; a filter only
/// applies to attributes).
fn mode_of(raw: &RawView, index: usize, format: Format) -> Result<(Mode, Filter), LoadError> {
    let unsupported = |what: String| LoadError::Unsupported {
        format,
        detail: format!("buffer view {index}: {NAME} {what} is not readable"),
    };
    let mode = match raw.mode.as_str() {
        "ATTRIBUTES" => Mode::Attributes,
        "TRIANGLES" => Mode::Triangles,
        other => return Err(unsupported(format!("mode '{other}'"))),
    };
    let filter = match (raw.filter.as_deref().unwrap_or("NONE"), mode) {
        ("NONE", _) => Filter::None,
        ("OCTAHEDRAL", Mode::Attributes) => Filter::Octahedral,
        ("QUATERNION", Mode::Attributes) => Filter::Quaternion,
        ("EXPONENTIAL", Mode::Attributes) => Filter::Exponential,
        (other, _) => {
            return Err(unsupported(format!(
                "filter '{other}' in mode {}",
                raw.mode
            )))
        }
    };
    Ok((mode, filter))
}

/// The fewest compressed bytes that decode to `count` elements of `stride` bytes: the header
/// bits of every group and the tail for attributes, a code per triangle and the 16-byte table
/// for triangles. This bounds a decoded view by its compressed bytes in the file.
fn least_compressed(mode: Mode, count: u64, stride: u64) -> u64 {
    match mode {
        Mode::Attributes => {
            let block = ((8192 / stride) & !(GROUP - 1)).min(256);
            let header = |elements: u64| elements.div_ceil(GROUP).div_ceil(4) * stride;
            let (full, rest) = (count / block, count % block);
            let rest = if rest > 0 { header(rest) } else { 0 };
            1 + full.saturating_mul(header(block)) + rest + stride.max(TAIL)
        }
        Mode::Triangles => 1 + count / 3 + 16,
    }
}

fn decode_view(
    c: &Compressed,
    buffers: &[Option<Cow<[u8]>>],
    view: usize,
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    let err = |detail: String| syntax(format, "buffer view", view, format!("{NAME}: {detail}"));
    let source = buffers
        .get(c.buffer)
        .and_then(|b| b.as_deref())
        .ok_or_else(|| err(format!("buffer {} was not loaded", c.buffer)))?;
    // Both were checked against the buffer's declared length, which the loaded data holds.
    let data = usize::try_from(c.offset)
        .ok()
        .zip(usize::try_from(c.offset + c.length).ok())
        .and_then(|(start, end)| source.get(start..end))
        .ok_or_else(|| err("the compressed bytes lie past the end of their buffer".into()))?;
    let size = c
        .count
        .checked_mul(c.stride as u64)
        .and_then(|s| usize::try_from(s).ok())
        .ok_or_else(|| err("too large for this platform".into()))?;
    let decoded = match c.mode {
        Mode::Attributes => decode_attributes(data, c.stride, size),
        Mode::Triangles => decode_triangles(data, c.stride, size),
    };
    let mut decoded = decoded.ok_or_else(|| err("the compressed data is corrupt".into()))?;
    unfilter(&mut decoded, c.filter, c.stride);
    Ok(decoded)
}

/// Applies `filter` to decoded elements of `stride` bytes (a stride the filter allows).
fn unfilter(bytes: &mut [u8], filter: Filter, stride: usize) {
    // The crate's filters take the elements as typed slices: copy through them, as the
    // bytes' alignment is not known.
    fn through<T: Copy + Default, const N: usize>(
        bytes: &mut [u8],
        from: fn([u8; N]) -> T,
        to: fn(T) -> [u8; N],
        apply: fn(&mut [T]),
    ) {
        let mut typed: Vec<T> = (bytes.chunks_exact(N))
            .map(|c| from(c.try_into().unwrap_or([0; N])))
            .collect();
        apply(&mut typed);
        for (c, t) in bytes.chunks_exact_mut(N).zip(typed) {
            c.copy_from_slice(&to(t));
        }
    }
    let shorts = |b: [u8; 8]| std::array::from_fn(|k| u16::from_le_bytes([b[2 * k], b[2 * k + 1]]));
    let short_bytes = |s: [u16; 4]| {
        let mut out = [0u8; 8];
        for (k, v) in s.iter().enumerate() {
            out[2 * k..2 * k + 2].copy_from_slice(&v.to_le_bytes());
        }
        out
    };
    match (filter, stride) {
        (Filter::None, _) => {}
        (Filter::Octahedral, 4) => through::<[u8; 4], 4>(bytes, |b| b, |b| b, decode_filter_oct_8),
        (Filter::Octahedral, _) => {
            through::<[u16; 4], 8>(bytes, shorts, short_bytes, decode_filter_oct_16)
        }
        (Filter::Quaternion, _) => {
            through::<[u16; 4], 8>(bytes, shorts, short_bytes, decode_filter_quat)
        }
        (Filter::Exponential, _) => through::<u32, 4>(
            bytes,
            u32::from_le_bytes,
            u32::to_le_bytes,
            decode_filter_exp,
        ),
    }
}

/// Attribute data of `size` bytes in `stride`-byte elements (a multiple of 4 up to 256).
fn decode_attributes(data: &[u8], stride: usize, size: usize) -> Option<Vec<u8>> {
    macro_rules! strides {
        ($($n:literal)*) => {
            match stride {
                $($n => decode_elements::<$n>(data, size / $n),)*
                _ => None,
            }
        };
    }
    strides!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108
        112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196
        200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

fn decode_elements<const N: usize>(data: &[u8], count: usize) -> Option<Vec<u8>> {
    let mut out = vec![[0u8; N]; count];
    decode_vertex_buffer(&mut out, data).ok()?;
    Some(out.into_iter().flatten().collect())
}

/// Triangle indices of `size` bytes, 2 or 4 bytes each.
fn decode_triangles(data: &[u8], stride: usize, size: usize) -> Option<Vec<u8>> {
    let mut indices = vec![0u32; size / stride];
    decode_index_buffer(&mut indices, data).ok()?;
    Some(match stride {
        // The codec's 16-bit output keeps each index's low bits.
        2 => indices
            .iter()
            .flat_map(|&i| (i as u16).to_le_bytes())
            .collect(),
        _ => indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshopt_rs::vertex::buffer::{encode_vertex_buffer, encode_vertex_buffer_bound};
    use meshopt_rs::vertex::VertexEncodingVersion;

    #[test]
    fn the_least_compressed_size_is_what_the_encoder_writes_for_zeros() {
        for (count, stride) in [(0usize, 4usize), (1, 8), (300, 8), (5000, 12), (17, 256)] {
            let bytes = vec![0u8; count * stride];
            let encoded = match stride {
                4 => encode_for::<4>(&bytes),
                8 => encode_for::<8>(&bytes),
                12 => encode_for::<12>(&bytes),
                _ => encode_for::<256>(&bytes),
            };
            let least = least_compressed(Mode::Attributes, count as u64, stride as u64);
            assert_eq!(encoded.len() as u64, least, "{count} x {stride}");
            assert_eq!(
                decode_attributes(&encoded, stride, count * stride),
                Some(bytes)
            );
        }
    }

    fn encode_for<const N: usize>(bytes: &[u8]) -> Vec<u8> {
        let elements: Vec<[u8; N]> = bytes
            .chunks_exact(N)
            .map(|c| c.try_into().expect("N bytes"))
            .collect();
        let mut out = vec![0; encode_vertex_buffer_bound(elements.len(), N)];
        let n = encode_vertex_buffer(&mut out, &elements, VertexEncodingVersion::V0).expect("fits");
        out.truncate(n);
        out
    }
}
