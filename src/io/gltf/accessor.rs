//! Accessors: where their elements lie in a buffer (checked against the buffer view and the buffer
//! before anything is allocated), and reading positions and indices out of the bytes.

use std::borrow::Cow;

use ::gltf::json::accessor::{ComponentType, Type};
use ::gltf::json::validation::Checked;
use ::gltf::json::Root;
use base64::Engine as _;

use super::super::{Format, LoadError, Location};
use super::meshopt::Compression;

/// An accessor's elements, resolved to one buffer and bounds-checked against its declared length.
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    pub accessor: usize,
    pub buffer: usize,
    /// Byte offset of element 0 in the buffer.
    pub start: usize,
    pub stride: usize,
    pub count: usize,
    pub component: ComponentType,
    pub components: usize,
    pub normalized: bool,
}

fn component_size(c: ComponentType) -> usize {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn type_components(t: Type) -> usize {
    match t {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

fn syntax(format: Format, what: &'static str, index: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format,
        location: Location::Item(what, index),
        detail,
    }
}

/// Where a buffer view lies in its buffer, and the stride of its elements.
struct ViewSpan {
    buffer_index: usize,
    view_offset: u64,
    view_len: u64,
    stride: usize,
}

/// Checks buffer view `view_index` (read by accessor `index`, of `element`-byte elements): its
/// buffer exists, it lies inside that buffer's declared length, its stride holds an element.
fn view_span(
    root: &Root,
    view: &::gltf::json::buffer::View,
    view_index: usize,
    index: usize,
    element: usize,
    format: Format,
) -> Result<ViewSpan, LoadError> {
    let view_err = |detail: String| syntax(format, "buffer view", view_index, detail);
    let buffer_index = view.buffer.value();
    let buffer = (root.buffers.get(buffer_index))
        .ok_or_else(|| view_err(format!("buffer {buffer_index} does not exist")))?;
    let view_offset = view.byte_offset.map_or(0, |o| o.0);
    let view_len = view.byte_length.0;
    if view_offset
        .checked_add(view_len)
        .is_none_or(|end| end > buffer.byte_length.0)
    {
        return Err(view_err(format!(
            "bytes {view_offset}..+{view_len} lie past the end of buffer {buffer_index} ({} bytes)",
            buffer.byte_length.0
        )));
    }
    let stride = match view.byte_stride {
        Some(s) if s.0 != 0 => s.0,
        _ => element,
    };
    if stride < element {
        return Err(view_err(format!(
            "byteStride {stride} is smaller than accessor {index}'s element size {element}"
        )));
    }
    Ok(ViewSpan {
        buffer_index,
        view_offset,
        view_len,
        stride,
    })
}

/// Resolves accessor `index` and checks that every element it reads lies inside its buffer view,
/// and the view inside its buffer's declared `byteLength`. A compressed view's elements are read
/// from its decoded buffer (see [`Compression`]).
pub(super) fn layout(
    root: &Root,
    compression: &Compression,
    index: usize,
    format: Format,
) -> Result<Layout, LoadError> {
    let err = |detail: String| syntax(format, "accessor", index, detail);
    let a = root
        .accessors
        .get(index)
        .ok_or_else(|| err(format!("there are only {} accessors", root.accessors.len())))?;
    if a.sparse.is_some() {
        return Err(LoadError::Unsupported {
            format,
            detail: format!("accessor {index} is sparse (sparse accessors are not readable)"),
        });
    }
    let (Checked::Valid(ct), Checked::Valid(ty)) = (&a.component_type, &a.type_) else {
        return Err(err("invalid componentType or type".into()));
    };
    let component = ct.0;
    let components = type_components(*ty);
    let element = component_size(component) * components;
    let view_index = a
        .buffer_view
        .ok_or_else(|| err("has no bufferView".into()))?
        .value();
    let view = root
        .buffer_views
        .get(view_index)
        .ok_or_else(|| err(format!("buffer view {view_index} does not exist")))?;
    let ViewSpan {
        buffer_index,
        view_offset,
        view_len,
        stride,
    } = view_span(root, view, view_index, index, element, format)?;

    let offset = a.byte_offset.map_or(0, |o| o.0);
    let count = a.count.0;
    // Last element ends at offset + (count - 1) * stride + element.
    let end = match count {
        0 => Some(offset),
        n => (n - 1)
            .checked_mul(stride as u64)
            .and_then(|s| s.checked_add(offset))
            .and_then(|s| s.checked_add(element as u64)),
    };
    if end.is_none_or(|end| end > view_len) {
        return Err(err(format!(
            "{count} elements of {element} bytes (stride {stride}) from byte {offset} do not fit \
             in buffer view {view_index} ({view_len} bytes)"
        )));
    }
    // Every number below is bounded by the buffer length just checked, but that length is
    // still only declared: the bytes are checked when the buffer is loaded.
    let to_usize =
        |v: u64| usize::try_from(v).map_err(|_| err("too large for this platform".into()));
    let (buffer_index, view_offset) = match compression.source(view_index) {
        Some(decoded) => (decoded, 0),
        None => (buffer_index, view_offset),
    };
    Ok(Layout {
        accessor: index,
        buffer: buffer_index,
        start: to_usize(view_offset + offset)?,
        stride,
        count: to_usize(count)?,
        component,
        components,
        normalized: a.normalized,
    })
}

/// Loads the buffers marked in `needed` (the file's, then the decoded views': see
/// [`Compression::buffer_count`]), with the buffers the decoded ones read from.
pub(super) fn load_buffers<'a>(
    root: &'a Root,
    compression: &Compression,
    bin: Option<&'a [u8]>,
    needed: &[bool],
    format: Format,
) -> Result<Vec<Option<Cow<'a, [u8]>>>, LoadError> {
    let mut needed = needed.to_vec();
    compression.mark_sources(&mut needed);
    let mut buffers = load_file_buffers(root, compression, bin, &needed, format)?;
    compression.decode(&mut buffers, &needed, format)?;
    Ok(buffers)
}

