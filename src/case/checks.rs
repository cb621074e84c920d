//! The checks between a case's structures an author reads after smoothing: which structure
//! that lay inside another has left it, and which surfaces that did not cross now do.

use serde_json::{json, Value};

use super::relations::{
    marks, relations, relations_refitting, PairRelation, RelationChanges, Surface, TreeShapes,
};
use super::Case;

/// The relations of every pair of structures that come near each other: of the originals, or
/// of the surfaces as shown. Each structure tolerates half its voxel diagonal (the
/// segmentation cannot place its boundary closer than that), a surface mesh none.
pub fn check(case: &Case, shown: bool) -> Vec<PairRelation> {
    relations(&surfaces(case, shown), &tolerances(case))
}

/// [`check`], refitting the trees of the check before it (kept in `trees`) where the
/// structures have the same triangles, and keeping this check's: the checks as opened and as
/// shown differ in positions only.
pub fn check_refitting(case: &Case, shown: bool, trees: &mut TreeShapes) -> Vec<PairRelation> {
    relations_refitting(&surfaces(case, shown), &tolerances(case), trees)
}

/// The vertices of each structure's surface as shown that make the warnings of `changed`
/// (found by [`check`] as opened, `before`, and as shown), so a view can mark where.
pub fn check_marks(
    case: &Case,
    before: &[PairRelation],
    changed: &RelationChanges,
) -> Vec<Vec<u32>> {
    if changed.left_inside.is_empty() && changed.new_crossings.is_empty() {
        return vec![Vec::new(); case.structures.len()];
    }
    marks(&surfaces(case, true), &tolerances(case), before, changed)
}

/// Each structure's surface, borrowed from the case (a whole-body case is not copied to be
/// checked).
fn surfaces(case: &Case, shown: bool) -> Vec<Surface<'_>> {
    (case.structures.iter())
        .map(|s| Surface {
            positions: match s.smoothed_now() {
                Some(m) if shown => &m.positions,
                _ => &s.original.positions,
            },
            triangles: &s.original.triangles,
        })
        .collect()
}

fn tolerances(case: &Case) -> Vec<f64> {
    (case.structures.iter())
        .map(|s| s.voxel_diagonal().map_or(0.0, |d| 0.5 * d))
        .collect()
}

fn pair_names(case: &Case, pairs: &[(usize, usize)]) -> Vec<[String; 2]> {
    pairs
        .iter()
        .map(|&(a, b)| {
            [
                case.structures[a].name.clone(),
                case.structures[b].name.clone(),
            ]
        })
        .collect()
}

/// The checks as JSON: every pair's relation by name, and the changes.
pub fn checks_json(case: &Case, after: &[PairRelation], changed: &RelationChanges) -> Value {
    let name = |i: usize| case.structures[i].name.as_str();
    let pairs: Vec<Value> = after
        .iter()
        .map(|r| {
            json!({
                "a": name(r.a), "b": name(r.b),
                "a_inside_b": r.a_inside_b, "b_inside_a": r.b_inside_a,
                "a_outside_b_mm": finite(r.a_outside_b), "b_outside_a_mm": finite(r.b_outside_a),
                "overlap_depth_mm": r.overlap_depth, "crosses": r.crosses,
            })
        })
        .collect();
    json!({
        "pairs": pairs,
        "left_inside": pair_names(case, &changed.left_inside),
        "new_crossings": pair_names(case, &changed.new_crossings),
    })
}

/// A distance, or `None` past the distance measured up to.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The checks as lines of text: what lay inside what and still does, and what went wrong.
pub fn checks_text(
    case: &Case,
    before: &[PairRelation],
    after: &[PairRelation],
    changed: &RelationChanges,
) -> String {
    let name = |i: usize| case.structures[i].name.as_str();
    let mut out = String::new();
    for r in before {
        for (inner, outer, inside) in [(r.a, r.b, r.a_inside_b), (r.b, r.a, r.b_inside_a)] {
            if inside && !changed.left_inside.contains(&(inner, outer)) {
                out += &format!("{} lies inside {}\n", name(inner), name(outer));
            }
        }
    }
    for &(a, b) in &changed.left_inside {
        out += &format!("warning: {} no longer lies inside {}\n", name(a), name(b));
    }
    for &(a, b) in &changed.new_crossings {
        let depth = after
            .iter()
            .find(|r| (r.a, r.b) == (a, b) || (r.a, r.b) == (b, a))
            .map_or(0.0, |r| r.overlap_depth);
        out += &format!(
            "warning: {} and {} now cross ({depth:.2} mm deep)\n",
            name(a),
            name(b)
        );
    }
    if changed.left_inside.is_empty() && changed.new_crossings.is_empty() {
        out += "no structure left another, and no new crossing\n";
    }
    out
}
