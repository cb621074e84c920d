//! Building a [`Topology`]: the vertex->triangle incidence by counting sort, every vertex's
//! 1-ring in parallel blocks (sorted, with each edge's triangle count), then the rings packed
//! into CSR arrays.

use std::ops::Range;

use super::{Mesh, Topology};
use rayon::prelude::*;

/// Vertices per parallel work item when building the rings.
const BLOCK: usize = 2048;

/// The topology of `mesh`. Triangle indices must be in range (the parsers guarantee it).
pub(super) fn build(mesh: &Mesh) -> Topology {
    let mut rings = Rings::new(mesh);
    rings.build(mesh);
    rings.pack()
}

/// A topology under construction.
struct Rings {
    triangle_offsets: Vec<u32>,
    vertex_triangles: Vec<u32>,
    /// Per vertex, two slots per incident triangle at twice its triangle offset: its distinct
    /// neighbours, sorted, at the front of its slots.
    raw: Vec<u32>,
    /// Parallel to `raw`: how many of the vertex's triangles use the edge to that neighbour.
    counts: Vec<u32>,
    /// Distinct neighbours of each vertex whose ring is built, in vertex order.
    unique: Vec<u32>,
}

impl Rings {
    /// The vertex->triangle incidence of `mesh`, by counting sort (ascending triangle order for
    /// free).
    fn new(mesh: &Mesh) -> Self {
        let n = mesh.positions.len();
        let tris = &mesh.triangles;
        debug_assert!(tris.iter().flatten().all(|&v| (v as usize) < n));
        let mut triangle_offsets = vec![0u32; n + 1];
        for t in tris {
            for (k, &v) in t.iter().enumerate() {
                if !t[..k].contains(&v) {
                    triangle_offsets[v as usize + 1] += 1;
                }
            }
        }
        for i in 1..triangle_offsets.len() {
            triangle_offsets[i] += triangle_offsets[i - 1];
        }
        let mut cursor: Vec<u32> = triangle_offsets[..n].to_vec();
        let mut vertex_triangles = vec![0u32; triangle_offsets[n] as usize];
        for (ti, t) in tris.iter().enumerate() {
            for (k, &v) in t.iter().enumerate() {
                if !t[..k].contains(&v) {
                    let c = &mut cursor[v as usize];
                    vertex_triangles[*c as usize] = ti as u32;
                    *c += 1;
                }
            }
        }
        let slots = 2 * vertex_triangles.len();
        Self {
            triangle_offsets,
            vertex_triangles,
            raw: vec![0; slots],
            counts: vec![0; slots],
            unique: Vec::new(),
        }
    }

    /// Builds every vertex's ring. `mesh` must be the one given to [`Self::new`].
    fn build(&mut self, mesh: &Mesh) {
        let n = self.triangle_offsets.len() - 1;
        let offsets = &self.triangle_offsets;
        let raw = by_blocks(&mut self.raw, offsets, 0..n, 2);
        let counts = by_blocks(&mut self.counts, offsets, 0..n, 2);
        let tris = &mesh.triangles;
        let vertex_triangles = &self.vertex_triangles;
        self.unique = raw
            .into_par_iter()
            .zip(counts)
            .flat_map_iter(|((range, raw), (_, counts))| {
                let base = 2 * offsets[range.start] as usize;
                range
                    .map(move |i| {
                        let slots =
                            2 * offsets[i] as usize - base..2 * offsets[i + 1] as usize - base;
                        let fan = &vertex_triangles[offsets[i] as usize..offsets[i + 1] as usize];
                        let slot = &mut raw[slots.clone()];
                        let counts = &mut counts[slots];
                        ring_of(i as u32, fan, tris, slot, counts)
                    })
                    // The closure borrows this block's slices only; collect before the next block.
                    .collect::<Vec<u32>>()
            })
            .collect();
    }

    /// The topology: the rings packed into CSR arrays, the boundary flags and the smoothing
    /// neighbourhood.
    fn pack(self) -> Topology {
        let n = self.triangle_offsets.len() - 1;
        let Self {
            triangle_offsets,
            vertex_triangles,
            raw,
            counts,
            unique,
        } = self;
        let mut offsets = vec![0u32; n + 1];
        for i in 0..n {
            offsets[i + 1] = offsets[i] + unique[i];
        }
        let total = offsets[n] as usize;
        let mut neighbors = vec![0u32; total];
        let mut edge_counts = vec![0u32; total];
        let to = &triangle_offsets;
        let packed = by_blocks(&mut neighbors, &offsets, 0..n, 1);
        let packed_counts = by_blocks(&mut edge_counts, &offsets, 0..n, 1);
        packed
            .into_par_iter()
            .zip(packed_counts)
            .for_each(|((range, nb), (_, ec))| {
                let base = offsets[range.start] as usize;
                for i in range {
                    let src = 2 * to[i] as usize;
                    let dst = offsets[i] as usize - base;
                    let k = unique[i] as usize;
                    nb[dst..dst + k].copy_from_slice(&raw[src..src + k]);
                    ec[dst..dst + k].copy_from_slice(&counts[src..src + k]);
                }
            });
        Topology::from_rings(
            (offsets, neighbors, edge_counts),
            triangle_offsets,
            vertex_triangles,
        )
    }
}

/// Writes vertex `i`'s distinct neighbours (over the triangles `fan`) sorted to the front of
/// `slot`, with how many of the triangles use each edge in `counts`; returns how many there are.
fn ring_of(i: u32, fan: &[u32], tris: &[[u32; 3]], slot: &mut [u32], counts: &mut [u32]) -> u32 {
    let mut len = 0;
    for &t in fan {
        for &v in &tris[t as usize] {
            if v != i {
                slot[len] = v;
                len += 1;
            }
        }
    }
    let slot = &mut slot[..len];
    slot.sort_unstable();
    let mut k = 0;
    for j in 0..len {
        if k > 0 && slot[k - 1] == slot[j] {
            counts[k - 1] += 1;
        } else {
            slot[k] = slot[j];
            counts[k] = 1;
            k += 1;
        }
    }
    k as u32
}

/// Splits `out`, the entries `scale * offsets[vertices.start] .. scale * offsets[vertices.end]`
/// of a per-vertex CSR array, into one slice per block of [`BLOCK`] vertices, with the block's
/// vertices: disjoint pieces that parallel tasks can fill.
pub(crate) fn by_blocks<'a, T>(
    out: &'a mut [T],
    offsets: &[u32],
    vertices: Range<usize>,
    scale: usize,
) -> Vec<(Range<usize>, &'a mut [T])> {
    let mut pieces = Vec::with_capacity(vertices.len().div_ceil(BLOCK));
    let mut rest = out;
    for start in vertices.clone().step_by(BLOCK) {
        let end = (start + BLOCK).min(vertices.end);
        let len = scale * (offsets[end] - offsets[start]) as usize;
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        pieces.push((start..end, piece));
    }
    pieces
}
