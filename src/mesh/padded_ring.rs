//! The smoothing neighbourhood laid out for the CPU kernels: every vertex's ring in a fixed row of
//! [`PADDED_WIDTH`] slots.
//!
//! A kernel summing a CSR ring loops as many times as the vertex has neighbours, which varies
//! from vertex to vertex (3 to 12 on segmentation meshes), so the loop's exit is mispredicted
//! about once per vertex: on the 206k-vertex staircase mesh that made a Laplace step about twice
//! as slow as a fixed loop over eight slots. Unused slots name a zero entry one past the last
//! vertex (the kernels' buffers carry it), so they add nothing and need no branch. Rings with
//! more than eight neighbours (under 1% of segmentation meshes' vertices) are kept whole in a
//! short list of their own, which their rows point into: read that rarely, the full CSR falls out
//! of the cache, and its misses cost a Laplace step on the 206k-vertex mesh about a tenth.

use rayon::prelude::*;

/// Slots per row: rings up to this valence take the fixed loop.
pub const PADDED_WIDTH: usize = 8;

/// Rows filled (or checked) per parallel task.
const BLOCK: usize = 4096;

/// Per vertex, its smoothing ring padded to [`PADDED_WIDTH`] slots, and the ring's inverse size.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PaddedRing {
    /// The ring's neighbours, then the vertex count (the zero entry) in the unused slots; for a
    /// larger ring, the range of `large` that holds it in its first two slots.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub rows: Vec<[u32; PADDED_WIDTH]>,
    /// `1 / ring size`; 0 for an isolated vertex (empty ring).
    #[serde(with = "crate::mesh::flat_bytes")]
    pub inverse_sizes: Vec<f32>,
    /// The rings larger than a row, whole, one after another in vertex order.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub large: Vec<u32>,
    /// How far a ring reaches in vertex order: the largest `|j - i|` over every vertex `i` and
    /// neighbour `j` (0 without edges). Meshes from a volume come in slice order, so this is
    /// a few slices' worth of vertices, far below the vertex count; a kernel that sweeps the
    /// vertices in order knows from it which results of an earlier pass a vertex can read.
    pub span: u32,
}

impl PaddedRing {
    /// Rows for the CSR ring `(offsets, neighbors)` (offsets one longer than the vertex count).
    pub fn new(offsets: &[u32], neighbors: &[u32]) -> Self {
        let n = offsets.len().saturating_sub(1);
        let mut rows = vec![[n as u32; PADDED_WIDTH]; n];
        let mut inverse_sizes = vec![0.0f32; n];
        // Filled in place, a block of rows per task: plain loops, no joining of vectors.
        rows.par_chunks_mut(BLOCK)
            .zip(inverse_sizes.par_chunks_mut(BLOCK))
            .enumerate()
            .for_each(|(b, (rows, inverse_sizes))| {
                let first = b * BLOCK;
                let offsets = &offsets[first..=first + rows.len()];
                let rings = offsets
                    .windows(2)
                    .map(|w| &neighbors[w[0] as usize..w[1] as usize]);
                for ((row, inverse), ring) in rows.iter_mut().zip(inverse_sizes).zip(rings) {
                    if ring.len() <= PADDED_WIDTH {
                        row[..ring.len()].copy_from_slice(ring);
                    }
                    if !ring.is_empty() {
                        *inverse = 1.0 / ring.len() as f32;
                    }
                }
            });
        let span = offsets
            .par_windows(2)
            .enumerate()
            .with_min_len(BLOCK)
            .map(|(i, w)| reach(i, &neighbors[w[0] as usize..w[1] as usize]))
            .max()
            .unwrap_or(0);
        // The large rings, in one pass over the offsets (few of them: no need to split it).
        let mut large = Vec::new();
        for (row, w) in rows.iter_mut().zip(offsets.windows(2)) {
            let ring = &neighbors[w[0] as usize..w[1] as usize];
            if ring.len() > PADDED_WIDTH {
                let start = large.len() as u32;
                large.extend_from_slice(ring);
                row[0] = start;
                row[1] = large.len() as u32;
            }
        }
        Self {
            rows,
            inverse_sizes,
            large,
            span,
        }
    }

    /// A ring that does not fit its row (see [`Self::fits`]), from the list of large rings.
    #[inline]
    pub fn large_ring(&self, row: &[u32; PADDED_WIDTH]) -> &[u32] {
        &self.large[row[0] as usize..row[1] as usize]
    }