/// Loads the file's buffers marked in `needed`: the GLB BIN chunk or a base64 data URI. A buffer
/// that names an external file is refused: parsers see bytes only, never the file system.
fn load_file_buffers<'a>(
    root: &'a Root,
    compression: &Compression,
    bin: Option<&'a [u8]>,
    needed: &[bool],
    format: Format,
) -> Result<Vec<Option<Cow<'a, [u8]>>>, LoadError> {
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        if !needed.get(i).copied().unwrap_or(false) {
            out.push(None);
            continue;
        }
        let data: Cow<'a, [u8]> = match buffer.uri.as_deref() {
            None if compression.is_fallback(i) => {
                return Err(syntax(
                    format,
                    "buffer",
                    i,
                    "is an EXT_meshopt_compression fallback without data, yet a view that is \
                     not compressed reads it"
                        .into(),
                ))
            }
            None => match (i, bin) {
                (0, Some(bin)) => Cow::Borrowed(bin),
                _ => {
                    return Err(syntax(
                        format,
                        "buffer",
                        i,
                        "has no uri and there is no GLB BIN chunk for it".into(),
                    ))
                }
            },
            Some(uri) => Cow::Owned(decode_data_uri(uri, i, format)?),
        };
        let declared = buffer.byte_length.0;
        if (data.len() as u64) < declared {
            return Err(syntax(
                format,
                "buffer",
                i,
                format!(
                    "byteLength is {declared} but the data holds only {} bytes",
                    data.len()
                ),
            ));
        }
        // The declared length fits in the data, so it fits in usize.
        let declared = declared as usize;
        out.push(Some(match data {
            Cow::Borrowed(b) => Cow::Borrowed(&b[..declared]),
            Cow::Owned(mut v) => {
                v.truncate(declared);
                Cow::Owned(v)
            }
        }));
    }
    Ok(out)
}

fn decode_data_uri(uri: &str, index: usize, format: Format) -> Result<Vec<u8>, LoadError> {
    let Some(rest) = uri.strip_prefix("data:") else {
        let shown: String = uri.chars().take(80).collect();
        return Err(LoadError::Unsupported {
            format,
            detail: format!(
                "buffer {index} refers to the external file '{shown}'; only self-contained files \
                 can be read: save as .glb or embed the buffers as data URIs"
            ),
        });
    };
    let (header, payload) = rest
        .split_once(',')
        .ok_or_else(|| syntax(format, "buffer", index, "data URI has no ','".into()))?;
    if !header.ends_with(";base64") {
        return Err(LoadError::Unsupported {
            format,
            detail: format!("buffer {index}: only base64 data URIs are readable"),
        });
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| syntax(format, "buffer", index, format!("data URI: {e}")))
}

