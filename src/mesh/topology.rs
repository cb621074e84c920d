//! Vertex 1-rings and vertex->triangle incidence as flat CSR arrays.
//!
//! Built in linear time by counting sorts; every array is `u32` so the GPU engine uploads it as-is.
//! `offsets[i]..offsets[i + 1]` indexes vertex `i`'s entries (the paper's "lookup table").

use super::Mesh;
use rayon::prelude::*;

/// Connectivity of an indexed mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Topology {
    /// CSR offsets into `neighbors`, one more than the vertex count.
    pub neighbor_offsets: Vec<u32>,
    /// 1-ring `N(i)`: the vertices sharing an edge with `i`, each once, ascending.
    pub neighbors: Vec<u32>,
    /// Parallel to `neighbors`: how many triangles use the edge `(i, neighbors[k])`.
    /// 1 = boundary edge, 2 = manifold interior edge, 3+ = non-manifold edge.
    pub edge_triangle_counts: Vec<u32>,
    /// CSR offsets into `vertex_triangles`, one more than the vertex count.
    pub triangle_offsets: Vec<u32>,
    /// Triangles incident to each vertex, ascending, each once.
    pub vertex_triangles: Vec<u32>,
    /// True for vertices on a boundary edge (an edge used by exactly one triangle).
    pub is_boundary: Vec<bool>,
    /// The neighbourhood smoothing uses: the full 1-ring for interior vertices and only the
    /// boundary neighbours for boundary vertices (1-D smoothing along the boundary).
    /// `None` when the mesh has no boundary, in which case it equals the 1-ring.
    boundary_ring: Option<(Vec<u32>, Vec<u32>)>,
}

impl Topology {
    /// Builds the CSR arrays for `mesh`. Triangles with repeated indices contribute only their
    /// distinct edges; indices must be in range (the parsers guarantee it).
    pub fn build(mesh: &Mesh) -> Self {
        let n = mesh.positions.len();
        let tris = &mesh.triangles;
        debug_assert!(tris.iter().flatten().all(|&v| (v as usize) < n));

        // Vertex -> triangle incidence by counting sort (ascending triangle order for free).
        let mut triangle_offsets = vec![0u32; n + 1];
        for t in tris {
            for (k, &v) in t.iter().enumerate() {
                if !t[..k].contains(&v) {
                    triangle_offsets[v as usize + 1] += 1;
                }
            }
        }
        prefix_sum(&mut triangle_offsets);
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

        let (neighbor_offsets, neighbors, edge_triangle_counts) =
            build_rings(tris, &triangle_offsets, &vertex_triangles);
        let total = neighbors.len();

        let is_boundary: Vec<bool> = (0..n)
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                edge_triangle_counts[neighbor_offsets[i] as usize..neighbor_offsets[i + 1] as usize]
                    .contains(&1)
            })
            .collect();

        let boundary_ring = is_boundary.iter().any(|&b| b).then(|| {
            let mut offsets = vec![0u32; n + 1];
            let mut ring = Vec::with_capacity(total);
            for i in 0..n {
                let range = neighbor_offsets[i] as usize..neighbor_offsets[i + 1] as usize;
                if is_boundary[i] {
                    ring.extend(
                        range
                            .filter(|&k| edge_triangle_counts[k] == 1)
                            .map(|k| neighbors[k]),
                    );
                } else {
                    ring.extend_from_slice(&neighbors[range]);
                }
                offsets[i + 1] = ring.len() as u32;
            }
            (offsets, ring)
        });

        Self {
            neighbor_offsets,
            neighbors,
            edge_triangle_counts,
            triangle_offsets,
            vertex_triangles,
            is_boundary,
            boundary_ring,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.neighbor_offsets.len().saturating_sub(1)
    }

    /// The 1-ring `N(i)`.
    #[inline]
    pub fn neighbors_of(&self, i: usize) -> &[u32] {
        &self.neighbors[self.neighbor_offsets[i] as usize..self.neighbor_offsets[i + 1] as usize]
    }

    /// Triangles incident to vertex `i`.
    #[inline]
    pub fn triangles_of(&self, i: usize) -> &[u32] {
        &self.vertex_triangles
            [self.triangle_offsets[i] as usize..self.triangle_offsets[i + 1] as usize]
    }

    /// True when any vertex lies on a boundary edge.
    pub fn has_boundary(&self) -> bool {
        self.boundary_ring.is_some()
    }

    /// The smoothing neighbourhood as CSR `(offsets, neighbors)`: the 1-ring, except that boundary
    /// vertices see only their boundary neighbours.
    pub fn smoothing_ring(&self) -> (&[u32], &[u32]) {
        match &self.boundary_ring {
            Some((offsets, ring)) => (offsets, ring),
            None => (&self.neighbor_offsets, &self.neighbors),
        }
    }

    /// Number of distinct undirected edges.
    pub fn edge_count(&self) -> usize {
        self.neighbors.len() / 2
    }

    /// Every undirected edge once, as `[i, j]` with `i < j`, ascending by `i` then `j`: the
    /// line list the 3D view draws as a wireframe.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut edges = Vec::with_capacity(self.edge_count());
        for i in 0..self.vertex_count() {
            let i = i as u32;
            edges.extend(
                self.neighbors_of(i as usize)
                    .iter()
                    .filter(|&&j| i < j)
                    .map(|&j| [i, j]),
            );
        }
        edges
    }
}

