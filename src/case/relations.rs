//! Spatial relations between the structures of a case: which lie inside which, and which
//! reach into another's material. Each structure is smoothed on its own, so a tumour can come
//! out of its organ or two neighbours can push into each other; comparing the relations before
//! and after smoothing shows the author where.
//!
//! A structure is a closed, outward-wound surface that may have several shells: a structure
//! carved out of another leaves that one an inward-facing cavity shell. "Inside" asks whether
//! one surface lies within the other's outermost extent (its material or its cavities, i.e.
//! inside at least one of its shells); "crossing" asks how deep one surface reaches into the
//! other's material (inside by parity over all of its triangles). Neighbours in a label map
//! share faces exactly, so points within a tolerance of the other surface count as inside it,
//! and depths up to the tolerance are not crossings.

mod cells;
mod rays;
#[cfg(test)]
mod tests;

use std::collections::HashMap;

use rayon::prelude::*;

use crate::mesh::{to_f64, Mesh};
use cells::Cells;
use rays::{Location, RayBvh, RayShape};

/// What one pair of structures does, in one state (original or smoothed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairRelation {
    /// Index of the first structure; always below `b`.
    pub a: usize,
    pub b: usize,
    /// Every vertex of `a` lies inside a shell of `b` (its material or a cavity) or within the
    /// pair's enclosure tolerance of `b`'s surface.
    pub a_inside_b: bool,
    pub b_inside_a: bool,
    /// How far the farthest vertex of `a` lies outside every shell of `b` (mm): 0 when all are
    /// enclosed, infinite past the enclosure tolerance plus the crossing tolerance.
    pub a_outside_b: f64,
    pub b_outside_a: f64,
    /// The pair's crossing tolerance (mm): also how much farther out a surface that lay inside
    /// may reach before it counts as having left.
    pub tolerance: f64,
    /// Deepest vertex of either surface inside the other's material (mm), 0 when none.
    pub overlap_depth: f64,
    /// `overlap_depth` exceeds the pair's crossing tolerance.
    pub crosses: bool,
}

/// The changes an author must see between two states of a case.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RelationChanges {
    /// `(inner, outer)`: the inner structure lay inside the outer one before and no longer does.
    pub left_inside: Vec<(usize, usize)>,
    /// `(a, b)`: pairs that cross now and did not before.
    pub new_crossings: Vec<(usize, usize)>,
}

/// Relations of every pair whose bounding boxes, grown by the pair's enclosure tolerance, meet;
/// pairs that are apart are left out. `tolerance[i]` is how far structure `i`'s surface may lie
/// from its true boundary (mm; half its voxel diagonal for a label-map structure). A pair
/// crosses when one surface reaches deeper than the larger of its two tolerances into the
/// other's material. A vertex counts as enclosed within the sum of the two of the other's
/// surface: the staircases of a true boundary nested against another can lie that far apart
/// (the phantom's tumour touches the background where the liver's voxels stop one layer short).
/// Every position of a mesh counts as one of its vertices. Meshes should be closed; a mesh
/// without vertices meets nothing.
///
/// # Panics
/// When `tolerance` and `meshes` differ in length.
pub fn relations<'a, S: Into<Surface<'a>> + Copy>(
    meshes: &[S],
    tolerance: &[f64],
) -> Vec<PairRelation> {
    relations_refitting(meshes, tolerance, &mut TreeShapes::default())
}

/// The splits of the trees [`relations_refitting`] built over each structure's triangles.
/// Smoothing moves a structure's vertices, not its triangles: the next check of the same
/// triangles refits these trees to the new positions instead of building them anew.
#[derive(Clone, Debug, Default)]
pub struct TreeShapes(Vec<Option<RayShape>>);

