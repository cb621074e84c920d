//! Building a [`MeshReport`] in steps, for a caller that must return between them (the browser's
//! one thread opening a large mesh draws a frame between steps): the per-vertex checks a run of
//! vertices at a time, then the per-triangle checks a run of triangles at a time, then the totals.
//! `MeshReport::new` runs the same steps in one call.

use std::ops::Range;

use super::{cross, sub, to_f64, Mesh, MeshReport, Topology};
use rayon::prelude::*;

/// A report under construction: what the vertices and triangles checked so far add up to.
pub struct ReportInParts {
    next_vertex: usize,
    next_triangle: usize,
    referenced: usize,
    nonmanifold_vertices: usize,
    degenerate_faces: usize,
    duplicate_faces: usize,
    triangles: usize,
    /// Union-find over the vertices, joined along the edges of the triangles checked so far.
    parent: Vec<u32>,
}

impl ReportInParts {
    pub fn new(mesh: &Mesh) -> Self {
        Self {
            next_vertex: 0,
            next_triangle: 0,
            referenced: 0,
            nonmanifold_vertices: 0,
            degenerate_faces: 0,
            duplicate_faces: 0,
            triangles: mesh.triangle_count(),
            parent: (0..mesh.vertex_count() as u32).collect(),
        }
    }

    /// Checks up to `items` more vertices, or once they are done, triangles (at least one);
    /// returns whether everything is checked. `topology` must be `Topology::build(mesh)`.
    pub fn advance(&mut self, mesh: &Mesh, topology: &Topology, items: usize) -> bool {
        let (n, f) = (mesh.vertex_count(), mesh.triangle_count());
        assert!(
            self.parent.len() == n && self.triangles == f,
            "the mesh the report was begun for"
        );
        let items = items.max(1);
        if self.next_vertex < n {
            let range = self.next_vertex..n.min(self.next_vertex.saturating_add(items));
            self.next_vertex = range.end;
            self.check_vertices(mesh, topology, range);
        } else if self.next_triangle < f {
            let range = self.next_triangle..f.min(self.next_triangle.saturating_add(items));
            self.next_triangle = range.end;
            self.check_triangles(mesh, topology, range);
        }
        self.next_vertex == n && self.next_triangle == f
    }

    /// The share of the vertices and triangles checked, in [0, 1].
    pub fn fraction(&self) -> f32 {
        let done = self.next_vertex + self.next_triangle;
        done as f32 / (self.parent.len() + self.triangles).max(1) as f32
    }

    /// Referenced and non-manifold vertices.
    fn check_vertices(&mut self, mesh: &Mesh, topology: &Topology, range: Range<usize>) {
        let (referenced, nonmanifold) = range
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                let fans = fan_count(mesh, topology, i);
                ((fans > 0) as usize, (fans > 1) as usize)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        self.referenced += referenced;
        self.nonmanifold_vertices += nonmanifold;
    }

    /// Degenerate and duplicate faces, and the components joined along the triangles' edges.
    fn check_triangles(&mut self, mesh: &Mesh, topology: &Topology, range: Range<usize>) {
        let (degenerate, duplicate) = range
            .clone()
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| {
                (
                    is_degenerate(mesh, t) as usize,
                    is_duplicate(mesh, topology, t) as usize,
                )
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        self.degenerate_faces += degenerate;
        self.duplicate_faces += duplicate;
        let parent = &mut self.parent;
        for t in &mesh.triangles[range] {
            for (a, b) in [(t[0], t[1]), (t[1], t[2])] {
                let (ra, rb) = (find(parent, a), find(parent, b));
                if ra != rb {
                    parent[ra as usize] = rb;
                }
            }
        }
    }

    /// The report, once [`Self::advance`] returned true.
    pub fn finish(mut self, mesh: &Mesh, topology: &Topology) -> MeshReport {
        let (n, f) = (mesh.vertex_count(), mesh.triangle_count());
        assert!(
            self.next_vertex == n && self.next_triangle == f,
            "finish before everything is checked"
        );
        let edges_used = |wanted: fn(u32) -> bool| {
            topology
                .edge_triangle_counts
                .iter()
                .filter(|&&c| wanted(c))
                .count()
                / 2
        };
        let boundary_edges = edges_used(|c| c == 1);
        let nonmanifold_edges = edges_used(|c| c >= 3);
        let components = (0..n)
            .filter(|&i| !topology.triangles_of(i).is_empty())
            .filter(|&i| find(&mut self.parent, i as u32) == i as u32)
            .count();
        let euler = self.referenced as i64 - topology.edge_count() as i64 + f as i64;
        let closed = boundary_edges == 0 && f > 0;
        let manifold = nonmanifold_edges == 0 && self.nonmanifold_vertices == 0;
        let genus = (closed && manifold && (2 * components as i64 - euler) % 2 == 0)
            .then(|| (2 * components as i64 - euler) / 2);
        let (bbox_min, bbox_max) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
        MeshReport {
            vertices: n,
            faces: f,
            unreferenced_vertices: n - self.referenced,
            degenerate_faces: self.degenerate_faces,
            duplicate_faces: self.duplicate_faces,
            boundary_edges,
            nonmanifold_edges,
            nonmanifold_vertices: self.nonmanifold_vertices,
            components,
            euler,
            genus,
            closed,
            volume: closed.then(|| mesh.signed_volume()),
            bbox_min,
            bbox_max,
        }
    }
}

/// A repeated index or zero area.
fn is_degenerate(mesh: &Mesh, t: usize) -> bool {
    let t = mesh.triangles[t];
    if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
        return true;
    }
    let a = to_f64(mesh.positions[t[0] as usize]);
    let b = to_f64(mesh.positions[t[1] as usize]);
    let c = to_f64(mesh.positions[t[2] as usize]);
    cross(sub(b, a), sub(c, a)) == [0.0; 3]
}

