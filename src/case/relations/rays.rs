//! Where a point lies against a closed surface, shell by shell: rays cast through a bounding
//! volume hierarchy over the surface's triangles, counting crossings per connected shell.
//!
//! Label-map surfaces are staircases: axis-aligned faces, edges and vertices on a grid, and
//! neighbouring structures share faces exactly. So rays leave along tilted, irrational-ish
//! directions that no grid line follows, and the ray-triangle test is watertight (Woop, Benthin
//! and Wald 2013, in f64): each edge's sign comes from the same transformed corners in both of
//! its triangles, so a ray passing between two triangles is counted by exactly one. A ray whose
//! edge signs are too close to call (it grazes an edge or a vertex) is thrown away and another
//! one cast; a ray that meets the surface at its start means the point is on the surface.

use crate::metrics::{TreeNode, TreeShape, TriangleBvh};

/// Deeper than any median-split tree over `u32` triangle counts can grow.
const STACK_DEPTH: usize = 64;
/// A point this close (mm) to a triangle along a ray lies on the surface.
pub(super) const ON_SURFACE: f64 = 1e-6;
/// An edge function below this fraction of its two products may have the wrong sign.
const SIGN_DOUBT: f64 = 1e-13;
/// Node boxes grow by this fraction of their coordinates (plus as much in mm), so rounding in
/// the slab test never culls a flat box (an axis-aligned staircase face) that a ray touches.
const BOX_PAD: f64 = 1e-9;
/// Tilts of a ray's two minor components off its main axis: irrational-ish and all different,
/// so no ray runs along a grid line or a staircase face, and no two rays are parallel.
pub(super) const TILTS: [[f64; 2]; 8] = [
    [std::f64::consts::FRAC_1_PI, 0.271_828_182_845_904_5],
    [-0.223_606_797_749_979, 0.414_213_562_373_095],
    [0.173_205_080_756_887_7, -0.381_966_011_250_105_1],
    [-0.367_879_441_171_442_3, -0.141_421_356_237_309_5],
    [0.447_213_595_499_957_9, 0.112_340_410_127_702_5],
    [-0.096_573_683_284_412_7, 0.333_978_211_634_927_4],
    [0.261_799_387_799_149_4, -0.193_147_180_559_945_3],
    [-0.405_465_108_108_164_4, -0.289_254_654_737_201_4],
];

/// Where a point lies against a surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Location {
    /// Within [`ON_SURFACE`] of it (or every ray grazed an edge, which only a point on the
    /// surface makes likely).
    OnSurface,
    /// Inside this many of its closed shells: 0 outside, odd in its material, even and more
    /// than 0 in a cavity.
    Within { shells: usize },
}

/// A closed surface made ready for rays and distances: its triangles in a tree, each knowing
/// its shell. Rays walk the distance tree's nodes and corners, so a structure is held once.
#[derive(Clone, Debug, Default)]
pub(super) struct RayBvh {
    tree: TriangleBvh,
    /// Each node's box as the rays test it ([`padded`]), worked out once and kept in f32
    /// rounded outwards (half the memory of f64; a box a hair larger only lets a ray test a
    /// few more triangles, each exactly).
    boxes: Vec<[[f32; 3]; 2]>,
    /// Connected shell of each entry of the tree's corners.
    shells: Vec<u32>,
    /// How many shells the surface has.
    shell_count: usize,
}

/// A [`RayBvh`] without its positions: its tree's splits and each entry's shell, which depend
/// on the triangles only.
#[derive(Clone, Debug, Default)]
pub(super) struct RayShape {
    tree: TreeShape,
    shells: Vec<u32>,
    shell_count: usize,
}

/// What one ray saw.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum Cast {
    OnSurface,
    /// It grazed an edge or a vertex: its count means nothing.
    Doubtful,
    /// The shells it crossed an odd number of times, sorted.
    Crossed(Vec<u32>),
}

/// What one triangle does to one ray.
enum Hit {
    Miss,
    /// Behind the origin, or past the ray's length.
    Behind,
    Ahead,
    OnSurface,
    Doubtful,
}

