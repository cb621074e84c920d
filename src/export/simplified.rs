//! The case glTF's simplified surfaces: each structure's smoothed surface simplified for the
//! download (see `crate::simplify`), its original and local error kept at the vertices the
//! simplified surface keeps, and the record of what was done and how far it moved.

use serde_json::{json, Value};

use crate::case::CaseStructure;
use crate::mesh::Mesh;
use crate::simplify::{simplify, Goal, Simplified};

/// How the case glTF's surfaces are simplified.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Simplification {
    /// Each structure within this many of its voxel diagonals of its smoothed surface
    /// (a structure without voxels keeps its surface).
    VoxelDiagonals(f64),
    /// About this many triangles in the whole case, shared in proportion to each structure's.
    TriangleBudget(usize),
}

impl Simplification {
    fn goal(self, s: &CaseStructure, case_triangles: usize) -> Option<Goal> {
        match self {
            Simplification::VoxelDiagonals(v) => s.voxel_diagonal().map(|d| Goal::Within(v * d)),
            Simplification::TriangleBudget(n) => {
                let own = s.original.triangle_count();
                let share = (n as f64 * own as f64 / case_triangles.max(1) as f64).floor();
                Some(Goal::Triangles((share as usize).max(4)))
            }
        }
    }

    fn record(self) -> Value {
        match self {
            Simplification::VoxelDiagonals(v) => json!({ "voxel_diagonals": v }),
            Simplification::TriangleBudget(n) => json!({ "case_triangles": n }),
        }
    }
}

/// A structure's simplified triangles (`case_triangles`: the case's, for a budget's share),
/// `None` where its surface is kept.
pub(super) fn simplify_structure(
    s: &CaseStructure,
    how: Simplification,
    case_triangles: usize,
) -> Option<Simplified> {
    let goal = how.goal(s, case_triangles)?;
    simplify(
        &Mesh::new(s.positions().to_vec(), s.original.triangles.clone()),
        goal,
    )
}

/// A structure's surfaces as the file holds them.
pub(super) struct Written {
    pub shown: Mesh,
    pub original: Mesh,
    pub local_error: Option<Vec<f32>>,
}

/// The structure's shown and original surfaces, and its local error, on the vertices the
/// simplified triangles use (all of them, in order, without simplification).
pub(super) fn written(
    s: &CaseStructure,
    simplified: Option<&Simplified>,
    with_local_error: bool,
) -> Written {
    let local_error = (s.smoothed_now())
        .and_then(|m| m.local_error.clone())
        .filter(|_| with_local_error);
    let Some(simplified) = simplified else {
        return Written {
            shown: Mesh::new(s.positions().to_vec(), s.original.triangles.clone()),
            original: s.original.clone(),
            local_error,
        };
    };
    let mut new_of_old = vec![u32::MAX; s.original.vertex_count()];
    let mut old_of_new = Vec::new();
    for &v in simplified.triangles.iter().flatten() {
        if new_of_old[v as usize] == u32::MAX {
            new_of_old[v as usize] = old_of_new.len() as u32;
            old_of_new.push(v as usize);
        }
    }
    let triangles: Vec<[u32; 3]> = (simplified.triangles.iter())
        .map(|t| t.map(|v| new_of_old[v as usize]))
        .collect();
    let pick = |p: &[[f32; 3]]| old_of_new.iter().map(|&i| p[i]).collect::<Vec<_>>();
    Written {
        shown: Mesh::new(pick(s.positions()), triangles.clone()),
        original: Mesh::new(pick(&s.original.positions), triangles),
        local_error: local_error.map(|e| old_of_new.iter().map(|&i| e[i]).collect()),
    }
}

/// The record of a structure's simplification: the goal, and the measured deviation (mm and
/// voxel diagonals) with the triangle counts, or that the surface was kept.
pub(super) fn record(s: &CaseStructure, how: Simplification, done: Option<&Simplified>) -> Value {
    let mut r = json!({ "goal": how.record(), "simplified": done.is_some() });
    if let Some(d) = done {
        r["max_deviation_mm"] = json!(d.deviation_mm);
        r["max_deviation_voxel_diagonals"] = json!(s.voxel_diagonal().map(|v| d.deviation_mm / v));
        r["triangles_before"] = json!(s.original.triangle_count());
        r["triangles"] = json!(d.triangles.len());
    }
    r
}