/// An earlier triangle has the same three vertices (in any order): it is among the triangles
/// of its lowest vertex, which the incidence lists in ascending order.
fn is_duplicate(mesh: &Mesh, topology: &Topology, t: usize) -> bool {
    let sorted = |t: usize| {
        let mut k = mesh.triangles[t];
        k.sort_unstable();
        k
    };
    let key = sorted(t);
    topology
        .triangles_of(key[0] as usize)
        .iter()
        .take_while(|&&u| (u as usize) < t)
        .any(|&u| sorted(u as usize) == key)
}

/// Fans up to this size are checked in arrays on the stack (no allocation per vertex).
const SMALL_FAN: usize = 16;

/// Number of edge-connected fans of triangles around vertex `i` (1 for a manifold vertex).
fn fan_count(mesh: &Mesh, topology: &Topology, i: usize) -> usize {
    let fan = topology.triangles_of(i);
    if fan.len() <= 1 {
        return fan.len();
    }
    if fan.len() <= SMALL_FAN {
        let mut parent = [0u32; SMALL_FAN];
        let mut seen = [(0u32, 0u32); 2 * SMALL_FAN];
        fans_in(mesh, fan, i, &mut parent[..fan.len()], &mut seen)
    } else {
        let mut parent = vec![0u32; fan.len()];
        let mut seen = vec![(0u32, 0u32); 2 * fan.len()];
        fans_in(mesh, fan, i, &mut parent, &mut seen)
    }
}

/// [`fan_count`] with scratch space: `parent` one entry per fan triangle, `seen` two.
fn fans_in(
    mesh: &Mesh,
    fan: &[u32],
    i: usize,
    parent: &mut [u32],
    seen: &mut [(u32, u32)],
) -> usize {
    for (k, p) in parent.iter_mut().enumerate() {
        *p = k as u32;
    }
    // Two triangles join when they share an edge through `i`: the same other vertex.
    let mut seen_len = 0;
    for (k, &t) in fan.iter().enumerate() {
        for &v in &mesh.triangles[t as usize] {
            if v as usize == i {
                continue;
            }
            match seen[..seen_len].iter().find(|(u, _)| *u == v) {
                Some(&(_, other)) => {
                    let (a, b) = (find(parent, other), find(parent, k as u32));
                    parent[a as usize] = b;
                }
                None => {
                    seen[seen_len] = (v, k as u32);
                    seen_len += 1;
                }
            }
        }
    }
    (0..parent.len() as u32)
        .filter(|&k| find(parent, k) == k)
        .count()
}

/// The root of `x`, halving the path on the way.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[parent[x as usize] as usize];
        parent[x as usize] = p;
        x = p;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures;

    #[test]
    fn any_steps_give_the_same_report() {
        let mut odd = fixtures::grid(40, 30);
        // A duplicate (rewound), a degenerate face, an unreferenced vertex and a second
        // component touching the grid at one vertex (non-manifold there).
        odd.triangles.push([5, 4, 46]);
        odd.triangles.push([7, 7, 8]);
        odd.positions.push([99.0; 3]);
        let v = odd.positions.len() as u32;
        odd.positions
            .extend([[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]]);
        odd.triangles.extend([[0, v, v + 1], [v + 1, v + 2, 0]]);
        for mesh in [fixtures::tetrahedron(), odd, Mesh::default()] {
            let topology = Topology::build(&mesh);
            let whole = MeshReport::new(&mesh, &topology);
            for part in [1, 7, 1000, 5000] {
                let mut parts = ReportInParts::new(&mesh);
                while !parts.advance(&mesh, &topology, part) {
                    assert!(parts.fraction() < 1.0);
                }
                assert_eq!(parts.finish(&mesh, &topology), whole, "part {part}");
            }
        }
    }

    #[test]
    fn counts_the_oddities_of_a_grid() {
        let mut mesh = fixtures::grid(40, 30);
        let clean = MeshReport::new(&mesh, &Topology::build(&mesh));
        assert_eq!(
            (
                clean.duplicate_faces,
                clean.degenerate_faces,
                clean.components
            ),
            (0, 0, 1)
        );
        assert_eq!(clean.nonmanifold_vertices, 0);
        mesh.triangles.push([5, 4, 46]);
        mesh.triangles.push([46, 5, 4]);
        mesh.triangles.push([7, 7, 8]);
        mesh.triangles.push([8, 7, 7]);
        let r = MeshReport::new(&mesh, &Topology::build(&mesh));
        // Each repeat of a face counts once: [5,4,46] twice over grid face [4,5,46], [8,7,7]
        // over [7,7,8].
        assert_eq!(r.duplicate_faces, 3, "{r:?}");
        assert_eq!(r.degenerate_faces, 2);
    }
}
