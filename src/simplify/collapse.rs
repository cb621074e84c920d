//! Half-edge collapses ordered by quadric error (Garland and Heckbert), each allowed only where
//! it keeps the surface a closed manifold of the same topology (the link condition) and folds
//! no triangle over. A collapse moves one vertex onto a neighbour, so the result keeps a subset
//! of the vertices, each where it was.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::mesh::{vertex_normals, Mesh};

/// The sum of squared distances to a set of planes, as a symmetric 4 x 4 matrix (10 numbers).
#[derive(Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: [f64; 3], d: f64) -> Self {
        let [a, b, c] = n;
        Quadric([
            a * a,
            a * b,
            a * c,
            a * d,
            b * b,
            b * c,
            b * d,
            c * c,
            c * d,
            d * d,
        ])
    }

    fn add(&mut self, o: &Quadric) {
        for (x, y) in self.0.iter_mut().zip(o.0) {
            *x += y;
        }
    }

    /// The summed squared distance of `p` to the planes (mm²).
    fn error(&self, p: [f64; 3]) -> f64 {
        let q = &self.0;
        let [x, y, z] = p;
        (q[0] * x * x + 2.0 * q[1] * x * y + 2.0 * q[2] * x * z + 2.0 * q[3] * x)
            + (q[4] * y * y + 2.0 * q[5] * y * z + 2.0 * q[6] * y)
            + (q[7] * z * z + 2.0 * q[8] * z + q[9])
    }
}

/// A candidate collapse of `from` onto `to`, with the stamps its ends had when it was costed.
struct Candidate {
    cost: f64,
    from: u32,
    to: u32,
    stamps: (u32, u32),
}

impl PartialEq for Candidate {
    fn eq(&self, o: &Self) -> bool {
        self.cost.total_cmp(&o.cost) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Candidate {
    // The heap pops the cheapest first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost.total_cmp(&self.cost)
    }
}

struct State<'a> {
    positions: &'a [[f32; 3]],
    /// The given surface's vertex normals: no triangle may face against its corners' normals.
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    alive: Vec<bool>,
    /// Each vertex's triangles (dead ones are dropped as met).
    around: Vec<Vec<u32>>,
    quadrics: Vec<Quadric>,
    stamps: Vec<u32>,
    removed: Vec<bool>,
    max_cost: f64,
    heap: BinaryHeap<Candidate>,
}

/// The surface's triangles after collapses costing at most `max_cost` (mm², the summed squared
/// distance of the kept vertex to the planes its collapsed neighbourhood had), stopping early
/// at `keep` triangles. Returns triangles over the surface's own vertices.
pub(super) fn collapse(surface: &Mesh, max_cost: f64, keep: usize) -> Vec<[u32; 3]> {
    let mut s = State::new(surface, max_cost);
    let mut count = surface.triangles.len();
    while count > keep {
        let Some(c) = s.heap.pop() else { break };
        let (u, v) = (c.from as usize, c.to as usize);
        if s.removed[u] || s.removed[v] || c.stamps != (s.stamps[u], s.stamps[v]) {
            continue;
        }
        if let Some(gone) = s.try_collapse(u, v) {
            count -= gone;
        }
    }
    (s.triangles.iter().zip(&s.alive))
        .filter(|(_, &a)| a)
        .map(|(t, _)| *t)
        .collect()
}