/// [`relations`], refitting the trees of `shapes` where a structure has the triangles they
/// were built over (building the others), and leaving this check's in `shapes`.
///
/// # Panics
/// When `tolerance` and `meshes` differ in length.
pub fn relations_refitting<'a, S: Into<Surface<'a>> + Copy>(
    meshes: &[S],
    tolerance: &[f64],
    shapes: &mut TreeShapes,
) -> Vec<PairRelation> {
    assert_eq!(meshes.len(), tolerance.len(), "one tolerance per structure");
    let meshes: Vec<Surface> = meshes.iter().map(|&m| m.into()).collect();
    let boxes: Vec<Option<Box3>> = meshes.iter().map(|m| Box3::of(m.positions)).collect();
    let tolerance: Vec<f64> = tolerance.iter().map(|t| t.max(0.0)).collect();
    let mut pairs = Vec::new();
    for a in 0..meshes.len() {
        for b in a + 1..meshes.len() {
            let tol = Tolerance {
                crossing: tolerance[a].max(tolerance[b]),
                enclosure: tolerance[a] + tolerance[b],
            };
            if let (Some(ba), Some(bb)) = (&boxes[a], &boxes[b]) {
                if ba.grown(tol.enclosure).meets(bb) {
                    pairs.push((a, b, tol));
                }
            }
        }
    }
    let mut used = vec![false; meshes.len()];
    for &(a, b, _) in &pairs {
        used[a] = true;
        used[b] = true;
    }
    // Each kept shape is moved into its refitted tree, and each tree's back into `shapes`
    // once the pairs are measured: no copy of either is held beside the trees.
    let mut before = std::mem::take(&mut shapes.0);
    before.resize_with(meshes.len(), || None);
    let solids: Vec<Option<Solid>> = (meshes.par_iter().zip(before))
        .zip(&boxes)
        .zip(&used)
        .map(|(((mesh, shape), bounds), &used)| match bounds {
            Some(bounds) if used => Some(Solid::new(mesh, *bounds, shape)),
            _ => None,
        })
        .collect();
    let relations = pairs
        .par_iter()
        .filter_map(|&(a, b, tol)| {
            let (sa, sb) = (solids[a].as_ref()?, solids[b].as_ref()?);
            let cap = tol.enclosure + tol.crossing;
            let (ab, ba) = rayon::join(
                || reach(meshes[a].positions, sa.bounds, sb, cap),
                || reach(meshes[b].positions, sb.bounds, sa, cap),
            );
            let overlap_depth = ab.depth.max(ba.depth);
            Some(PairRelation {
                a,
                b,
                a_inside_b: ab.outside <= tol.enclosure,
                b_inside_a: ba.outside <= tol.enclosure,
                a_outside_b: ab.outside,
                b_outside_a: ba.outside,
                tolerance: tol.crossing,
                overlap_depth,
                crosses: overlap_depth > tol.crossing,
            })
        })
        .collect();
    shapes.0 = (solids.into_iter())
        .map(|s| s.map(|s| s.rays.into_shape()))
        .collect();
    relations
}

/// What changed from `before` to `after` (both from [`relations`] over the same structures).
/// A structure that lay inside another has left it when it now reaches farther outside it than
/// it did by more than the pair's tolerance: a staircase that already touched the outside (a
/// tumour under a thin layer the voxels did not resolve) is not flagged for staying there. A
/// pair missing from `after` has come apart, so an inside relation it had is left.
pub fn changes(before: &[PairRelation], after: &[PairRelation]) -> RelationChanges {
    let then: HashMap<(usize, usize), &PairRelation> =
        before.iter().map(|r| ((r.a, r.b), r)).collect();
    let now: HashMap<(usize, usize), &PairRelation> =
        after.iter().map(|r| ((r.a, r.b), r)).collect();
    let mut out = RelationChanges::default();
    for r in before {
        let still = now.get(&(r.a, r.b));
        let left = |was: f64, is: fn(&PairRelation) -> f64| {
            still.is_none_or(|s| is(s) > was + r.tolerance)
        };
        if r.a_inside_b && left(r.a_outside_b, |s| s.a_outside_b) {
            out.left_inside.push((r.a, r.b));
        }
        if r.b_inside_a && left(r.b_outside_a, |s| s.b_outside_a) {
            out.left_inside.push((r.b, r.a));
        }
    }
    for s in after {
        if s.crosses && !then.get(&(s.a, s.b)).is_some_and(|r| r.crosses) {
            out.new_crossings.push((s.a, s.b));
        }
    }
    out
}

