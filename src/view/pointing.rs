//! Which structure of a case lies under the pointer, as drawn: a student's click or hover
//! names it. Hidden structures, those drawn all but transparent and what the clipping plane
//! cuts away are passed through.

use glam::Vec3;

use super::{pick_triangle_where, Hit, Ray};
use crate::case::CaseStructure;

/// Below this opacity a structure is looked through, not at.
const SEEN_THROUGH: f32 = 0.05;

/// The structure of `structures` that `ray` meets first, and where, of those drawn; `plane` is
/// the view's clipping plane `(n, d)` (`n . p > d` is cut away; zero cuts nothing).
pub fn structure_at(
    structures: &[CaseStructure],
    ray: &Ray,
    plane: [f32; 4],
) -> Option<(usize, Hit)> {
    first_hit(structures, ray, plane, SEEN_THROUGH)
}

/// The opaque structure `ray` meets first, and where: what hides whatever lies behind it (a
/// translucent one lets it show).
pub fn opaque_at(structures: &[CaseStructure], ray: &Ray, plane: [f32; 4]) -> Option<(usize, Hit)> {
    first_hit(structures, ray, plane, 1.0)
}

/// The first hit among the shown structures at least `opacity` opaque.
fn first_hit(
    structures: &[CaseStructure],
    ray: &Ray,
    plane: [f32; 4],
    opacity: f32,
) -> Option<(usize, Hit)> {
    let normal = Vec3::new(plane[0], plane[1], plane[2]);
    let kept = |p: Vec3| normal.dot(p) <= plane[3];
    // Each structure as drawn: its smoothed surface where it has one (the model's too,
    // measured or not), else the surface as read.
    (structures.iter().enumerate())
        .filter(|(_, s)| s.visible && s.color[3] >= opacity)
        .filter_map(|(i, s)| {
            let triangles = &s.original.triangles;
            pick_triangle_where(s.positions(), triangles, ray, kept).map(|hit| (i, hit))
        })
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
}
