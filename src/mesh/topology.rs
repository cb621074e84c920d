//! Vertex 1-rings and vertex->triangle incidence as flat CSR arrays.
//!
//! Built in linear time by counting sorts; every array is `u32` so the GPU engine uploads it as-is.
//! `offsets[i]..offsets[i + 1]` indexes vertex `i`'s entries (the paper's "lookup table").

use super::padded_ring::PaddedRing;
use super::topology_build;
use super::Mesh;
use rayon::prelude::*;

/// Connectivity of an indexed mesh.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Topology {
    /// CSR offsets into `neighbors`, one more than the vertex count.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub neighbor_offsets: Vec<u32>,
    /// 1-ring `N(i)`: the vertices sharing an edge with `i`, each once, ascending.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub neighbors: Vec<u32>,
    /// Parallel to `neighbors`: how many triangles use the edge `(i, neighbors[k])`.
    /// 1 = boundary edge, 2 = manifold interior edge, 3+ = non-manifold edge.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub edge_triangle_counts: Vec<u32>,
    /// CSR offsets into `vertex_triangles`, one more than the vertex count.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub triangle_offsets: Vec<u32>,
    /// Triangles incident to each vertex, ascending, each once.
    #[serde(with = "crate::mesh::flat_bytes")]
    pub vertex_triangles: Vec<u32>,
    /// True for vertices on a boundary edge (an edge used by exactly one triangle).
    pub is_boundary: Vec<bool>,
    /// The neighbourhood smoothing uses: the full 1-ring for interior vertices and only the
    /// boundary neighbours for boundary vertices (1-D smoothing along the boundary).
    /// `None` when the mesh has no boundary, in which case it equals the 1-ring.
    boundary_ring: Option<(Vec<u32>, Vec<u32>)>,
    /// The smoothing neighbourhood in fixed rows, as the CPU kernels read it.
    padded_ring: PaddedRing,
    /// The vertex count `padded_ring` describes ([`PaddedRing::describes`]), checked once:
    /// every smoothing run asks, and the web app's runs come in many short pieces. Not sent
    /// with the rest: a topology read from a message is checked anew, as the kernels' gathers
    /// rely on it.
    #[serde(skip)]
    padded_ring_for: DescribedCount,
}

/// The vertex count a padded ring describes, worked out when first asked. Derived from the
/// rings, so it plays no part in comparing topologies.
#[derive(Clone, Debug, Default)]
struct DescribedCount(std::sync::OnceLock<Option<usize>>);

impl PartialEq for DescribedCount {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Topology {
    /// Builds the CSR arrays for `mesh`. Triangles with repeated indices contribute only their
    /// distinct edges; indices must be in range (the parsers guarantee it).
    pub fn build(mesh: &Mesh) -> Self {
        topology_build::build(mesh)
    }

    /// The topology from its 1-rings and incidence; derives the boundary flags and the
    /// smoothing neighbourhood.
    pub(super) fn from_rings(
        (neighbor_offsets, neighbors, edge_triangle_counts): (Vec<u32>, Vec<u32>, Vec<u32>),
        triangle_offsets: Vec<u32>,
        vertex_triangles: Vec<u32>,
    ) -> Self {
        let n = neighbor_offsets.len().saturating_sub(1);
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
            let mut ring = Vec::with_capacity(neighbors.len());
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
        let padded_ring = match &boundary_ring {
            Some((offsets, ring)) => PaddedRing::new(offsets, ring),
            None => PaddedRing::new(&neighbor_offsets, &neighbors),
        };
        let padded_ring_for = DescribedCount(padded_ring.describes(n).then_some(n).into());

        Self {
            neighbor_offsets,
            neighbors,
            edge_triangle_counts,
            triangle_offsets,
            vertex_triangles,
            is_boundary,
            boundary_ring,
            padded_ring,
            padded_ring_for,
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

    /// [`Self::smoothing_ring`] in fixed rows of eight slots (see [`PaddedRing`]).
    pub fn padded_ring(&self) -> &PaddedRing {
        &self.padded_ring
    }

    /// Whether [`Self::padded_ring`] describes `vertex_count` vertices, so the kernels may
    /// gather with it from buffers of that many (see [`PaddedRing::describes`]).
    pub fn padded_ring_describes(&self, vertex_count: usize) -> bool {
        let rows = self.padded_ring.rows.len();
        let described = self
            .padded_ring_for
            .0
            .get_or_init(|| self.padded_ring.describes(rows).then_some(rows));
        *described == Some(vertex_count)
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
    fn a_topology_read_from_a_message_checks_its_padded_rows_anew() {
        let t = Topology::build(&square());
        assert!(t.padded_ring_describes(4));
        let wire = postcard::to_allocvec(&t).expect("serializes");
        let back: Topology = postcard::from_bytes(&wire).expect("reads back");
        assert_eq!(back, t);
        assert!(back.padded_ring_describes(4) && !back.padded_ring_describes(5));
        // A row whose pad names a vertex past the last: the kernels must not gather with it.
        let row: Vec<u8> = t.padded_ring().rows[1]
            .iter()
            .flat_map(|j| j.to_le_bytes())
            .collect();
        let at = wire
            .windows(row.len())
            .position(|w| w == row)
            .expect("the row's bytes");
        let mut lying = wire.clone();
        lying[at + row.len() - 4..at + row.len()].copy_from_slice(&99u32.to_le_bytes());
        let lying: Topology = postcard::from_bytes(&lying).expect("reads back");
        assert!(!lying.padded_ring_describes(4));
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