fn p64(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn dot(u: [f64; 3], v: [f64; 3]) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

impl<'a> State<'a> {
    fn new(surface: &'a Mesh, max_cost: f64) -> Self {
        let n = surface.positions.len();
        let mut around = vec![Vec::new(); n];
        let mut quadrics = vec![Quadric::default(); n];
        for (i, t) in surface.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|v| p64(surface.positions[v as usize]));
            let normal = cross(sub(b, a), sub(c, a));
            let length = dot(normal, normal).sqrt();
            for &v in t {
                around[v as usize].push(i as u32);
            }
            if length > 0.0 {
                let unit = normal.map(|x| x / length);
                let q = Quadric::plane(unit, -dot(unit, a));
                for &v in t {
                    quadrics[v as usize].add(&q);
                }
            }
        }
        let mut s = State {
            positions: &surface.positions,
            normals: vertex_normals(&surface.positions, &surface.triangles),
            triangles: surface.triangles.clone(),
            alive: vec![true; surface.triangles.len()],
            around,
            quadrics,
            stamps: vec![0; n],
            removed: vec![false; n],
            max_cost,
            heap: BinaryHeap::new(),
        };
        let mut first = Vec::with_capacity(surface.triangles.len());
        for t in &surface.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                // Each edge once: from the triangle that has it with its lower end first.
                if a < b {
                    first.extend(s.candidate(a as usize, b as usize));
                }
            }
        }
        s.heap = BinaryHeap::from(first);
        s
    }

    /// Costs both directions of the edge and keeps the cheaper, where it is within the most a
    /// collapse may cost (a dearer one would never be taken).
    fn push_edge(&mut self, a: usize, b: usize) {
        if let Some(c) = self.candidate(a, b) {
            self.heap.push(c);
        }
    }

    fn candidate(&self, a: usize, b: usize) -> Option<Candidate> {
        let mut q = self.quadrics[a];
        q.add(&self.quadrics[b]);
        let cost_at = |v: usize| q.error(p64(self.positions[v])).max(0.0);
        let (ca, cb) = (cost_at(a), cost_at(b));
        let (from, to, cost) = if cb <= ca { (a, b, cb) } else { (b, a, ca) };
        (cost <= self.max_cost).then(|| Candidate {
            cost,
            from: from as u32,
            to: to as u32,
            stamps: (self.stamps[from], self.stamps[to]),
        })
    }

    fn live_triangles(&mut self, v: usize) -> Vec<u32> {
        let alive = &self.alive;
        self.around[v].retain(|&t| alive[t as usize]);
        self.around[v].clone()
    }

    fn neighbours(&self, triangles: &[u32], v: usize) -> Vec<u32> {
        let mut out: Vec<u32> = triangles
            .iter()
            .flat_map(|&t| self.triangles[t as usize])
            .filter(|&w| w as usize != v)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Collapses `u` onto `v` where that keeps the surface sound; the triangles it removed.
    fn try_collapse(&mut self, u: usize, v: usize) -> Option<usize> {
        let tu = self.live_triangles(u);
        let tv = self.live_triangles(v);
        let shared: Vec<u32> = tu
            .iter()
            .copied()
            .filter(|t| self.triangles[*t as usize].contains(&(v as u32)))
            .collect();
        if shared.len() != 2 {
            return None;
        }
        // The link condition: u and v share exactly the neighbours opposite their edge.
        let (nu, nv) = (self.neighbours(&tu, u), self.neighbours(&tv, v));
        let common: Vec<u32> = nu
            .iter()
            .copied()
            .filter(|w| nv.binary_search(w).is_ok())
            .collect();
        let mut opposite: Vec<u32> = shared
            .iter()
            .flat_map(|&t| self.triangles[t as usize])
            .filter(|&w| w as usize != u && w as usize != v)
            .collect();
        opposite.sort_unstable();
        if common != opposite || opposite.len() != 2 {
            return None;
        }
        // Neither opposite vertex may drop to two triangles (a tetrahedron's collapse).
        if opposite.iter().any(|&w| {
            self.around[w as usize]
                .iter()
                .filter(|&&t| self.alive[t as usize])
                .count()
                <= 3
        }) {
            return None;
        }
        let moved: Vec<u32> = tu.iter().copied().filter(|t| !shared.contains(t)).collect();
        if moved.iter().any(|&t| self.folds(t, u, v)) {
            return None;
        }
        for &t in &shared {
            self.alive[t as usize] = false;
        }
        for &t in &moved {
            for w in self.triangles[t as usize].iter_mut() {
                if *w as usize == u {
                    *w = v as u32;
                }
            }
            self.around[v].push(t);
        }
        self.removed[u] = true;
        self.around[u].clear();
        let q = self.quadrics[u];
        self.quadrics[v].add(&q);
        self.stamps[v] += 1;
        let tv = self.live_triangles(v);
        for w in self.neighbours(&tv, v) {
            self.push_edge(v, w as usize);
        }
        Some(shared.len())
    }

    /// Whether triangle `t`, with `u` moved onto `v`, turns against its own normal or its
    /// corners' normals on the given surface, or becomes a sliver.
    fn folds(&self, t: u32, u: usize, v: usize) -> bool {
        let corners = self.triangles[t as usize];
        let at = |w: u32| p64(self.positions[w as usize]);
        let [a, b, c] = corners.map(at);
        let before = cross(sub(b, a), sub(c, a));
        let [a2, b2, c2] = corners.map(|w| if w as usize == u { at(v as u32) } else { at(w) });
        let after = cross(sub(b2, a2), sub(c2, a2));
        let longest = [sub(b2, a2), sub(c2, b2), sub(a2, c2)]
            .iter()
            .map(|e| dot(*e, *e))
            .fold(0.0, f64::max);
        let area2 = dot(after, after).sqrt();
        let corner_normals: [f64; 3] = std::array::from_fn(|k| {
            corners
                .iter()
                .map(|&w| if w as usize == u { v } else { w as usize })
                .map(|w| f64::from(self.normals[w][k]))
                .sum()
        });
        area2 <= SLIVER * longest || dot(before, after) <= 0.0 || dot(corner_normals, after) <= 0.0
    }
}

/// Twice a triangle's area over its longest edge squared below which it is a sliver (its
/// height below a fiftieth of its longest edge): no collapse makes one.
const SLIVER: f64 = 0.02;
