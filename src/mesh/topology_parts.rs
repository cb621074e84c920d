//! Building a [`Topology`] in steps, for a caller that must return between them (the browser's
//! one thread opening a large mesh draws a frame between steps): the vertex->triangle incidence
//! when created, the 1-rings a run of vertices per [`TopologyInParts::advance`], then the
//! compaction and the boundary in [`TopologyInParts::finish`]. `Topology::build` runs the same
//! steps in one call, so both give the same arrays.

use std::ops::Range;

use super::{Mesh, Topology};
use rayon::prelude::*;

/// Vertices per parallel work item when building the rings.
const BLOCK: usize = 2048;

/// A topology under construction.
pub struct TopologyInParts {
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

impl TopologyInParts {
    /// The vertex->triangle incidence of `mesh`, by counting sort (ascending triangle order for
    /// free). Triangle indices must be in range (the parsers guarantee it).
    pub fn new(mesh: &Mesh) -> Self {
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
            unique: Vec::with_capacity(n),
        }
    }

    fn vertex_count(&self) -> usize {
        self.triangle_offsets.len() - 1
    }

    /// Builds the rings of up to `vertices` more vertices (whole blocks of [`BLOCK`], at least
    /// one); returns whether every ring is built. `mesh` must be the one given to [`Self::new`].
    pub fn advance(&mut self, mesh: &Mesh, vertices: usize) -> bool {
        let n = self.vertex_count();
        assert_eq!(
            mesh.vertex_count(),
            n,
            "the mesh the incidence was built for"
        );
        let start = self.unique.len();
        let blocks = vertices.div_ceil(BLOCK).max(1);
        let end = n.min(start.saturating_add(blocks.saturating_mul(BLOCK)));
        let offsets = &self.triangle_offsets;
        let slots = 2 * offsets[start] as usize..2 * offsets[end] as usize;
        let raw = by_blocks(&mut self.raw[slots.clone()], offsets, start..end, 2);
        let counts = by_blocks(&mut self.counts[slots], offsets, start..end, 2);
        let tris = &mesh.triangles;
        let vertex_triangles = &self.vertex_triangles;
        let unique: Vec<u32> = raw
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
        self.unique.extend(unique);
        self.unique.len() == n
    }

    /// The share of the rings built, in [0, 1].
    pub fn fraction(&self) -> f32 {
        self.unique.len() as f32 / self.vertex_count().max(1) as f32
    }

    /// The topology, once [`Self::advance`] returned true: the rings packed into CSR arrays,
    /// the boundary flags and the smoothing neighbourhood.
    pub fn finish(self) -> Topology {
        let n = self.vertex_count();
        assert_eq!(self.unique.len(), n, "finish before every ring is built");
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures;

    #[test]
    fn any_steps_build_the_same_topology() {
        let meshes = [
            fixtures::tetrahedron(),
            fixtures::grid(70, 90),
            Mesh::new(
                vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0; 3]],
                vec![[0, 1, 2], [0, 0, 1]],
            ),
            Mesh::default(),
        ];
        for mesh in meshes {
            let whole = Topology::build(&mesh);
            for part in [1, BLOCK, BLOCK + 1, 3 * BLOCK] {
                let mut parts = TopologyInParts::new(&mesh);
                let mut calls = 1;
                while !parts.advance(&mesh, part) {
                    calls += 1;
                    assert!(parts.fraction() < 1.0);
                }
                let expected_calls = mesh.vertex_count().div_ceil(part.div_ceil(BLOCK) * BLOCK);
                assert_eq!(calls, expected_calls.max(1), "part {part}");
                assert_eq!(parts.finish(), whole, "part {part}");
            }
        }
    }
}
