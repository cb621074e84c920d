//! EXT_meshopt_compression's encoders, from `meshopt-rs` (the pure-Rust port of meshoptimizer):
//! vertex codec version 0 for attribute views, index codec version 1 for triangle lists, the
//! versions the extension specifies.

use meshopt_rs::index::buffer::{encode_index_buffer, encode_index_buffer_bound};
use meshopt_rs::index::IndexEncodingVersion;
use meshopt_rs::vertex::buffer::{encode_vertex_buffer, encode_vertex_buffer_bound};
use meshopt_rs::vertex::VertexEncodingVersion;

/// Attribute data of `stride`-byte elements (4, 8, 12 or 16), compressed; `None` for any other
/// stride or a length that is not whole elements.
pub(super) fn encode_attributes(bytes: &[u8], stride: usize) -> Option<Vec<u8>> {
    match stride {
        4 => encode::<4>(bytes),
        8 => encode::<8>(bytes),
        12 => encode::<12>(bytes),
        16 => encode::<16>(bytes),
        _ => None,
    }
}

fn encode<const N: usize>(bytes: &[u8]) -> Option<Vec<u8>> {
    if !bytes.len().is_multiple_of(N) {
        return None;
    }
    // The codec takes elements as a type whose size is the stride.
    let elements: Vec<[u8; N]> = bytes
        .chunks_exact(N)
        .map(|c| c.try_into().unwrap_or([0; N]))
        .collect();
    let mut out = vec![0; encode_vertex_buffer_bound(elements.len(), N)];
    let written = encode_vertex_buffer(&mut out, &elements, VertexEncodingVersion::V0)?;
    out.truncate(written);
    Some(out)
}

/// A triangle list's indices (referring to `vertex_count` vertices), compressed; `None` when
/// they do not make whole triangles.
pub(super) fn encode_triangles(indices: &[u32], vertex_count: usize) -> Option<Vec<u8>> {
    if !indices.len().is_multiple_of(3) {
        return None;
    }
    let mut out = vec![0; encode_index_buffer_bound(indices.len(), vertex_count)];
    let written = encode_index_buffer(&mut out, indices, IndexEncodingVersion::V1)?;
    out.truncate(written);
    Some(out)
}
