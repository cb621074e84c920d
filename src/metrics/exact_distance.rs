//! Exact point-to-mesh distance: a bounding volume hierarchy over the triangles of the original
//! mesh. The local error only approximates this distance; tests and `measure --exact` use it as
//! the yardstick.

use crate::mesh::{cross, dot, sub, to_f64};
use rayon::prelude::*;

/// Triangles per leaf: small leaves keep the exact tests few, the tree stays shallow enough.
const LEAF_SIZE: usize = 4;
/// Deeper than any median-split tree over `u32` triangle counts can grow.
const STACK_DEPTH: usize = 64;
/// A triangle whose sine of the angle between its edges at the first corner is below this is
/// treated as a sliver: its plane is numerically unreliable, so only its edges count.
pub(crate) const SLIVER_SINE: f64 = 1e-8;

/// A node of a triangle tree: its box, and its leaf range or children.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// Leaf: first triangle in leaf order. Inner node: index of the left child (right = left + 1).
    pub first: u32,
    /// Triangles in a leaf; 0 marks an inner node.
    pub count: u32,
}

/// The median-split tree over `triangles` (indices into `positions`, which must be in range):
/// its nodes, root first, and the mesh's triangle indices in leaf order.
fn build_tree(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> (Vec<Node>, Vec<u32>) {
    // Each triangle's centroid, read from the mesh once: the build then walks these small
    // items in order at every level; a node's box comes from its children's once they are
    // built, so only the leaves read corners again.
    let mut items: Vec<Item> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut centroid = [0.0f32; 3];
            for &v in tri {
                for (k, &x) in positions[v as usize].iter().enumerate() {
                    centroid[k] += x / 3.0;
                }
            }
            Item {
                id: t as u32,
                centroid,
            }
        })
        .collect();
    let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
    if !items.is_empty() {
        nodes.push(Node {
            min: [0.0; 3],
            max: [0.0; 3],
            first: 0,
            count: 0,
        });
        let mesh = (positions, triangles);
        build(&mut nodes, 0, &mut items, 0, mesh);
    }
    (nodes, items.iter().map(|item| item.id).collect())
}

/// A tree's node links (first, count) and leaf order, without its boxes: what a tree over the
/// same triangles at other positions keeps ([`TriangleBvh::refitted`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct TreeShape {
    links: Vec<[u32; 2]>,
    ids: Vec<u32>,
}

/// A triangle while the tree is built.
struct Item {
    id: u32,
    centroid: [f32; 3],
}

/// The closest point of a mesh to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    pub distance: f64,
    /// Index of the triangle (in the mesh's triangle order) that holds the closest point.
    pub triangle: u32,
}

/// Bounding volume hierarchy (median split on the longest centroid axis) over a triangle set.
#[derive(Clone, Debug, Default)]
pub struct TriangleBvh {
    nodes: Vec<Node>,
    /// Triangle corners in leaf order, so a leaf's triangles are contiguous in memory.
    corners: Vec<[[f32; 3]; 3]>,
    /// Mesh triangle index of each entry of `corners`.
    ids: Vec<u32>,
}

