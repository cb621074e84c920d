//! The smoothing neighbourhood as the kernels read it, and the one neighbour-average they share.

use rayon::prelude::*;

use crate::mesh::{PaddedRing, Topology, PADDED_WIDTH};

/// Vertices per parallel task. Each task is a plain loop over a contiguous run of vertices
/// (rayon's per-item closures cost ~15% more); 1024 is large enough that scheduling (a few
/// microseconds per task) vanishes next to the work, small enough to balance two to sixteen
/// threads on meshes of ten thousand vertices and up.
pub(crate) const CHUNK: usize = 1024;

/// The smoothing neighbourhood as the kernels read it (`Topology::padded_ring`), checked once
/// against the vertex count, so the kernels gather neighbours without a check per slot: eight
/// checks a row kept all eight indices live at once, and WebAssembly's compilers spilled them.
#[derive(Clone, Copy)]
pub(crate) struct KernelRings<'a> {
    padded: &'a PaddedRing,
    vertex_count: usize,
}

impl<'a> KernelRings<'a> {
    /// `None` when the topology does not describe `vertex_count` vertices (built for another
    /// mesh; see [`PaddedRing::describes`], checked when the topology was built).
    pub(crate) fn new(topology: &'a Topology, vertex_count: usize) -> Option<Self> {
        let padded = topology.padded_ring();
        topology
            .padded_ring_describes(vertex_count)
            .then_some(Self {
                padded,
                vertex_count,
            })
    }

    pub(crate) fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// How far a ring reaches in vertex order ([`PaddedRing::span`]).
    pub(crate) fn span(&self) -> u32 {
        self.padded.span
    }

    /// The rings of the vertices of chunk `c` (`c * CHUNK ..`, at most `CHUNK` of them), in
    /// order, each over `field`, the values its mean reads.
    ///
    /// # Panics
    /// If `field` is not a field of this many vertices.
    #[inline(always)]
    pub(crate) fn chunk(&self, c: usize, field: &'a Field) -> impl Iterator<Item = Ring<'a>> + 'a {
        // What makes the gathers of `mean` safe: every slot of a row that fits names at most
        // the vertex count (`new`), and `field` holds that many entries and one more.
        assert_eq!(field.0.len(), self.vertex_count + 1, "a field of this mesh");
        let field = &field.0[..];
        let start = (c * CHUNK).min(self.vertex_count());
        let end = (start + CHUNK).min(self.vertex_count());
        self.padded.rows[start..end]
            .iter()
            .zip(&self.padded.inverse_sizes[start..end])
            .map(move |(row, &inverse_size)| Ring {
                row,
                inverse_size,
                field,
            })
    }

    /// Mean of the ring's field over `ring` (which must not be empty).
    ///
    /// A row's slots go into four sums of two: a fixed loop without branches, four independent
    /// add chains, and a vertex's four lanes in one vector register.
    #[inline(always)]
    pub(crate) fn mean(&self, ring: Ring) -> [f32; 4] {
        let q = ring.field;
        if !PaddedRing::fits(ring.inverse_size) {
            return self.large_mean(ring.row, q);
        }
        let r = ring.row;
        // SAFETY: `ring` comes from `chunk`, whose rows fit only where every slot is at most
        // the vertex count they were checked against, and whose field has one entry more.
        let at = |slot: usize| unsafe { *q.get_unchecked(r[slot] as usize) };
        let mut sums = [[0.0f32; 4]; 4];
        for (h, sum) in sums.iter_mut().enumerate() {
            let (a, b) = (at(2 * h), at(2 * h + 1));
            for k in 0..4 {
                sum[k] = a[k] + b[k];
            }
        }
        let s = ring.inverse_size;
        std::array::from_fn(|k| ((sums[0][k] + sums[1][k]) + (sums[2][k] + sums[3][k])) * s)
    }

    /// The mean over a ring larger than a row, from the list of large rings: neighbours go in
    /// pairs into two sums (half the loop branches, two independent add chains).
    #[inline(never)]
    fn large_mean(&self, row: &[u32; PADDED_WIDTH], q: &[[f32; 4]]) -> [f32; 4] {
        let ring = self.padded.large_ring(row);
        let mut even = [0.0f32; 4];
        let mut odd = [0.0f32; 4];
        let mut pairs = ring.chunks_exact(2);
        for pair in &mut pairs {
            let (a, b) = (q[pair[0] as usize], q[pair[1] as usize]);
            for k in 0..4 {
                even[k] += a[k];
                odd[k] += b[k];
            }
        }
        if let [j] = *pairs.remainder() {
            let a = q[j as usize];
            for k in 0..4 {
                even[k] += a[k];
            }
        }
        let inv = 1.0 / ring.len().max(1) as f32;
        std::array::from_fn(|k| (even[k] + odd[k]) * inv)
    }
}

/// One vertex's smoothing ring, over the field its mean reads (made only by
/// [`KernelRings::chunk`]).
#[derive(Clone, Copy)]
pub(crate) struct Ring<'a> {
    row: &'a [u32; PADDED_WIDTH],
    inverse_size: f32,
    field: &'a [[f32; 4]],
}

impl Ring<'_> {
    /// An isolated vertex: no neighbours to average.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.inverse_size == 0.0
    }
}

/// Per-vertex 3-vectors as the kernels gather them: four lanes per vertex (the fourth 0, so a
/// vertex is one aligned 16-byte load and its sums one vector add) and, after the last vertex,
/// the zero entry that padded ring slots name. Only the vertices' entries can be changed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Field(Vec<[f32; 4]>);

