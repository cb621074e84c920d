//! Relations between the structures of the shared label maps: the phantom's tumour lies inside
//! its liver and nothing crosses as extracted; a tumour grown by 3 mm crosses the liver. The
//! JHU atlas (48 structures) is timed, before and after smoothing each structure.

use std::time::Instant;

use meshsmooth::case::relations::{changes, relations, PairRelation};
use meshsmooth::mesh::{Mesh, Topology};
use meshsmooth::segmentation::Structure;
use meshsmooth::smooth::{smooth, Filter, NoObserver, Params};

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::open;

/// Half each structure's voxel diagonal: how far the true boundary may lie from the staircase.
fn tolerances(structures: &[Structure]) -> Vec<f64> {
    structures
        .iter()
        .map(|s| 0.5 * s.voxel_diagonal())
        .collect()
}

fn index(structures: &[Structure], name: &str) -> usize {
    structures
        .iter()
        .position(|s| s.name == name)
        .unwrap_or_else(|| panic!("no {name} among {:?}", names(structures)))
}

fn names(structures: &[Structure]) -> Vec<&str> {
    structures.iter().map(|s| s.name.as_str()).collect()
}

fn pair(list: &[PairRelation], a: usize, b: usize) -> PairRelation {
    *list
        .iter()
        .find(|r| (r.a, r.b) == (a.min(b), a.max(b)))
        .unwrap_or_else(|| panic!("no pair ({a}, {b}) in {list:?}"))
}

/// Whether `inner` lies inside `outer` according to their pair.
fn inside(list: &[PairRelation], inner: usize, outer: usize) -> bool {
    let r = pair(list, inner, outer);
    if r.a == inner {
        r.a_inside_b
    } else {
        r.b_inside_a
    }
}

/// Moves every vertex away from the centroid by `by` mm.
fn push_out(mesh: &Mesh, by: f64) -> Mesh {
    let n = mesh.positions.len() as f64;
    let c = [0, 1, 2].map(|k| mesh.positions.iter().map(|p| p[k] as f64).sum::<f64>() / n);
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            let d = [0, 1, 2].map(|k| p[k] as f64 - c[k]);
            let r = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            [0, 1, 2].map(|k| (c[k] + d[k] * (r + by) / r) as f32)
        })
        .collect();
    Mesh::new(positions, mesh.triangles.clone())
}

/// Each structure smoothed as a case does by default: Laplace+HC, bound at its tolerance.
fn smoothed(structures: &[Structure], tol: &[f64]) -> Vec<Mesh> {
    structures
        .iter()
        .zip(tol)
        .map(|(s, &bound)| {
            let params = Params {
                max_displacement: Some(bound as f32),
                ..Params::defaults(Filter::Hc)
            };
            let topology = Topology::build(&s.mesh);
            let positions = smooth(&s.mesh, &topology, &params, None, &mut NoObserver);
            Mesh::new(positions, s.mesh.triangles.clone())
        })
        .collect()
}

#[test]
fn phantom_tumour_lies_inside_the_liver_and_crosses_it_when_grown_by_3_mm() {
    let structures = open(
        "labelmaps/case_phantom_shared.nii.gz",
        Some("labelmaps/case_phantom_shared_labels.txt"),
    );
    let tol = tolerances(&structures);
    let (liver, tumour) = (index(&structures, "liver"), index(&structures, "tumor"));
    let mut meshes: Vec<&Mesh> = structures.iter().map(|s| &s.mesh).collect();
    let before = relations(&meshes, &tol);
    for r in &before {
        println!(
            "{} / {}: inside {} {}, depth {:.4} mm",
            structures[r.a].name, structures[r.b].name, r.a_inside_b, r.b_inside_a, r.overlap_depth
        );
    }
    assert!(inside(&before, tumour, liver), "{before:?}");
    assert!(!inside(&before, liver, tumour), "{before:?}");
    assert!(before.iter().all(|r| !r.crosses), "{before:?}");

    let grown = push_out(&structures[tumour].mesh, 3.0);
    meshes[tumour] = &grown;
    let after = relations(&meshes, &tol);
    let r = pair(&after, tumour, liver);
    println!("grown tumour / liver: {r:?}");
    assert!(r.crosses, "{r:?}");
    // Each vertex moved 3 mm off the cavity wall it lay on, so it is at most 3 mm deep.
    assert!(
        r.overlap_depth > 2.0 && r.overlap_depth <= 3.0 + 1e-3,
        "{r:?}"
    );
    let change = changes(&before, &after);
    println!("grown tumour: {change:?}");
    assert!(
        change
            .new_crossings
            .contains(&(liver.min(tumour), liver.max(tumour))),
        "{change:?}"
    );

    // Smoothed as a case does by default: reported, not asserted.
    let surfaces = smoothed(&structures, &tol);
    let smooth_relations = relations(&surfaces.iter().collect::<Vec<_>>(), &tol);
    println!(
        "smoothed: {:?}, tumour / liver {:?}",
        changes(&before, &smooth_relations),
        pair(&smooth_relations, tumour, liver)
    );
}

#[test]
fn jhu_atlas_relations_timing() {
    let structures = open("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz", None);
    let tol = tolerances(&structures);
    let vertices: usize = structures.iter().map(|s| s.mesh.positions.len()).sum();
    let meshes: Vec<&Mesh> = structures.iter().map(|s| &s.mesh).collect();
    let start = Instant::now();
    let before = relations(&meshes, &tol);
    let took = start.elapsed();
    let inside = before
        .iter()
        .filter(|r| r.a_inside_b || r.b_inside_a)
        .count();
    let deepest = before.iter().map(|r| r.overlap_depth).fold(0.0, f64::max);
    println!(
        "JHU: {} structures, {vertices} vertices, {} pairs near, {inside} with one inside, \
         deepest overlap {deepest:.2e} mm: {:.0} ms as extracted",
        structures.len(),
        before.len(),
        took.as_secs_f64() * 1e3
    );
    // Label-map neighbours share faces exactly: nothing reaches into another's material.
    assert!(deepest < 1e-3, "{before:?}");

    let surfaces = smoothed(&structures, &tol);
    let meshes: Vec<&Mesh> = surfaces.iter().collect();
    let start = Instant::now();
    let after = relations(&meshes, &tol);
    let took = start.elapsed();
    let change = changes(&before, &after);
    let deepest = after.iter().map(|r| r.overlap_depth).fold(0.0, f64::max);
    println!(
        "JHU smoothed: {} pairs near, {} cross, {} left inside, deepest overlap {deepest:.2} mm: \
         {:.0} ms",
        after.len(),
        change.new_crossings.len(),
        change.left_inside.len(),
        took.as_secs_f64() * 1e3
    );
}
