//! The indexed triangle mesh and everything derived from its connectivity.
//!
//! A mesh is two flat arrays (positions, triangles) so it can be uploaded to a GPU as-is;
//! topology (`Topology`) and the validation report (`MeshReport`) are built on demand.

pub(crate) mod flat_bytes;
mod normals;
mod padded_ring;
mod report;
mod report_checks;
mod topology;
mod topology_build;

pub use normals::vertex_normals;
pub use padded_ring::{PaddedRing, PADDED_WIDTH};
pub use report::MeshReport;
pub use topology::Topology;
pub(crate) use topology_build::by_blocks;

/// "No such index" in flat `u32` arrays.
pub const NONE: u32 = u32::MAX;

/// Indexed triangle mesh: positions in the file's units (mm for medical meshes) and
/// counter-clockwise triangles (seen from outside).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mesh {
    #[serde(with = "flat_bytes")]
    pub positions: Vec<[f32; 3]>,
    #[serde(with = "flat_bytes")]
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn new(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            triangles,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounding box `(min, max)` of all positions; `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<([f32; 3], [f32; 3])> {
        bounding_box(&self.positions)
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh).
    pub fn bounding_box_diagonal(&self) -> f64 {
        self.bounding_box().map_or(0.0, |(lo, hi)| {
            let d: f64 = (0..3).map(|k| (hi[k] as f64 - lo[k] as f64).powi(2)).sum();
            d.sqrt()
        })
    }

    /// Signed volume by the divergence theorem, `V = 1/6 sum_t p_a . (p_b x p_c)`, in f64.
    /// Meaningful only for a closed, consistently wound mesh (the report says whether it is).
    pub fn signed_volume(&self) -> f64 {
        signed_volume(&self.positions, &self.triangles)
    }

    /// The part of the surface around `vertices`: every triangle with one of them as a
    /// corner, over only the vertices those use. Indices out of range are ignored.
    pub fn patch(&self, vertices: &[u32]) -> Mesh {
        let mut marked = vec![false; self.positions.len()];
        for &v in vertices {
            if let Some(m) = marked.get_mut(v as usize) {
                *m = true;
            }
        }
        self.part(|t| t.iter().any(|&v| marked[v as usize])).0
    }

    /// The triangles `keep` keeps, over only the vertices those use, and the index in this
    /// mesh of each of the part's vertices.
    pub fn part(&self, keep: impl Fn(&[u32; 3]) -> bool) -> (Mesh, Vec<u32>) {
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut kept: Vec<u32> = Vec::new();
        let triangles = (self.triangles.iter().filter(|t| keep(t)))
            .map(|t| {
                t.map(|v| {
                    let slot = &mut new_index[v as usize];
                    if *slot == u32::MAX {
                        *slot = kept.len() as u32;
                        kept.push(v);
                    }
                    *slot
                })
            })
            .collect();
        let positions = kept.iter().map(|&v| self.positions[v as usize]).collect();
        (Mesh::new(positions, triangles), kept)
    }
}

/// Axis-aligned bounding box of a point set.
pub fn bounding_box(positions: &[[f32; 3]]) -> Option<([f32; 3], [f32; 3])> {
    let first = *positions.first()?;
    Some(
        positions
            .iter()
            .fold((first, first), |(mut lo, mut hi), p| {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
                (lo, hi)
            }),
    )
}

/// Signed volume of a triangle set over the given positions (divergence theorem, f64 sums).
pub fn signed_volume(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> f64 {
    use rayon::prelude::*;
    triangles
        .par_chunks(4096)
        .map(|chunk| {
            chunk
                .iter()
                .map(|t| {
                    let a = to_f64(positions[t[0] as usize]);
                    let b = to_f64(positions[t[1] as usize]);
                    let c = to_f64(positions[t[2] as usize]);
                    dot(a, cross(b, c))
                })
                .sum::<f64>()
        })
        .sum::<f64>()
        / 6.0
}

#[inline]
pub(crate) fn to_f64(p: [f32; 3]) -> [f64; 3] {
    [p[0] as f64, p[1] as f64, p[2] as f64]
}

#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// [`sub`] in f32, for the measure pass's vector kernels.
#[inline(always)]
pub(crate) fn sub32(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// [`cross`] in f32.
#[inline(always)]
pub(crate) fn cross32(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// [`dot`] in f32.
#[inline(always)]
pub(crate) fn dot32(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Meshes the unit tests of several modules share.
#[cfg(test)]
pub(crate) mod fixtures {
    use super::Mesh;

    /// Unit right tetrahedron, outward winding: closed, genus 0, volume 1/6.
    pub(crate) fn tetrahedron() -> Mesh {
        Mesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    /// An open, wavy height field of `cols` by `rows` quads, each split into two triangles
    /// along alternating diagonals.
    pub(crate) fn grid(cols: u32, rows: u32) -> Mesh {
        let mut positions = Vec::new();
        for y in 0..=rows {
            for x in 0..=cols {
                let h = ((x as f32) * 0.7).sin() * ((y as f32) * 0.4).cos();
                positions.push([x as f32, y as f32, h]);
            }
        }
        let at = |x: u32, y: u32| y * (cols + 1) + x;
        let mut triangles = Vec::new();
        for y in 0..rows {
            for x in 0..cols {
                let (a, b, c, d) = (at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1));
                if (x + y) % 2 == 0 {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        Mesh::new(positions, triangles)
    }

    /// A closed double cone: two apexes with `k` neighbours each around a wavy rim of `k`
    /// vertices (valence 4 each), and an isolated vertex.
    pub(crate) fn double_cone(k: u32) -> Mesh {
        let mut positions = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.3]];
        for j in 0..k {
            let a = j as f32 * std::f32::consts::TAU / k as f32;
            positions.push([a.cos(), a.sin(), 0.1 * (j % 3) as f32]);
        }
        positions.push([5.0, 5.0, 5.0]);
        let rim = |j: u32| 2 + j % k;
        let triangles = (0..k)
            .flat_map(|j| [[0, rim(j), rim(j + 1)], [1, rim(j + 1), rim(j)]])
            .collect();
        Mesh::new(positions, triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::tetrahedron;
    use super::*;

    #[test]
    fn tetrahedron_volume_is_one_sixth() {
        assert!((tetrahedron().signed_volume() - 1.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn bounding_box_of_tetrahedron() {
        let m = tetrahedron();
        assert_eq!(m.bounding_box(), Some(([0.0; 3], [1.0; 3])));
        assert!((m.bounding_box_diagonal() - 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(Mesh::default().bounding_box(), None);
    }

    #[test]
    fn a_patch_holds_the_triangles_around_its_vertices() {
        let m = tetrahedron();
        // Vertex 0 is a corner of three of the four triangles; those use all four vertices.
        let around_0 = m.patch(&[0]);
        let at_0 = m.triangles.iter().filter(|t| t.contains(&0)).count();
        assert_eq!(around_0.triangle_count(), at_0);
        assert_eq!(around_0.vertex_count(), 4);
        assert!(
            (around_0.signed_volume() - m.signed_volume()).abs() > 1e-3,
            "one face left out"
        );
        // The same corners in the same places, reindexed.
        for (t, old) in around_0
            .triangles
            .iter()
            .zip(m.triangles.iter().filter(|t| t.contains(&0)))
        {
            for k in 0..3 {
                assert_eq!(
                    around_0.positions[t[k] as usize],
                    m.positions[old[k] as usize]
                );
            }
        }
        assert_eq!(m.patch(&[]), Mesh::default());
        assert_eq!(m.patch(&[99]), Mesh::default());
        assert_eq!(m.patch(&[0, 1, 2, 3]).signed_volume(), m.signed_volume());
    }
}