impl RayBvh {
    /// Builds the tree over `triangles` (indices into `positions`, which must be in range).
    pub(super) fn new(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Self {
        let tree = TriangleBvh::new(positions, triangles);
        let shell_of = triangle_shells(positions.len(), triangles);
        let shell_count = shell_of.iter().max().map_or(0, |&s| s as usize + 1);
        let shells = tree.ids().iter().map(|&t| shell_of[t as usize]).collect();
        Self::with_boxes(tree, shells, shell_count)
    }

    /// The tree of `shape` ([`Self::into_shape`] of a tree over the same triangles) at new
    /// `positions`, refitted ([`TriangleBvh::refitted`]); `None` when `shape` is not of
    /// `triangles.len()` triangles.
    pub(super) fn refitted(
        shape: RayShape,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
    ) -> Option<Self> {
        let tree = TriangleBvh::refitted(shape.tree, positions, triangles)?;
        Some(Self::with_boxes(tree, shape.shells, shape.shell_count))
    }

    /// What a tree over the same triangles at other positions keeps of this one; the rest
    /// is dropped.
    pub(super) fn into_shape(self) -> RayShape {
        RayShape {
            tree: self.tree.into_shape(),
            shells: self.shells,
            shell_count: self.shell_count,
        }
    }

    fn with_boxes(tree: TriangleBvh, shells: Vec<u32>, shell_count: usize) -> Self {
        let boxes = (tree.nodes().iter())
            .map(|node| {
                let (min, max) = padded(node);
                [min.map(f32_below), max.map(f32_above)]
            })
            .collect();
        Self {
            tree,
            boxes,
            shells,
            shell_count,
        }
    }

    /// The tree, for distances to the surface.
    pub(super) fn tree(&self) -> &TriangleBvh {
        &self.tree
    }

    /// How many connected shells the surface has.
    pub(super) fn shell_count(&self) -> usize {
        self.shell_count
    }

    /// The axis and sign of the side of the surface's box nearest to `p`, where rays from `p`
    /// leave it soonest; `None` for a surface without triangles.
    pub(super) fn nearest_side(&self, p: [f64; 3]) -> Option<(usize, f64)> {
        let root = self.tree.nodes().first()?;
        Some(nearest_side(&padded(root), p))
    }

    /// Where `p` lies: inside how many shells, by the majority of three rays (two that agree
    /// suffice), each shell counted by its own parity. Rays leave along the axis whose side of
    /// the surface's box is nearest, so they cross little of the tree.
    pub(super) fn locate(&self, p: [f64; 3]) -> Location {
        let Some((axis, sign)) = self.nearest_side(p) else {
            return Location::Within { shells: 0 };
        };
        let mut clean: Vec<Vec<u32>> = Vec::with_capacity(3);
        for tilt in TILTS {
            match self.cast(p, direction(axis, sign, tilt)) {
                Cast::OnSurface => return Location::OnSurface,
                Cast::Doubtful => continue,
                Cast::Crossed(odd) => clean.push(odd),
            }
            if clean.len() == 3 || (clean.len() == 2 && clean[0] == clean[1]) {
                break;
            }
        }
        if clean.is_empty() {
            return Location::OnSurface;
        }
        let rays = clean.len();
        let mut all = clean.concat();
        all.sort_unstable();
        let shells = all
            .chunk_by(|a, b| a == b)
            .filter(|votes| 2 * votes.len() > rays)
            .count();
        Location::Within { shells }
    }

    /// Casts one ray from `origin` along the unit vector `dir`.
    pub(super) fn cast(&self, origin: [f64; 3], dir: [f64; 3]) -> Cast {
        self.cast_within(origin, dir, f64::INFINITY)
    }

    /// Casts one ray from `origin` along the unit vector `dir`, counting the crossings up to
    /// `length` (mm) from the origin: the end must lie away from the surface, where no
    /// triangle's crossing is too close to `length` to tell.
    pub(super) fn cast_within(&self, origin: [f64; 3], dir: [f64; 3], length: f64) -> Cast {
        let ray = Ray::new(origin, dir, length);
        let mut odd: Vec<u32> = Vec::new();
        let mut stack = [0u32; STACK_DEPTH];
        let mut top = 0usize;
        let mut index = 0usize;
        let (nodes, corners) = (self.tree.nodes(), self.tree.corners());
        loop {
            let node = &nodes[index];
            if ray.enters(&self.boxes[index]) {
                if node.count > 0 {
                    let start = node.first as usize;
                    let end = start + node.count as usize;
                    for (tri, &shell) in corners[start..end].iter().zip(&self.shells[start..end]) {
                        match ray.hit(tri) {
                            Hit::Miss | Hit::Behind => {}
                            Hit::OnSurface => return Cast::OnSurface,
                            Hit::Doubtful => return Cast::Doubtful,
                            Hit::Ahead => match odd.iter().position(|&s| s == shell) {
                                Some(k) => {
                                    odd.swap_remove(k);
                                }
                                None => odd.push(shell),
                            },
                        }
                    }
                } else {
                    // Median splits keep the depth below 33, one entry per level at most.
                    stack[top] = node.first + 1;
                    top += 1;
                    index = node.first as usize;
                    continue;
                }
            }
            if top == 0 {
                odd.sort_unstable();
                return Cast::Crossed(odd);
            }
            top -= 1;
            index = stack[top] as usize;
        }
    }
}

/// A ray in the sheared frame of the watertight test: the ray runs along +z' from the origin.
struct Ray {
    origin: [f64; 3],
    inverse: [f64; 3],
    /// Crossings at or beyond this distance along the ray do not count.
    length: f64,
    /// Axes that become x', y' and z'.
    kx: usize,
    ky: usize,
    kz: usize,
    /// Shear of x' and y' by z, and the scale of z'.
    sx: f64,
    sy: f64,
    sz: f64,
}

impl Ray {
    fn new(origin: [f64; 3], dir: [f64; 3], length: f64) -> Self {
        let kz = (0..3)
            .max_by(|&a, &b| dir[a].abs().total_cmp(&dir[b].abs()))
            .unwrap_or(2);
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir[kz] < 0.0 {
            // Keeps the winding, as the paper does; parity would not mind.
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            origin,
            inverse: dir.map(|d| 1.0 / d),
            length,
            kx,
            ky,
            kz,
            sx: dir[kx] / dir[kz],
            sy: dir[ky] / dir[kz],
            sz: 1.0 / dir[kz],
        }
    }