    /// Whether these rows describe `vertex_count` vertices, so a kernel gathering from a buffer of
    /// `vertex_count + 1` entries (the zero entry last) reads nothing out of range: one row per
    /// vertex, every slot of a row that fits at most `vertex_count`, every large ring's range
    /// within the list and its entries below `vertex_count`. Checked once per topology;
    /// each task's loop has no early exit.
    pub fn describes(&self, vertex_count: usize) -> bool {
        let sized = self.rows.len() == vertex_count && self.inverse_sizes.len() == vertex_count;
        let large = self.large.len();
        sized
            && self.large.iter().all(|&j| (j as usize) < vertex_count)
            && self
                .rows
                .par_chunks(BLOCK)
                .zip(self.inverse_sizes.par_chunks(BLOCK))
                .enumerate()
                .all(|(b, (rows, inverse_sizes))| {
                    let rows = rows.iter().zip(inverse_sizes).enumerate();
                    rows.fold(true, |ok, (k, (row, &inv))| {
                        let i = b * BLOCK + k;
                        let fine = if Self::fits(inv) {
                            let padding = vertex_count as u32;
                            let near = |j: u32| j == padding || reach(i, &[j]) <= self.span;
                            row.iter()
                                .fold(true, |ok, &j| ok & (j as usize <= vertex_count) & near(j))
                        } else if inv != 0.0 {
                            row[0] <= row[1]
                                && row[1] as usize <= large
                                && reach(i, self.large_ring(row)) <= self.span
                        } else {
                            true
                        };
                        ok & fine
                    })
                })
    }

    /// True when a ring of this inverse size fits a row whole (at least 1/8; an isolated
    /// vertex's 0 does not: it has nothing to read).
    #[inline(always)]
    pub fn fits(inverse_size: f32) -> bool {
        inverse_size >= 1.0 / PADDED_WIDTH as f32
    }
}

/// The largest `|j - i|` over `ring`, the neighbours of vertex `i`.
#[inline]
fn reach(i: usize, ring: &[u32]) -> u32 {
    ring.iter()
        .map(|&j| (j as usize).abs_diff(i) as u32)
        .max()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_hold_the_ring_then_the_pad() {
        // Vertex 0: two neighbours; 1: none; 2: ten (more than a row).
        let big: Vec<u32> = (0..10).map(|k| k + 3).collect();
        let offsets = [0, 2, 2, 12];
        let neighbors: Vec<u32> = [7, 9].iter().copied().chain(big.clone()).collect();
        let p = PaddedRing::new(&offsets, &neighbors);
        assert_eq!(p.rows[0], [7, 9, 3, 3, 3, 3, 3, 3]);
        assert_eq!(p.rows[1], [3; 8]);
        assert_eq!(p.rows[2][..2], [0, 10]);
        assert_eq!(p.large_ring(&p.rows[2]), &big[..]);
        assert_eq!(p.inverse_sizes, vec![0.5, 0.0, 0.1]);
        // Vertex 2 reaches vertex 12.
        assert_eq!(p.span, 10);
        assert!(PaddedRing::fits(p.inverse_sizes[0]));
        assert!(!PaddedRing::fits(p.inverse_sizes[1]));
        assert!(!PaddedRing::fits(p.inverse_sizes[2]));
        assert!(PaddedRing::fits(1.0 / 8.0) && !PaddedRing::fits(1.0 / 9.0));
    }

    #[test]
    fn rows_describe_only_their_own_vertex_count() {
        // Twelve vertices: 0 has two neighbours, 2 has ten (a large ring), the rest none.
        let mut offsets = vec![0u32, 2, 2, 12];
        offsets.resize(13, 12);
        let neighbors = [7, 9, 0, 1, 3, 4, 5, 6, 7, 8, 9, 11];
        let p = PaddedRing::new(&offsets, &neighbors);
        assert!(p.describes(12));
        assert!(!p.describes(11) && !p.describes(13));
        assert_eq!(p.span, 9);
        // A slot past the zero entry, a large ring's range past the list, a neighbour that is
        // no vertex, rings that reach further than the span: not these rows.
        let mut short = p.clone();
        short.span = 8;
        let mut past = p.clone();
        past.rows[0][1] = 13;
        let mut beyond = p.clone();
        beyond.rows[2][1] = 11;
        let mut foreign = p.clone();
        foreign.large[3] = 12;
        for broken in [short, past, beyond, foreign] {
            assert!(!broken.describes(12));
        }
    }
}
