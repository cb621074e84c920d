//! The validation report: what a mesh is made of and what is odd about it.
//!
//! Odd meshes (open, several components, non-manifold, degenerate faces) are reported, never refused.

use super::report_checks;
use super::{Mesh, Topology};
use serde::{Deserialize, Serialize};

/// Counts and flags that describe a mesh. Serialises to the `meshsmooth info --json` keys.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshReport {
    pub vertices: usize,
    pub faces: usize,
    /// Vertices no triangle uses (kept in the mesh, left out of Euler and components).
    pub unreferenced_vertices: usize,
    /// Faces with a repeated index or zero area.
    pub degenerate_faces: usize,
    /// Faces over the same three vertices as an earlier face (any order or winding).
    pub duplicate_faces: usize,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    /// Vertices whose incident triangles form more than one edge-connected fan.
    pub nonmanifold_vertices: usize,
    /// Edge-connected components of the referenced vertices.
    pub components: usize,
    /// V - E + F over the referenced vertices.
    pub euler: i64,
    /// Total genus `(2 * components - euler) / 2`, defined for closed manifold meshes only.
    pub genus: Option<i64>,
    /// No boundary edges (every edge is used by two or more triangles).
    pub closed: bool,
    /// Enclosed volume (divergence theorem), defined for closed meshes only.
    pub volume: Option<f64>,
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
}

impl MeshReport {
    /// The report of `mesh`; `topology` must be `Topology::build(mesh)`.
    pub fn new(mesh: &Mesh, topology: &Topology) -> Self {
        report_checks::check(mesh, topology)
    }

    /// Human-readable warnings for whatever is odd about the mesh (empty when nothing is).
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        let mut say = |count: usize, what: &str| {
            if count > 0 {
                w.push(format!("{count} {what}"));
            }
        };
        say(
            self.unreferenced_vertices,
            "unreferenced vertices (kept, not smoothed)",
        );
        say(self.degenerate_faces, "degenerate (zero-area) faces");
        say(self.duplicate_faces, "duplicate faces");
        say(
            self.boundary_edges,
            "boundary edges: the mesh is open, volume is undefined",
        );
        say(
            self.nonmanifold_edges,
            "non-manifold edges (used by 3+ faces)",
        );
        say(self.nonmanifold_vertices, "non-manifold vertices");
        if self.components > 1 {
            w.push(format!("{} connected components", self.components));
        }
        if let Some(v) = self.volume {
            if v < 0.0 {
                w.push("negative volume: faces are wound inside-out".to_string());
            }
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> MeshReport {
        let m = Mesh::new(positions, triangles);
        MeshReport::new(&m, &Topology::build(&m))
    }

    fn tetra() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let m = crate::mesh::fixtures::tetrahedron();
        (m.positions, m.triangles)
    }

    #[test]
    fn closed_tetrahedron() {
        let (p, t) = tetra();
        let r = report(p, t);
        assert_eq!((r.vertices, r.faces, r.euler, r.genus), (4, 4, 2, Some(0)));
        assert!(r.closed);
        assert_eq!(r.components, 1);
        assert!((r.volume.unwrap() - 1.0 / 6.0).abs() < 1e-12);
        assert!(r.warnings().is_empty());
    }

    #[test]
    fn open_mesh_has_no_volume_or_genus() {
        let (p, mut t) = tetra();
        t.pop();
        let r = report(p, t);
        assert!(!r.closed);
        assert_eq!(r.boundary_edges, 3);
        assert_eq!((r.volume, r.genus), (None, None));
        assert_eq!(r.euler, 1);
    }

    #[test]
    fn two_tetrahedra_touching_at_a_vertex() {
        let (mut p, mut t) = tetra();
        p.extend([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]);
        // A second tetrahedron sharing vertex 0 only: vertex 0 becomes non-manifold.
        t.extend([[0, 4, 5], [0, 6, 4], [0, 5, 6], [4, 6, 5]]);
        let r = report(p, t);
        assert_eq!(r.components, 1);
        assert_eq!(r.nonmanifold_vertices, 1);
        assert_eq!(r.nonmanifold_edges, 0);
        assert_eq!(r.genus, None);
        assert!(r.closed);
    }

    #[test]
    fn oddities_are_counted() {
        let (mut p, mut t) = tetra();
        p.push([9.0; 3]); // unreferenced
        t.push([2, 1, 0]); // duplicate of face 0 (reversed), also makes edges non-manifold
        t.push([0, 0, 1]); // degenerate
        let r = report(p, t);
        assert_eq!(r.unreferenced_vertices, 1);
        assert_eq!(r.duplicate_faces, 1);
        assert_eq!(r.degenerate_faces, 1);
        assert!(r.nonmanifold_edges >= 1);
        assert!(!r.warnings().is_empty());
    }
}