/// Vertices per parallel work item when building the rings.
const BLOCK: usize = 2048;

/// The 1-ring CSR with edge multiplicities, without per-vertex allocations: every vertex's raw
/// list (two entries per incident triangle) is written into one flat buffer at twice its
/// triangle offset, sorted and deduplicated in place, then compacted.
fn build_rings(
    tris: &[[u32; 3]],
    triangle_offsets: &[u32],
    vertex_triangles: &[u32],
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let n = triangle_offsets.len() - 1;
    let raw_len = 2 * triangle_offsets[n] as usize;
    let mut raw = vec![0u32; raw_len];
    let mut counts = vec![0u32; raw_len];

    // Per block: its vertices, and the slices of `raw` and `counts` it owns.
    let mut jobs = Vec::with_capacity(n / BLOCK + 1);
    {
        let (mut raw_rest, mut counts_rest) = (&mut raw[..], &mut counts[..]);
        for start in (0..n).step_by(BLOCK) {
            let end = (start + BLOCK).min(n);
            let len = 2 * (triangle_offsets[end] - triangle_offsets[start]) as usize;
            let (r, rr) = std::mem::take(&mut raw_rest).split_at_mut(len);
            let (c, cr) = std::mem::take(&mut counts_rest).split_at_mut(len);
            (raw_rest, counts_rest) = (rr, cr);
            jobs.push((start, end, r, c));
        }
    }
    // Distinct neighbours per vertex, block by block.
    let unique: Vec<u32> = jobs
        .par_iter_mut()
        .flat_map_iter(|(start, end, r, c)| {
            let mut u = Vec::with_capacity(*end - *start);
            let base = 2 * triangle_offsets[*start] as usize;
            for i in *start..*end {
                let lo = 2 * triangle_offsets[i] as usize - base;
                let hi = 2 * triangle_offsets[i + 1] as usize - base;
                let slot = &mut r[lo..hi];
                let mut len = 0;
                for &ti in &vertex_triangles
                    [triangle_offsets[i] as usize..triangle_offsets[i + 1] as usize]
                {
                    for &v in &tris[ti as usize] {
                        if v as usize != i {
                            slot[len] = v;
                            len += 1;
                        }
                    }
                }
                let slot = &mut slot[..len];
                slot.sort_unstable();
                let cnt = &mut c[lo..hi];
                let mut k = 0;
                for j in 0..len {
                    if k > 0 && slot[k - 1] == slot[j] {
                        cnt[k - 1] += 1;
                    } else {
                        slot[k] = slot[j];
                        cnt[k] = 1;
                        k += 1;
                    }
                }
                u.push(k as u32);
            }
            u
        })
        .collect();

    let mut offsets = vec![0u32; n + 1];
    for i in 0..n {
        offsets[i + 1] = offsets[i] + unique[i];
    }
    let total = offsets[n] as usize;
    let mut neighbors = vec![0u32; total];
    let mut edge_counts = vec![0u32; total];
    {
        let (mut nb_rest, mut ec_rest) = (&mut neighbors[..], &mut edge_counts[..]);
        let mut out = Vec::with_capacity(jobs.len());
        for (start, end, r, c) in jobs {
            let len = (offsets[end] - offsets[start]) as usize;
            let (nb, nr) = std::mem::take(&mut nb_rest).split_at_mut(len);
            let (ec, er) = std::mem::take(&mut ec_rest).split_at_mut(len);
            (nb_rest, ec_rest) = (nr, er);
            out.push((start, end, r, c, nb, ec));
        }
        out.into_par_iter().for_each(|(start, end, r, c, nb, ec)| {
            let base_raw = 2 * triangle_offsets[start] as usize;
            let base_out = offsets[start] as usize;
            for i in start..end {
                let src = 2 * triangle_offsets[i] as usize - base_raw;
                let dst = offsets[i] as usize - base_out;
                let k = unique[i] as usize;
                nb[dst..dst + k].copy_from_slice(&r[src..src + k]);
                ec[dst..dst + k].copy_from_slice(&c[src..src + k]);
            }
        });
    }
    (offsets, neighbors, edge_counts)
}

