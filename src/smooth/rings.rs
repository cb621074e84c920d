//! The smoothing neighbourhood as the kernels read it, and the one neighbour-average they share.

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
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets.last().map(|&e| e as usize) == Some(neighbors.len())
            && neighbors.iter().all(|&j| (j as usize) < vertex_count);
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