/// Reads one accessor's elements as `f32` vectors of `N` components, converting integer types
/// (normalised or not, as KHR_mesh_quantization allows).
pub(super) fn read_vectors<const N: usize>(
    layout: &Layout,
    data: &[u8],
    format: Format,
) -> Result<Vec<[f32; N]>, LoadError> {
    let err = |detail: String| syntax(format, "accessor", layout.accessor, detail);
    if layout.components != N {
        return Err(err(format!(
            "has {} components per element, expected {N}",
            layout.components
        )));
    }
    if layout.component == ComponentType::U32 {
        return Err(LoadError::Unsupported {
            format,
            detail: format!(
                "accessor {}: 32-bit integer vertex attributes are not allowed",
                layout.accessor
            ),
        });
    }
    let size = component_size(layout.component);
    let mut out = Vec::with_capacity(layout.count);
    for i in 0..layout.count {
        let at = layout.start + i * layout.stride;
        let bytes = data
            .get(at..at + size * N)
            .ok_or_else(|| err(format!("element {i} lies past the end of the buffer")))?;
        let mut v = [0.0f32; N];
        for (k, c) in bytes.chunks_exact(size).enumerate() {
            v[k] = component_value(layout.component, layout.normalized, c);
        }
        out.push(v);
    }
    Ok(out)
}

fn component_value(component: ComponentType, normalized: bool, c: &[u8]) -> f32 {
    let (raw, scale) = match (component, c) {
        (ComponentType::F32, &[a, b, c, d]) => return f32::from_le_bytes([a, b, c, d]),
        (ComponentType::I8, &[a]) => (a as i8 as f32, 127.0),
        (ComponentType::U8, &[a]) => (a as f32, 255.0),
        (ComponentType::I16, &[a, b]) => (i16::from_le_bytes([a, b]) as f32, 32767.0),
        (ComponentType::U16, &[a, b]) => (u16::from_le_bytes([a, b]) as f32, 65535.0),
        // Callers slice by the component's size; NaN would be caught as a bad coordinate.
        _ => return f32::NAN,
    };
    if normalized {
        // The specification's decoding: signed values clamp so that -128 and -127 both map to -1.
        (raw / scale).max(-1.0)
    } else {
        raw
    }
}

/// Reads an index accessor (unsigned byte, short or int scalars).
pub(super) fn read_indices(
    layout: &Layout,
    data: &[u8],
    format: Format,
) -> Result<Vec<u32>, LoadError> {
    let err = |detail: String| syntax(format, "accessor", layout.accessor, detail);
    if layout.components != 1 || layout.normalized {
        return Err(err("indices must be unnormalised scalars".into()));
    }
    let size = match layout.component {
        ComponentType::U8 | ComponentType::U16 | ComponentType::U32 => {
            component_size(layout.component)
        }
        other => {
            return Err(err(format!(
                "index component type {other:?} is not an unsigned integer"
            )))
        }
    };
    let mut out = Vec::with_capacity(layout.count);
    for i in 0..layout.count {
        let at = layout.start + i * layout.stride;
        let c = data
            .get(at..at + size)
            .ok_or_else(|| err(format!("element {i} lies past the end of the buffer")))?;
        out.push(match c {
            [a] => *a as u32,
            [a, b] => u16::from_le_bytes([*a, *b]) as u32,
            [a, b, c, d] => u32::from_le_bytes([*a, *b, *c, *d]),
            _ => return Err(err("bad index size".into())),
        });
    }
    Ok(out)
}

/// The bytes of buffer view `index` read as they are (a view holding a blob, not elements):
/// checked to lie in its buffer, which must be loaded and not compressed.
pub(super) fn view_bytes<'b>(
    root: &Root,
    compression: &Compression,
    buffers: &'b [Option<Cow<'_, [u8]>>],
    index: usize,
    format: Format,
) -> Result<&'b [u8], LoadError> {
    let err = |detail: String| syntax(format, "buffer view", index, detail);
    let view = (root.buffer_views.get(index)).ok_or_else(|| err("does not exist".into()))?;
    if compression.source(index).is_some() {
        return Err(err("is compressed, where a plain one was expected".into()));
    }
    let span = view_span(root, view, index, index, 1, format)?;
    let buffer = (buffers.get(span.buffer_index))
        .and_then(Option::as_deref)
        .ok_or_else(|| err(format!("buffer {} holds no data", span.buffer_index)))?;
    // The span lies within the buffer's declared length, which the loaded data holds.
    let start = span.view_offset as usize;
    (buffer.get(start..start + span.view_len as usize))
        .ok_or_else(|| err("lies past the end of its buffer".into()))
}