impl TriangleBvh {
    /// Builds the tree over `triangles` (indices into `positions`, which must be in range).
    pub fn new(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Self {
        let (nodes, ids) = build_tree(positions, triangles);
        Self::from_tree(positions, triangles, nodes, ids)
    }

    /// The node links and leaf order of this tree, to be refitted later ([`Self::refitted`]);
    /// the rest is dropped.
    pub(crate) fn into_shape(self) -> TreeShape {
        TreeShape {
            links: self.nodes.iter().map(|n| [n.first, n.count]).collect(),
            ids: self.ids,
        }
    }

    /// The tree of `shape` over the same `triangles` at new `positions`: the splits kept, every
    /// box worked out again from its corners. As exact as a tree built anew and cheaper to
    /// make; its boxes overlap more the farther the vertices moved. `None` when `shape` is not
    /// of `triangles.len()` triangles.
    pub(crate) fn refitted(
        shape: TreeShape,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
    ) -> Option<Self> {
        if shape.ids.len() != triangles.len() {
            return None;
        }
        let corners: Vec<[[f32; 3]; 3]> = (shape.ids.iter())
            .map(|&t| triangles[t as usize].map(|v| positions[v as usize]))
            .collect();
        let mut nodes: Vec<Node> = (shape.links.iter())
            .map(|&[first, count]| Node {
                min: [f32::INFINITY; 3],
                max: [f32::NEG_INFINITY; 3],
                first,
                count,
            })
            .collect();
        // Children come after their parent: from the last node back, a node's children have
        // their boxes when it takes the union.
        for i in (0..nodes.len()).rev() {
            let Node { first, count, .. } = nodes[i];
            let (first, count) = (first as usize, count as usize);
            let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let mut grow = |p: [f32; 3]| {
                for k in 0..3 {
                    min[k] = min[k].min(p[k]);
                    max[k] = max[k].max(p[k]);
                }
            };
            if count > 0 {
                corners
                    .get(first..first + count)?
                    .iter()
                    .flatten()
                    .for_each(|&p| grow(p));
            } else {
                for child in nodes.get(first..first + 2)? {
                    grow(child.min);
                    grow(child.max);
                }
            }
            nodes[i].min = min;
            nodes[i].max = max;
        }
        Some(Self {
            nodes,
            corners,
            ids: shape.ids,
        })
    }

    fn from_tree(
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        nodes: Vec<Node>,
        ids: Vec<u32>,
    ) -> Self {
        let corners = ids
            .iter()
            .map(|&t| triangles[t as usize].map(|v| positions[v as usize]))
            .collect();
        Self {
            nodes,
            corners,
            ids,
        }
    }

    /// The tree's nodes, root first, for other walks over the same triangles (rays).
    pub(crate) fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The triangles' corners in leaf order (the order the nodes' ranges index).
    pub(crate) fn corners(&self) -> &[[[f32; 3]; 3]] {
        &self.corners
    }

    /// The mesh's triangle index of each entry of [`Self::corners`].
    pub(crate) fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// Closest point of the triangle set to `p`; `None` when there are no triangles.
    pub fn closest(&self, p: [f64; 3]) -> Option<Closest> {
        self.closest_within(p, f64::INFINITY)
    }

    /// Closest point of the triangle set to `p` if it is nearer than `bound`, else `None`.
    /// A good bound (a distance known to be reached, such as the local error) lets the search
    /// skip most of the tree.
    pub fn closest_within(&self, p: [f64; 3], bound: f64) -> Option<Closest> {
        let root = self.nodes.first()?;
        let mut best = bound * bound;
        let mut best_entry = usize::MAX;
        let mut stack = [0u32; STACK_DEPTH];
        let mut top = 0usize;
        let mut node = *root;
        loop {
            if node.count > 0 {
                let start = node.first as usize;
                for (k, tri) in self.corners[start..start + node.count as usize]
                    .iter()
                    .enumerate()
                {
                    let d2 =
                        point_triangle_distance2(p, to_f64(tri[0]), to_f64(tri[1]), to_f64(tri[2]));
                    if d2 < best {
                        best = d2;
                        best_entry = start + k;
                    }
                }
            } else {
                // Visit the nearer child first; keep the other if it could still hold a closer point.
                let left = node.first as usize;
                let (dl, dr) = (
                    box_distance2(&self.nodes[left], p),
                    box_distance2(&self.nodes[left + 1], p),
                );
                let (near, far, dfar, dnear) = if dl <= dr {
                    (left, left + 1, dr, dl)
                } else {
                    (left + 1, left, dl, dr)
                };
                if dfar < best {
                    // One entry per level at most, and median splits keep the depth below 33.
                    stack[top] = far as u32;
                    top += 1;
                }
                if dnear < best {
                    node = self.nodes[near];
                    continue;
                }
            }
            // Pop the next subtree that can still beat the best distance.
            loop {
                if top == 0 {
                    return self.ids.get(best_entry).map(|&triangle| Closest {
                        distance: best.sqrt(),
                        triangle,
                    });
                }
                top -= 1;
                let candidate = self.nodes[stack[top] as usize];
                if box_distance2(&candidate, p) < best {
                    node = candidate;
                    break;
                }
            }
        }
    }