    /// Whether the ray (from slightly behind its origin, to catch a surface through it) meets
    /// the node's box.
    #[inline]
    fn enters(&self, &[min, max]: &[[f32; 3]; 2]) -> bool {
        let (mut near, mut far) = (-ON_SURFACE, self.length);
        for k in 0..3 {
            let a = (f64::from(min[k]) - self.origin[k]) * self.inverse[k];
            let b = (f64::from(max[k]) - self.origin[k]) * self.inverse[k];
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        near <= far
    }

    /// A corner in the sheared frame. Every triangle that shares the corner gets the very same
    /// numbers, which is what makes the test watertight.
    #[inline]
    fn corner(&self, p: [f32; 3]) -> [f64; 3] {
        let a = [
            p[0] as f64 - self.origin[0],
            p[1] as f64 - self.origin[1],
            p[2] as f64 - self.origin[2],
        ];
        [
            a[self.kx] - self.sx * a[self.kz],
            a[self.ky] - self.sy * a[self.kz],
            self.sz * a[self.kz],
        ]
    }

    #[inline]
    fn hit(&self, tri: &[[f32; 3]; 3]) -> Hit {
        let [a, b, c] = tri.map(|p| self.corner(p));
        let u = edge(b, c);
        let v = edge(c, a);
        let w = edge(a, b);
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return Hit::Miss;
        }
        let det = u + v + w;
        if det == 0.0 {
            // The ray runs in the triangle's plane.
            return Hit::Doubtful;
        }
        let t = (u * a[2] + v * b[2] + w * c[2]) / det;
        if t.abs() <= ON_SURFACE {
            Hit::OnSurface
        } else if t < 0.0 || t >= self.length {
            Hit::Behind
        } else if u == 0.0 || v == 0.0 || w == 0.0 {
            Hit::Doubtful
        } else {
            Hit::Ahead
        }
    }
}

/// The edge function of `p`→`q` at the origin: `q` and `p` swapped give exactly its negation.
/// Zero when its sign is in doubt.
#[inline]
fn edge(p: [f64; 3], q: [f64; 3]) -> f64 {
    let (l, r) = (q[0] * p[1], q[1] * p[0]);
    let e = l - r;
    if e.abs() <= SIGN_DOUBT * (l.abs() + r.abs()) {
        0.0
    } else {
        e
    }
}

/// The unit direction along `axis` (towards `sign`), tilted by `tilt` on the other two axes.
pub(super) fn direction(axis: usize, sign: f64, tilt: [f64; 2]) -> [f64; 3] {
    let mut d = [0.0; 3];
    d[axis] = sign;
    d[(axis + 1) % 3] = tilt[0];
    d[(axis + 2) % 3] = tilt[1];
    let n = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    d.map(|x| x / n)
}

/// The axis and sign of the side of `node`'s box nearest to `p`.
fn nearest_side(&(min, max): &Padded, p: [f64; 3]) -> (usize, f64) {
    let mut best = (2, 1.0, f64::INFINITY);
    for (k, ((&x, &lo), &hi)) in p.iter().zip(&min).zip(&max).enumerate() {
        for (sign, gap) in [(-1.0, x - lo), (1.0, hi - x)] {
            if gap.abs() < best.2 {
                best = (k, sign, gap.abs());
            }
        }
    }
    (best.0, best.1)
}

/// A node's box, widened a hair ([`padded`]).
type Padded = ([f64; 3], [f64; 3]);

/// The tree's box of `node`, widened a hair so that a ray along a box face is not lost to
/// rounding.
fn padded(node: &TreeNode) -> Padded {
    let pad = |x: f64| BOX_PAD * (1.0 + x.abs());
    (
        node.min.map(|x| f64::from(x) - pad(f64::from(x))),
        node.max.map(|x| f64::from(x) + pad(f64::from(x))),
    )
}

/// The largest f32 at or below `x`.
fn f32_below(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        y.next_down()
    } else {
        y
    }
}

/// The smallest f32 at or above `x`.
fn f32_above(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up()
    } else {
        y
    }
}

/// The connected shell of each triangle (triangles sharing a vertex are one shell), numbered
/// from 0.
fn triangle_shells(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..vertex_count as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let up = parent[parent[v as usize] as usize];
            parent[v as usize] = up;
            v = up;
        }
        v
    }
    for tri in triangles {
        let r0 = root(&mut parent, tri[0]);
        for &v in &tri[1..] {
            let r = root(&mut parent, v);
            if r != r0 {
                parent[r as usize] = r0;
            }
        }
    }
    let mut number = vec![u32::MAX; vertex_count];
    let mut shells = 0u32;
    triangles
        .iter()
        .map(|tri| {
            let r = root(&mut parent, tri[0]) as usize;
            if number[r] == u32::MAX {
                number[r] = shells;
                shells += 1;
            }
            number[r]
        })
        .collect()
}