/// The vertices behind each warning of `changed` (from [`changes`] of `before` and the
/// relations of `meshes` now), per structure, so a view can show where: of a structure that
/// left another, those farther outside it than the pair allows; of a pair that now crosses,
/// those of each deeper in the other's material than the pair's crossing tolerance.
/// `tolerance` is as given to [`relations`].
///
/// # Panics
/// When `tolerance` and `meshes` differ in length.
pub fn marks<'a, S: Into<Surface<'a>> + Copy>(
    meshes: &[S],
    tolerance: &[f64],
    before: &[PairRelation],
    changed: &RelationChanges,
) -> Vec<Vec<u32>> {
    assert_eq!(meshes.len(), tolerance.len(), "one tolerance per structure");
    let meshes: Vec<Surface> = meshes.iter().map(|&m| m.into()).collect();
    let tol = |a: usize, b: usize| Tolerance {
        crossing: tolerance[a].max(tolerance[b]).max(0.0),
        enclosure: tolerance[a].max(0.0) + tolerance[b].max(0.0),
    };
    // (structure marked, the other, what marks a vertex)
    let mut asks: Vec<(usize, usize, Mark)> = Vec::new();
    for &(inner, outer) in &changed.left_inside {
        let t = tol(inner, outer);
        let was = before
            .iter()
            .find(|r| (r.a, r.b) == (inner, outer) || (r.b, r.a) == (inner, outer))
            .map_or(0.0, |r| {
                if r.a == inner {
                    r.a_outside_b
                } else {
                    r.b_outside_a
                }
            });
        asks.push((inner, outer, Mark::OutsideBeyond(was + t.crossing)));
    }
    for &(a, b) in &changed.new_crossings {
        let depth = tol(a, b).crossing;
        asks.push((a, b, Mark::DeeperThan(depth)));
        asks.push((b, a, Mark::DeeperThan(depth)));
    }
    let mut solids: HashMap<usize, Solid> = HashMap::new();
    for &(_, other, _) in &asks {
        if let (None, Some(bounds)) = (solids.get(&other), Box3::of(meshes[other].positions)) {
            solids.insert(other, Solid::new(&meshes[other], bounds, None));
        }
    }
    let mut out = vec![Vec::new(); meshes.len()];
    for (marked, other, mark) in &asks {
        let (Some(solid), Some(bounds)) = (solids.get(other), Box3::of(meshes[*marked].positions))
        else {
            continue;
        };
        let t = tol(*marked, *other);
        let mut against = Against::new(bounds, solid, t.enclosure + t.crossing);
        // Every distance measured, so only the vertices that went too far are marked.
        against.may_enclose = true;
        let found: Vec<u32> = (meshes[*marked].positions.par_iter().enumerate())
            .filter(|(_, &p)| mark.holds(against.at(to_f64(p))))
            .map(|(i, _)| i as u32)
            .collect();
        out[*marked].extend(found);
    }
    for list in &mut out {
        list.sort_unstable();
        list.dedup();
    }
    out
}

/// What marks a vertex against another structure.
#[derive(Clone, Copy)]
enum Mark {
    /// Lying farther outside it than this (mm).
    OutsideBeyond(f64),
    /// Lying deeper in its material than this (mm).
    DeeperThan(f64),
}

impl Mark {
    fn holds(self, r: Reach) -> bool {
        match self {
            Mark::OutsideBeyond(d) => r.outside > d,
            Mark::DeeperThan(d) => r.depth > d,
        }
    }
}

/// A pair's tolerances (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tolerance {
    /// Depth into the other's material that is not yet a crossing.
    crossing: f64,
    /// Distance outside the other within which a vertex still counts as enclosed.
    enclosure: f64,
}

/// An axis-aligned box (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Box3 {
    min: [f64; 3],
    max: [f64; 3],
}

impl Box3 {
    fn of(positions: &[[f32; 3]]) -> Option<Self> {
        crate::mesh::bounding_box(positions).map(|(min, max)| Self {
            min: to_f64(min),
            max: to_f64(max),
        })
    }

    fn grown(&self, by: f64) -> Self {
        Self {
            min: self.min.map(|x| x - by),
            max: self.max.map(|x| x + by),
        }
    }