    /// Distance from `p` to the triangle set; `None` when there are no triangles.
    pub fn distance(&self, p: [f64; 3]) -> Option<f64> {
        self.closest(p).map(|c| c.distance)
    }

    /// Distances of many points, in parallel; `f64::INFINITY` where there are no triangles.
    pub fn distances(&self, points: &[[f32; 3]]) -> Vec<f64> {
        points
            .par_iter()
            .with_min_len(256)
            .map(|&p| self.distance(to_f64(p)).unwrap_or(f64::INFINITY))
            .collect()
    }
}

/// Fills `nodes[index]` for `items` (whose leaf order starts at `offset`) and recurses.
/// Depth is bounded by log2 of the triangle count because every split halves the set.
fn build(
    nodes: &mut Vec<Node>,
    index: usize,
    items: &mut [Item],
    offset: usize,
    mesh: (&[[f32; 3]], &[[u32; 3]]),
) {
    if items.len() <= LEAF_SIZE {
        let (positions, triangles) = mesh;
        let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for item in items.iter() {
            for &v in &triangles[item.id as usize] {
                let p = positions[v as usize];
                for k in 0..3 {
                    min[k] = min[k].min(p[k]);
                    max[k] = max[k].max(p[k]);
                }
            }
        }
        nodes[index] = Node {
            min,
            max,
            first: offset as u32,
            count: items.len() as u32,
        };
        return;
    }
    let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for item in items.iter() {
        for k in 0..3 {
            cmin[k] = cmin[k].min(item.centroid[k]);
            cmax[k] = cmax[k].max(item.centroid[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (cmax[a] - cmin[a]).total_cmp(&(cmax[b] - cmin[b])))
        .unwrap_or(0);
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    let left = nodes.len();
    let placeholder = Node {
        min: [0.0; 3],
        max: [0.0; 3],
        first: 0,
        count: 0,
    };
    nodes.push(placeholder);
    nodes.push(placeholder);
    let (lo, hi) = items.split_at_mut(mid);
    build(nodes, left, lo, offset, mesh);
    build(nodes, left + 1, hi, offset + mid, mesh);
    let (a, b) = (nodes[left], nodes[left + 1]);
    nodes[index] = Node {
        min: std::array::from_fn(|k| a.min[k].min(b.min[k])),
        max: std::array::from_fn(|k| a.max[k].max(b.max[k])),
        first: left as u32,
        count: 0,
    };
}

#[inline]
fn box_distance2(node: &Node, p: [f64; 3]) -> f64 {
    let mut d2 = 0.0;
    for ((&x, &lo), &hi) in p.iter().zip(&node.min).zip(&node.max) {
        // Zero inside the slab, else the gap to its nearer side.
        let d = (lo as f64 - x).max(x - hi as f64).max(0.0);
        d2 += d * d;
    }
    d2
}

/// Squared distance from `p` to the segment `a`-`b` (a point when `a == b`).
#[inline]
pub fn point_segment_distance2(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let e = sub(b, a);
    let d = sub(p, a);
    let len2 = dot(e, e);
    let t = if len2 > 0.0 {
        (dot(d, e) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let r = [d[0] - t * e[0], d[1] - t * e[1], d[2] - t * e[2]];
    dot(r, r)
}

/// Squared distance from `p` to the triangle `a b c`. The closest point is either the projection
/// onto the plane (when it falls inside) or on one of the three edges; degenerate and sliver
/// triangles are measured by their edges alone, which never yields NaN.
pub fn point_triangle_distance2(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let m = cross(e1, e2);
    let m2 = dot(m, m);
    if m2 > (SLIVER_SINE * SLIVER_SINE) * dot(e1, e1) * dot(e2, e2) && m2.is_finite() {
        let d = sub(p, a);
        // Barycentric coordinates of the projection by Cramer's rule with the plane normal m.
        let u = dot(cross(d, e2), m) / m2;
        let v = dot(cross(e1, d), m) / m2;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
            let h = dot(d, m);
            return h * h / m2;
        }
    }
    point_segment_distance2(p, a, b)
        .min(point_segment_distance2(p, b, c))
        .min(point_segment_distance2(p, c, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance from `p` to the nearest of `triangles`, each measured.
    fn brute_distance(p: [f64; 3], positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> f64 {
        (triangles.iter())
            .map(|t| {
                let [a, b, c] = t.map(|v| to_f64(positions[v as usize]));
                point_triangle_distance2(p, a, b, c)
            })
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    }

    #[test]
    fn triangle_regions() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        // Above the face, beyond an edge, beyond a corner.
        assert_eq!(point_triangle_distance2([0.5, 0.5, 3.0], a, b, c), 9.0);
        assert!((point_triangle_distance2([1.0, -1.0, 0.0], a, b, c) - 1.0).abs() < 1e-15);
        assert!((point_triangle_distance2([3.0, -1.0, 1.0], a, b, c) - 3.0).abs() < 1e-15);
        // Beyond the hypotenuse: the closest point is (1, 1, 0).
        assert!((point_triangle_distance2([1.5, 1.5, 0.0], a, b, c) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn degenerate_triangles_measure_by_edges() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        // Collinear and fully collapsed triangles.
        let d = point_triangle_distance2([0.5, 1.0, 0.0], a, b, [2.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-15);
        let d = point_triangle_distance2([0.0, 0.0, 2.0], a, a, a);
        assert_eq!(d, 4.0);
    }

    #[test]
    fn empty_tree_has_no_distance() {
        let bvh = TriangleBvh::new(&[], &[]);
        assert_eq!(bvh.distance([0.0; 3]), None);
        assert_eq!(bvh.distances(&[[1.0; 3]]), vec![f64::INFINITY]);
    }

    #[test]
    fn tree_matches_brute_force_on_a_strip() {
        // A wavy strip of many triangles so the tree has several levels.
        let n = 40;
        let mut positions = Vec::new();
        for i in 0..=n {
            let x = i as f32 * 0.5;
            positions.push([x, 0.0, (x * 0.7).sin()]);
            positions.push([x, 1.0, (x * 0.3).cos()]);
        }
        let mut triangles = Vec::new();
        for i in 0..n as u32 {
            let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
        let bvh = TriangleBvh::new(&positions, &triangles);
        // The same triangles with their vertices moved, on the first tree's splits.
        let moved: Vec<[f32; 3]> = (positions.iter().enumerate())
            .map(|(i, p)| [p[0], p[1] + 0.3 * (i as f32).sin(), p[2] - 0.2 * p[0].cos()])
            .collect();
        let shape = || bvh.clone().into_shape();
        let refitted = TriangleBvh::refitted(shape(), &moved, &triangles).expect("fits");
        assert!(TriangleBvh::refitted(shape(), &moved, &triangles[1..]).is_none());
        for k in 0..200 {
            let f = k as f64;
            let p = [
                (f * 0.37) % 22.0 - 1.0,
                (f * 0.61) % 3.0 - 1.0,
                (f * 0.23) % 4.0 - 2.0,
            ];
            let brute = brute_distance(p, &positions, &triangles);
            let got = bvh.closest(p).expect("non-empty");
            assert_eq!(got.distance, brute, "point {p:?}");
            let moved_brute = brute_distance(p, &moved, &triangles);
            assert_eq!(refitted.distance(p), Some(moved_brute), "point {p:?}");
            let [a, b, c] = triangles[got.triangle as usize].map(|v| to_f64(positions[v as usize]));
            assert_eq!(point_triangle_distance2(p, a, b, c).sqrt(), brute);
        }
    }
}