fn prefix_sum(offsets: &mut [u32]) {
    for i in 1..offsets.len() {
        offsets[i] += offsets[i - 1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Mesh {
        // Two triangles sharing the diagonal 0-2: an open quad.
        Mesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn quad_rings_and_edge_counts() {
        let t = Topology::build(&square());
        assert_eq!(t.neighbors_of(0), &[1, 2, 3]);
        assert_eq!(t.neighbors_of(1), &[0, 2]);
        assert_eq!(t.triangles_of(0), &[0, 1]);
        assert_eq!(t.triangles_of(3), &[1]);
        assert_eq!(t.edge_count(), 5);
        // The diagonal 0-2 is shared by both triangles; all others are boundary edges.
        let k = t.neighbor_offsets[0] as usize + 1;
        assert_eq!(t.neighbors[k], 2);
        assert_eq!(t.edge_triangle_counts[k], 2);
        assert!(t.is_boundary.iter().all(|&b| b));
        // Boundary vertices smooth along the boundary only: 0 drops the diagonal to 2.
        let (off, ring) = t.smoothing_ring();
        assert_eq!(&ring[off[0] as usize..off[1] as usize], &[1, 3]);
    }

    #[test]
    fn closed_mesh_has_no_boundary_and_shares_the_ring() {
        let m = crate::mesh::fixtures::tetrahedron();
        let t = Topology::build(&m);
        assert!(!t.has_boundary());
        assert!(t.edge_triangle_counts.iter().all(|&c| c == 2));
        assert_eq!(t.smoothing_ring().1, &t.neighbors[..]);
        assert_eq!(t.edge_count(), 6);
    }

    #[test]
    fn edges_lists_each_undirected_edge_once() {
        let t = Topology::build(&square());
        assert_eq!(t.edges(), vec![[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]);
        let m = crate::mesh::fixtures::tetrahedron();
        let edges = Topology::build(&m).edges();
        assert_eq!(edges.len(), 6);
        assert!(edges.iter().all(|[i, j]| i < j));
        assert!(Topology::build(&Mesh::default()).edges().is_empty());
    }

    #[test]
    fn unreferenced_and_degenerate_index_triangles() {
        let m = Mesh::new(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0; 3]],
            vec![[0, 1, 2], [0, 0, 1]],
        );
        let t = Topology::build(&m);
        assert!(t.neighbors_of(3).is_empty());
        assert!(t.triangles_of(3).is_empty());
        assert_eq!(t.triangles_of(0), &[0, 1]);
        // Edge 0-1 is used by both triangles (the second is degenerate but still names it).
        assert_eq!(t.neighbors_of(0), &[1, 2]);
    }
}