    fn meets(&self, other: &Self) -> bool {
        (0..3).all(|k| self.min[k] <= other.max[k] && other.min[k] <= self.max[k])
    }

    fn holds(&self, p: [f64; 3]) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }

    fn holds_box(&self, other: &Self) -> bool {
        self.holds(other.min) && self.holds(other.max)
    }
}

/// A structure's surface as the checks read it, borrowed: its positions and triangles.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    pub positions: &'a [[f32; 3]],
    pub triangles: &'a [[u32; 3]],
}

impl<'a> From<&'a Mesh> for Surface<'a> {
    fn from(m: &'a Mesh) -> Self {
        Surface {
            positions: &m.positions,
            triangles: &m.triangles,
        }
    }
}

/// A structure made ready to be asked about points: cells and rays for inside, the rays' tree
/// for distances.
struct Solid {
    bounds: Box3,
    cells: Cells,
    rays: RayBvh,
}

impl Solid {
    /// The structure's solid, its rays' tree refitted from `shape` where it fits.
    fn new(mesh: &Surface, bounds: Box3, shape: Option<RayShape>) -> Self {
        let (p, t) = (mesh.positions, mesh.triangles);
        let refitted = shape.and_then(|s| RayBvh::refitted(s, p, t));
        let rays = refitted.unwrap_or_else(|| RayBvh::new(p, t));
        Self {
            bounds,
            cells: Cells::new(p, t, bounds.min, bounds.max, &rays),
            rays,
        }
    }
}

/// How one surface lies against another structure.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Reach {
    /// How far the farthest vertex lies outside every shell of the other (mm), 0 when none
    /// does, infinite past the cap.
    outside: f64,
    /// Deepest vertex in the other's material (mm), 0 when none.
    depth: f64,
}

/// How the surface with vertices `positions` (bounded by `bounds`) lies against `other`;
/// distances outside it are measured up to `cap`.
fn reach(positions: &[[f32; 3]], bounds: Box3, other: &Solid, cap: f64) -> Reach {
    let against = Against::new(bounds, other, cap);
    positions
        .par_iter()
        .with_min_len(128)
        .map(|&p| against.at(to_f64(p)))
        .reduce(
            || Reach {
                outside: 0.0,
                depth: 0.0,
            },
            |x, y| Reach {
                outside: x.outside.max(y.outside),
                depth: x.depth.max(y.depth),
            },
        )
}

/// Asks how the points of one surface lie against another structure.
struct Against<'a> {
    other: &'a Solid,
    cap: f64,
    /// The other's box grown by the cap: points beyond it are farther out than the cap.
    reachable: Box3,
    /// The surface lies within `reachable`: below that, some point is beyond the cap anyway.
    may_enclose: bool,
}

impl<'a> Against<'a> {
    fn new(bounds: Box3, other: &'a Solid, cap: f64) -> Self {
        let reachable = other.bounds.grown(cap);
        Self {
            other,
            cap,
            reachable,
            may_enclose: reachable.holds_box(&bounds),
        }
    }

    /// Distances are computed only where they decide something: rays only for points in the
    /// other's box, distances outside only where the surface may still be enclosed.
    fn at(&self, p: [f64; 3]) -> Reach {
        let other = self.other;
        let outside = |p: [f64; 3]| {
            if !self.may_enclose {
                return f64::INFINITY;
            }
            match other.rays.tree().closest_within(p, self.cap.next_up()) {
                Some(c) => c.distance,
                None => f64::INFINITY,
            }
        };
        if !other.bounds.holds(p) {
            return Reach {
                outside: if self.reachable.holds(p) {
                    outside(p)
                } else {
                    f64::INFINITY
                },
                depth: 0.0,
            };
        }
        match other.cells.locate(p, &other.rays) {
            Location::OnSurface => Reach {
                outside: 0.0,
                depth: 0.0,
            },
            Location::Within { shells } if shells % 2 == 1 => Reach {
                outside: 0.0,
                depth: other.rays.tree().distance(p).unwrap_or(0.0),
            },
            Location::Within { shells } => Reach {
                outside: if shells > 0 { 0.0 } else { outside(p) },
                depth: 0.0,
            },
        }
    }
}
