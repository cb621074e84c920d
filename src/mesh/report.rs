//! The validation report: what a mesh is made of and what is odd about it.
//!
//! Odd meshes (open, several components, non-manifold, degenerate faces) are reported, never refused.

use super::{cross, sub, to_f64, Mesh, Topology};
use rayon::prelude::*;
use serde::Serialize;

/// Counts and flags that describe a mesh. Serialises to the `meshsmooth info --json` keys.
#[derive(Clone, Debug, PartialEq, Serialize)]
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
    pub fn new(mesh: &Mesh, topology: &Topology) -> Self {
        let n = mesh.vertex_count();
        let referenced = (0..n)
            .filter(|&i| topology.triangle_offsets[i] != topology.triangle_offsets[i + 1])
            .count();
        let boundary_edges = topology
            .edge_triangle_counts
            .iter()
            .filter(|&&c| c == 1)
            .count()
            / 2;
        let nonmanifold_edges = topology
            .edge_triangle_counts
            .iter()
            .filter(|&&c| c >= 3)
            .count()
            / 2;
        let nonmanifold_vertices = (0..n)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&i| fan_count(mesh, topology, i) > 1)
            .count();
        let components = component_count(mesh, topology);
        let euler = referenced as i64 - topology.edge_count() as i64 + mesh.triangle_count() as i64;
        let closed = boundary_edges == 0 && mesh.triangle_count() > 0;
        let manifold = nonmanifold_edges == 0 && nonmanifold_vertices == 0;
        let genus = (closed && manifold && (2 * components as i64 - euler) % 2 == 0)
            .then(|| (2 * components as i64 - euler) / 2);
        let (bbox_min, bbox_max) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
        Self {
            vertices: n,
            faces: mesh.triangle_count(),
            unreferenced_vertices: n - referenced,
            degenerate_faces: degenerate_count(mesh),
            duplicate_faces: duplicate_count(mesh),
            boundary_edges,
            nonmanifold_edges,
            nonmanifold_vertices,
            components,
            euler,
            genus,
            closed,
            volume: closed.then(|| mesh.signed_volume()),
            bbox_min,
            bbox_max,
        }
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

fn degenerate_count(mesh: &Mesh) -> usize {
    mesh.triangles
        .par_iter()
        .with_min_len(4096)
        .filter(|t| {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return true;
            }
            let a = to_f64(mesh.positions[t[0] as usize]);
            let b = to_f64(mesh.positions[t[1] as usize]);
            let c = to_f64(mesh.positions[t[2] as usize]);
            cross(sub(b, a), sub(c, a)) == [0.0; 3]
        })
        .count()
}

fn duplicate_count(mesh: &Mesh) -> usize {
    let mut keys: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let mut k = *t;
            k.sort_unstable();
            k
        })
        .collect();
    keys.par_sort_unstable();
    keys.windows(2).filter(|w| w[0] == w[1]).count()
}

/// Number of edge-connected fans of triangles around vertex `i` (1 for a manifold vertex).
fn fan_count(mesh: &Mesh, topology: &Topology, i: usize) -> usize {
    let fan = topology.triangles_of(i);
    if fan.len() <= 1 {
        return fan.len();
    }
    // Tiny union-find over the fan; two triangles join when they share an edge through `i`.
    let mut parent: Vec<usize> = (0..fan.len()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut seen: Vec<(u32, usize)> = Vec::with_capacity(fan.len() * 2);
    for (k, &ti) in fan.iter().enumerate() {
        for &v in &mesh.triangles[ti as usize] {
            if v as usize == i {
                continue;
            }
            match seen.iter().find(|(u, _)| *u == v) {
                Some(&(_, other)) => {
                    let (a, b) = (find(&mut parent, other), find(&mut parent, k));
                    parent[a] = b;
                }
                None => seen.push((v, k)),
            }
        }
    }
    (0..fan.len())
        .filter(|&k| find(&mut parent, k) == k)
        .count()
}

fn component_count(mesh: &Mesh, topology: &Topology) -> usize {
    let n = mesh.vertex_count();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let p = parent[parent[x as usize] as usize];
            parent[x as usize] = p;
            x = p;
        }
        x
    }
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2])] {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent[ra as usize] = rb;
            }
        }
    }
    (0..n)
        .filter(|&i| topology.triangle_offsets[i] != topology.triangle_offsets[i + 1])
        .filter(|&i| find(&mut parent, i as u32) == i as u32)
        .count()
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
