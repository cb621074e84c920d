//! The original mesh M as the measures see it: built once per loaded mesh, so every measure pass
//! over a smoothed mesh only reads what stays fixed.

use super::curvature::fan_corners;
use super::report::{measure_pass, Sums};
use crate::mesh::{Mesh, Topology};

/// The original mesh with what the measures precompute from it: its volume V0 (closed meshes
/// only) and its curvature K0.
#[derive(Clone, Debug)]
pub struct Original {
    mesh: Mesh,
    topology: Topology,
    /// Other two corners of each vertex->triangle incidence (parallel to `vertex_triangles`).
    fan_corners: Vec<[u32; 2]>,
    volume: Option<f64>,
    curvature: f64,
    /// Vertices some triangle uses: the ones the local error averages over.
    referenced: usize,
}

impl Original {
    /// Precomputes the original's measures. `topology` must be `Topology::build(mesh)`.
    pub fn new(mesh: &Mesh, topology: &Topology) -> Self {
        assert_eq!(
            topology.vertex_count(),
            mesh.vertex_count(),
            "topology must be built from this mesh"
        );
        let referenced = (0..mesh.vertex_count())
            .filter(|&i| !topology.triangles_of(i).is_empty())
            .count();
        let mut original = Self {
            mesh: mesh.clone(),
            topology: topology.clone(),
            fan_corners: fan_corners(&mesh.triangles, topology),
            volume: None,
            curvature: 0.0,
            referenced,
        };
        let sums: Sums = measure_pass(&original, &mesh.positions, None, None);
        original.volume = original.is_closed().then(|| sums.volume());
        original.curvature = sums.curvature();
        original
    }

    /// V0, by the divergence theorem; `None` for an open mesh (or one without triangles), where
    /// an enclosed volume means nothing.
    pub fn volume(&self) -> Option<f64> {
        self.volume
    }

    /// K0: mean `|K_G|` over the interior vertices with a defined curvature.
    pub fn curvature(&self) -> f64 {
        self.curvature
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

    /// Number of vertices some triangle uses.
    pub fn referenced_vertices(&self) -> usize {
        self.referenced
    }
}
