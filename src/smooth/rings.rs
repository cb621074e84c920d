//! The smoothing neighbourhood as the kernels read it, and the one neighbour-average they share.

use rayon::prelude::*;

use crate::mesh::Topology;

/// Vertices per parallel task. Each task is a plain loop over a contiguous run of vertices
/// (rayon's per-item closures cost ~15% more); 1024 is large enough that scheduling (a few
/// microseconds per task) vanishes next to the work, small enough to balance two to sixteen
/// threads on meshes of ten thousand vertices and up.
pub(crate) const CHUNK: usize = 1024;

/// The smoothing neighbourhood (`Topology::smoothing_ring`) checked once against the vertex
/// count, so every kernel can slice rings and gather neighbours without further checks failing.
#[derive(Clone, Copy)]
pub(crate) struct Rings<'a> {
    offsets: &'a [u32],
    neighbors: &'a [u32],
}

impl<'a> Rings<'a> {
    /// `None` when the topology does not describe `vertex_count` vertices (built for another
    /// mesh): the CSR must have `vertex_count + 1` non-decreasing offsets ending at the list's
    /// length, and every neighbour must be a vertex.
    pub(crate) fn new(topology: &'a Topology, vertex_count: usize) -> Option<Self> {
        let (offsets, neighbors) = topology.smoothing_ring();
        let consistent = offsets.len() == vertex_count + 1
            && offsets.first() == Some(&0)
            && offsets.last().map(|&e| e as usize) == Some(neighbors.len())
            && non_decreasing(offsets)
            && neighbors_below(neighbors, vertex_count);
        consistent.then_some(Self { offsets, neighbors })
    }

    pub(crate) fn vertex_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The rings of the vertices of chunk `c` (`c * CHUNK ..`, at most `CHUNK` of them), in
    /// order. Walking the chunk's offsets pairwise saves the per-vertex offset checks.
    #[inline(always)]
    pub(crate) fn chunk(&self, c: usize) -> impl Iterator<Item = &'a [u32]> + 'a {
        let start = (c * CHUNK).min(self.vertex_count());
        let end = (start + CHUNK).min(self.vertex_count());
        let neighbors = self.neighbors;
        self.offsets[start..=end]
            .windows(2)
            .map(move |w| &neighbors[w[0] as usize..w[1] as usize])
    }
}

/// Entries checked per parallel task by the checks below: each task is a loop without an early
/// exit, which the compiler turns into vector instructions (the checks run once per smoothing
/// run, over every neighbour entry: a few percent of a short run when done one by one).
const CHECK_CHUNK: usize = 64 * 1024;

/// `offsets[k] <= offsets[k + 1]` for every `k`.
fn non_decreasing(offsets: &[u32]) -> bool {
    let Some(tail) = offsets.get(1..) else {
        return true;
    };
    offsets
        .par_chunks(CHECK_CHUNK)
        .zip(tail.par_chunks(CHECK_CHUNK))
        .all(|(a, b)| a.iter().zip(b).fold(true, |ok, (x, y)| ok & (x <= y)))
}

/// Every entry of `neighbors` is below `vertex_count`.
fn neighbors_below(neighbors: &[u32], vertex_count: usize) -> bool {
    neighbors.par_chunks(CHECK_CHUNK).all(|c| {
        let largest = c.iter().fold(0, |m, &j| m.max(j));
        (largest as usize) < vertex_count
    })
}

/// Mean of `q` over a non-empty ring. `q` must hold every vertex the ring names.
///
/// Neighbours go in pairs into two sums: half the loop branches (whose trip count varies with
/// the valence, so the exit is often mispredicted) and two independent add chains.
#[inline(always)]
pub(crate) fn ring_mean(ring: &[u32], q: &[[f32; 3]]) -> [f32; 3] {
    let mut even = [0.0f32; 3];
    let mut odd = [0.0f32; 3];
    let mut pairs = ring.chunks_exact(2);
    for pair in &mut pairs {
        let (a, b) = (q[pair[0] as usize], q[pair[1] as usize]);
        for k in 0..3 {
            even[k] += a[k];
            odd[k] += b[k];
        }
    }
    if let [j] = *pairs.remainder() {
        let a = q[j as usize];
        for k in 0..3 {
            even[k] += a[k];
        }
    }
    let inv = 1.0 / ring.len() as f32;
    std::array::from_fn(|k| (even[k] + odd[k]) * inv)
}
