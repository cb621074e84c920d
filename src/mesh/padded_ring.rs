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

/// Rows filled per parallel task.
const BLOCK: usize = 4096;

/// Per vertex, its smoothing ring padded to [`PADDED_WIDTH`] slots, and the ring's inverse size.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PaddedRing {
    /// The ring's neighbours, then the vertex count (the zero entry) in the unused slots; for a
    /// larger ring, the range of `large` that holds it in its first two slots.
    pub rows: Vec<[u32; PADDED_WIDTH]>,
    /// `1 / ring size`; 0 for an isolated vertex (empty ring).
    pub inverse_sizes: Vec<f32>,
    /// The rings larger than a row, whole, one after another in vertex order.
    pub large: Vec<u32>,
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
        }
    }

    /// A ring that does not fit its row (see [`Self::fits`]), from the list of large rings.
    #[inline]
    pub fn large_ring(&self, row: &[u32; PADDED_WIDTH]) -> &[u32] {
        &self.large[row[0] as usize..row[1] as usize]
    }

    /// True when a ring of this inverse size fits a row whole (at least 1/8; an isolated
    /// vertex's 0 does not: it has nothing to read).
    #[inline(always)]
    pub fn fits(inverse_size: f32) -> bool {
        inverse_size >= 1.0 / PADDED_WIDTH as f32
    }
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
        assert!(PaddedRing::fits(p.inverse_sizes[0]));
        assert!(!PaddedRing::fits(p.inverse_sizes[1]));
        assert!(!PaddedRing::fits(p.inverse_sizes[2]));
        assert!(PaddedRing::fits(1.0 / 8.0) && !PaddedRing::fits(1.0 / 9.0));
    }
}