impl Field {
    /// Zeros for `n` vertices.
    pub(crate) fn zeros(n: usize) -> Self {
        Self(vec![[0.0; 4]; n + 1])
    }

    /// `points`, one per vertex.
    pub(crate) fn from_points(points: &[[f32; 3]]) -> Self {
        Self::from_points_about(points, [0.0; 3])
    }

    /// `points - origin`, one per vertex (subtracting a zero origin changes no point).
    pub(crate) fn from_points_about(points: &[[f32; 3]], origin: [f32; 3]) -> Self {
        let mut field = Self::zeros(points.len());
        field
            .vertices_mut()
            .par_chunks_mut(CHUNK)
            .zip(points.par_chunks(CHUNK))
            .for_each(|(out, points)| {
                for (o, p) in out.iter_mut().zip(points) {
                    *o = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2], 0.0];
                }
            });
        field
    }

    /// The vertices' entries.
    pub(crate) fn vertices(&self) -> &[[f32; 4]] {
        &self.0[..self.0.len() - 1]
    }

    pub(crate) fn vertices_mut(&mut self) -> &mut [[f32; 4]] {
        let n = self.0.len() - 1;
        &mut self.0[..n]
    }

    /// The vertices' entries as 3-vectors, written into `out` (resized to fit).
    pub(crate) fn write_points(&self, out: &mut Vec<[f32; 3]>) {
        out.resize(self.0.len() - 1, [0.0; 3]);
        out.par_chunks_mut(CHUNK)
            .zip(self.vertices().par_chunks(CHUNK))
            .for_each(|(out, field)| {
                for (o, f) in out.iter_mut().zip(field) {
                    *o = [f[0], f[1], f[2]];
                }
            });
    }
}

/// A run's buffers, kept between the calls of a run spread over several: the positions `q`,
/// and the second positions buffer and the HC differences, made when first needed.
pub(crate) struct Fields {
    pub(crate) q: Field,
    next: Option<Field>,
    differences: Vec<Field>,
}

impl Fields {
    /// `points`, one per vertex, as the positions; nothing else made yet.
    pub(crate) fn from_points(points: &[[f32; 3]]) -> Self {
        Self {
            q: Field::from_points(points),
            next: None,
            differences: Vec::new(),
        }
    }

    /// The positions, the second buffer and `count` difference buffers (zeros when made).
    pub(crate) fn with_scratch(&mut self, count: usize) -> (&mut Field, &mut Field, &mut [Field]) {
        let n = self.q.vertices().len();
        if self.differences.len() != count {
            self.differences = (0..count).map(|_| Field::zeros(n)).collect();
        }
        let next = self.next.get_or_insert_with(|| Field::zeros(n));
        (&mut self.q, next, &mut self.differences)
    }
}

/// The first three lanes.
#[inline(always)]
pub(crate) fn xyz(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

/// `v` with a zero fourth lane.
#[inline(always)]
pub(crate) fn xyz0(v: [f32; 3]) -> [f32; 4] {
    [v[0], v[1], v[2], 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::double_cone;

    #[test]
    fn means_over_rows_and_larger_rings_equal_the_plain_mean() {
        for k in [3, 8, 9, 12] {
            let mesh = double_cone(k);
            let topology = Topology::build(&mesh);
            let n = mesh.vertex_count();
            let rings = KernelRings::new(&topology, n).expect("built for this mesh");
            let q = Field::from_points(&mesh.positions);
            let means: Vec<Option<[f32; 4]>> = (0..n.div_ceil(CHUNK))
                .flat_map(|c| rings.chunk(c, &q).collect::<Vec<_>>())
                .map(|ring| (!ring.is_empty()).then(|| rings.mean(ring)))
                .collect();
            assert_eq!(means.len(), n);
            for (i, m) in means.iter().enumerate() {
                let ring = topology.neighbors_of(i);
                let Some(m) = m else {
                    assert!(ring.is_empty(), "vertex {i} of cone {k}");
                    continue;
                };
                for (d, &got) in m[..3].iter().enumerate() {
                    let plain = ring
                        .iter()
                        .map(|&j| mesh.positions[j as usize][d])
                        .sum::<f32>()
                        / ring.len() as f32;
                    assert!((got - plain).abs() < 1e-6, "vertex {i} of cone {k}");
                }
                assert_eq!(m[3], 0.0);
            }
            assert!(means[n - 1].is_none(), "the isolated vertex");
        }
    }

    #[test]
    #[should_panic(expected = "a field of this mesh")]
    fn rings_refuse_a_field_of_another_size() {
        let mesh = double_cone(5);
        let topology = Topology::build(&mesh);
        let n = mesh.vertex_count();
        let rings = KernelRings::new(&topology, n).expect("built for this mesh");
        // Its zero entry would be read as a vertex, and a pad slot past its end.
        let short = Field::zeros(n - 1);
        let _ = rings.chunk(0, &short).count();
    }

    #[test]
    fn a_field_keeps_its_zero_entry_and_gives_back_its_points() {
        let points = vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        let mut f = Field::from_points(&points);
        f.vertices_mut().iter_mut().for_each(|v| v[0] += 1.0);
        assert_eq!(f.0[2], [0.0; 4]);
        let mut back = Vec::new();
        f.write_points(&mut back);
        assert_eq!(back, vec![[2.0, 2.0, 3.0], [5.0, 5.0, 6.0]]);
    }
}
