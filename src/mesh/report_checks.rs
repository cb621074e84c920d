//! The checks behind a [`MeshReport`]: per vertex (referenced, manifold fans), per triangle
//! (degenerate, duplicate), the components by union-find along the triangles' edges, and the
//! totals.

use super::{cross, sub, to_f64, Mesh, MeshReport, Topology};
use rayon::prelude::*;

/// The report of `mesh`; `topology` must be `Topology::build(mesh)`.
pub(super) fn check(mesh: &Mesh, topology: &Topology) -> MeshReport {
    let (n, f) = (mesh.vertex_count(), mesh.triangle_count());
    let (referenced, nonmanifold_vertices) = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| {
            let fans = fan_count(mesh, topology, i);
            ((fans > 0) as usize, (fans > 1) as usize)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let (degenerate_faces, duplicate_faces) = (0..f)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| {
            (
                is_degenerate(mesh, t) as usize,
                is_duplicate(mesh, topology, t) as usize,
            )
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
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
    let components = components(mesh, topology);
    let euler = referenced as i64 - topology.edge_count() as i64 + f as i64;
    let closed = boundary_edges == 0 && f > 0;
    let manifold = nonmanifold_edges == 0 && nonmanifold_vertices == 0;
    let genus = (closed && manifold && (2 * components as i64 - euler) % 2 == 0)
        .then(|| (2 * components as i64 - euler) / 2);
    let (bbox_min, bbox_max) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
    MeshReport {
        vertices: n,
        faces: f,
        unreferenced_vertices: n - referenced,
        degenerate_faces,
        duplicate_faces,
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

/// Edge-connected components of the referenced vertices: union-find along the triangles' edges.
fn components(mesh: &Mesh, topology: &Topology) -> usize {
    let n = mesh.vertex_count();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2])] {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent[ra as usize] = rb;
            }
        }
    }
    (0..n)
        .filter(|&i| !topology.triangles_of(i).is_empty())
        .filter(|&i| find(&mut parent, i as u32) == i as u32)
        .count()
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
