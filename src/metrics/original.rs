//! The original mesh M as the measures see it: built once per loaded mesh, so every measure pass
//! over a smoothed mesh only reads what stays fixed.

use super::curvature::{fan_corners, CornerCode};
use super::prism_rows::PrismRows;
use super::stand_in::StandIn;
use crate::mesh::{Mesh, Topology};

/// The original mesh with what the measures precompute from it: the triangle fans in the order
/// the passes read them, the drift's shortcut radius, the volume V0 (closed meshes only), the
/// curvature K0 and the roughness R0.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Original {
    mesh: Mesh,
    topology: Topology,
    /// Other two corners of each vertex->triangle incidence (parallel to `vertex_triangles`).
    #[serde(with = "crate::mesh::flat_bytes")]
    fan_corners: Vec<[u32; 2]>,
    /// Each vertex->triangle incidence as the triangle's corner (parallel to
    /// `vertex_triangles`).
    #[serde(with = "crate::mesh::flat_bytes")]
    corner_codes: Vec<CornerCode>,
    /// Each vertex's fan as one row of its rim, where it fits (the local error's fast path).
    prism_rows: PrismRows,
    /// Per vertex, the square of 0.49 times its shortest edge: a point that near the vertex is
    /// nearer to it than to any neighbour (each is at least 0.51 edge away), so the drift can
    /// skip the ring. The margin keeps the shortcut exact in f32.
    #[serde(with = "crate::mesh::flat_bytes")]
    stay_radius2: Vec<f32>,
    volume: Option<f64>,
    curvature: f64,
    /// R0, the original's roughness (see [`super::roughness()`]).
    roughness: f64,
    /// Vertices some triangle uses: the ones the local error averages over.
    referenced: usize,
    /// What it measures with where it stands in for a larger surface ([`Self::standing_in`]).
    #[serde(default)]
    stand_in: Option<StandIn>,
}

impl Original {
    /// Precomputes the original's measures. `topology` must be `Topology::build(mesh)`.
    pub fn new(mesh: &Mesh, topology: &Topology) -> Self {
        Self::build(mesh, topology, None)
    }

    /// [`Self::new`], or with `stand_in` and the whole's volume, an original standing in for
    /// a larger surface.
    pub(super) fn build(
        mesh: &Mesh,
        topology: &Topology,
        stand_in: Option<(StandIn, f64)>,
    ) -> Self {
        let mut o = Self::bare(mesh.clone(), topology.clone());
        (o.fan_corners, o.corner_codes) = fan_corners(&o.mesh.triangles, &o.topology);
        o.prism_rows = PrismRows::new(o.mesh.vertex_count(), |r| o.fan_corners(r));
        o.stay_radius2 = stay_radius2(&o.mesh.positions, &o.topology);
        o.roughness = super::roughness(&o, &o.mesh.positions);
        let volume0 = stand_in.as_ref().map(|(_, v)| *v);
        o.stand_in = stand_in.map(|(s, _)| s);
        // The volume and curvature need no reference: the local error of the original is 0.
        let sums = super::report::measure_pass(&o, &o.mesh.positions, None);
        o.volume = volume0.or_else(|| o.is_closed().then(|| sums.volume()));
        o.curvature = sums.curvature();
        o
    }

    /// The original with nothing precomputed yet.
    fn bare(mesh: Mesh, topology: Topology) -> Self {
        assert_eq!(
            topology.vertex_count(),
            mesh.vertex_count(),
            "topology must be built from this mesh"
        );
        let referenced = (0..mesh.vertex_count())
            .filter(|&i| !topology.triangles_of(i).is_empty())
            .count();
        Self {
            fan_corners: Vec::new(),
            corner_codes: Vec::new(),
            prism_rows: PrismRows::default(),
            stay_radius2: Vec::new(),
            mesh,
            topology,
            volume: None,
            curvature: 0.0,
            roughness: 0.0,
            referenced,
            stand_in: None,
        }
    }

    /// V0, by the divergence theorem; `None` for an open mesh (or one without triangles), where
    /// an enclosed volume means nothing. Patches standing in for a closed surface (open
    /// themselves) give the whole surface's.
    pub fn volume(&self) -> Option<f64> {
        self.volume
    }

    /// K0: mean `|K_G|` over the interior vertices with a defined curvature.
    pub fn curvature(&self) -> f64 {
        self.curvature
    }

    /// R0: the original's roughness (see [`super::roughness()`]).
    pub fn roughness(&self) -> f64 {
        self.roughness
    }

    /// `R / R0` of smoothed `positions`: above 1, the smoothing left the mesh rougher than it
    /// was (see [`super::roughness_ratio`]).
    pub fn roughness_ratio(&self, positions: &[[f32; 3]]) -> f64 {
        super::roughness_ratio(super::roughness(self, positions), self.roughness)
    }

    /// No boundary edges and at least one triangle.
    pub fn is_closed(&self) -> bool {
        !self.topology.has_boundary() && !self.mesh.triangles.is_empty()
    }

    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// The other two corners of each triangle around vertex `i`, in winding order.
    #[inline]
    pub(crate) fn fan_corners(&self, i: usize) -> &[[u32; 2]] {
        let o = &self.topology.triangle_offsets;
        &self.fan_corners[o[i] as usize..o[i + 1] as usize]
    }

    /// The corners vertex `i` takes in its triangles.
    #[inline]
    pub(crate) fn corner_codes(&self, i: usize) -> &[CornerCode] {
        let o = &self.topology.triangle_offsets;
        &self.corner_codes[o[i] as usize..o[i + 1] as usize]
    }

    /// The rim row of vertex `i`'s fan, where it has one.
    #[inline(always)]
    pub(crate) fn prism_row(&self, i: usize) -> Option<&[u32; super::prism_rows::ROW]> {
        self.prism_rows.row(i)
    }

    /// [`Self::fan_corners`] of every vertex, in vertex order (parallel to the topology's
    /// `vertex_triangles`): what the GPU engine uploads.
    #[cfg(feature = "gpu")]
    pub(crate) fn all_fan_corners(&self) -> &[[u32; 2]] {
        &self.fan_corners
    }

    pub(crate) fn stay_radius2(&self) -> &[f32] {
        &self.stay_radius2
    }

    /// What it measures with where it stands in for a larger surface.
    pub(crate) fn stand_in(&self) -> Option<&StandIn> {
        self.stand_in.as_ref()
    }

    /// Whether it stands in for a larger surface ([`Self::standing_in`]).
    pub fn is_standing_in(&self) -> bool {
        self.stand_in.is_some()
    }

    /// Number of vertices some triangle uses.
    pub fn referenced_vertices(&self) -> usize {
        self.referenced
    }
}

fn stay_radius2(positions: &[[f32; 3]], topology: &Topology) -> Vec<f32> {
    use rayon::prelude::*;
    (0..positions.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| {
            let p = positions[i];
            let shortest2 = topology
                .neighbors_of(i)
                .iter()
                .map(|&j| {
                    let q = positions[j as usize];
                    (0..3).map(|k| (q[k] - p[k]) * (q[k] - p[k])).sum::<f32>()
                })
                .fold(f32::INFINITY, f32::min);
            if shortest2.is_finite() {
                0.49 * 0.49 * shortest2
            } else {
                0.0
            }
        })
        .collect()
}
