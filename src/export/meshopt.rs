//! EXT_meshopt_compression's encoders, from `meshopt-rs` (the pure-Rust port of meshoptimizer):
//! vertex codec version 0 for attribute views, index codec version 1 for triangle lists, the
//! versions the extension specifies.

use meshopt_rs::index::buffer::{encode_index_buffer, encode_index_buffer_bound};
use meshopt_rs::index::IndexEncodingVersion;
use meshopt_rs::vertex::buffer::{encode_vertex_buffer, encode_vertex_buffer_bound};
use meshopt_rs::vertex::cache::optimize_vertex_cache_strip;
use meshopt_rs::vertex::fetch::optimize_vertex_fetch_remap;
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

/// The order in which the codecs compress a mesh best: triangles reordered for the vertex
/// cache (the index codec encodes recently seen edges and vertices in a few bits), then
/// vertices in the order the triangles first use them (the vertex codec encodes each vertex as
/// a difference from the one before). Returns the triangles on the new vertex numbers and, for
/// each new vertex, its old number; vertices no triangle uses are left out.
pub(super) fn codec_order(
    triangles: &[[u32; 3]],
    vertex_count: usize,
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    let mut cached = vec![0u32; flat.len()];
    optimize_vertex_cache_strip(&mut cached, &flat, vertex_count);
    let mut remap = vec![0u32; vertex_count];
    let kept = optimize_vertex_fetch_remap(&mut remap, &cached);
    let mut old_of_new = vec![0u32; kept];
    for (old, &new) in remap.iter().enumerate() {
        if let Some(slot) = old_of_new.get_mut(new as usize) {
            *slot = old as u32;
        }
    }
    let renumbered = cached
        .chunks_exact(3)
        .map(|t| {
            [
                remap[t[0] as usize],
                remap[t[1] as usize],
                remap[t[2] as usize],
            ]
        })
        .collect();
    (renumbered, old_of_new)
}
