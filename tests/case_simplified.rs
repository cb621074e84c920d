//! The simplified case glTF: each structure within the distance the author chose of its
//! smoothed surface, still closed and manifold, the tumour still inside the liver, and each
//! record's stated deviation the one measured again from the file.

use meshsmooth::case::{self, from_gltf_scene, smooth_structure, Case};
use meshsmooth::export::{write_case, CaseGltfOptions, Simplification};
use meshsmooth::io::load_gltf_scene;
use meshsmooth::mesh::{Mesh, MeshReport, Topology};
use serde_json::Value;

#[path = "common/label_maps.rs"]
mod label_maps;

#[path = "common/surface_deviation.rs"]
mod surface_deviation;

use surface_deviation::measured;

fn smoothed_phantom() -> Case {
    let structures = label_maps::open(
        "labelmaps/case_phantom_shared.nii.gz",
        Some("labelmaps/case_phantom_shared_labels.txt"),
    );
    let mut case = Case::from_label_map(structures, Some("case_phantom_shared.nii.gz"));
    for s in &mut case.structures {
        smooth_structure(s);
    }
    case
}

#[test]
fn a_simplified_case_keeps_its_structures_closed_nested_and_within_the_distance() {
    let case = smoothed_phantom();
    let vd = 0.1;
    let options = CaseGltfOptions {
        simplify: Some(Simplification::VoxelDiagonals(vd)),
        compressed: false,
        ..Default::default()
    };
    let bytes = write_case(&case, &options).expect("writes");
    let full = write_case(&case, &CaseGltfOptions::default()).expect("writes");
    let scene = load_gltf_scene(&bytes, "simplified.glb").expect("reads");
    let records: Vec<Value> = (scene.nodes.iter())
        .map(|n| n.extras.as_ref().expect("a record")["meshsmooth"]["simplification"].clone())
        .collect();
    let back = from_gltf_scene(scene, "simplified.glb").expect("a case");
    let mut before = 0;
    let mut after = 0;
    for ((a, b), r) in case.structures.iter().zip(&back.structures).zip(&records) {
        assert_eq!(r["simplified"], true, "{}: {r}", a.name);
        assert_eq!(r["goal"]["voxel_diagonals"], vd);
        let stated = r["max_deviation_mm"].as_f64().expect("mm");
        let diagonal = a.voxel_diagonal().expect("voxels");
        assert!(
            stated > 0.0 && stated <= vd * diagonal,
            "{}: {stated} mm",
            a.name
        );
        assert_eq!(r["triangles"], b.original.triangle_count());
        assert_eq!(r["triangles_before"], a.original.triangle_count());
        before += a.original.triangle_count();
        after += b.original.triangle_count();

        let smoothed = Mesh::new(a.positions().to_vec(), a.original.triangles.clone());
        let simplified = Mesh::new(b.positions().to_vec(), b.original.triangles.clone());
        let again = measured(&smoothed, &simplified);
        assert!(
            (again - stated).abs() <= 0.01 * stated,
            "{}: stated {stated} mm, measured {again} mm",
            a.name
        );
        let report = MeshReport::new(&simplified, &Topology::build(&simplified));
        let was = MeshReport::new(&smoothed, &Topology::build(&smoothed));
        assert!(report.closed && report.boundary_edges == 0, "{}", a.name);
        assert_eq!(
            (
                report.nonmanifold_edges,
                report.nonmanifold_vertices,
                report.degenerate_faces
            ),
            (0, 0, 0),
            "{}",
            a.name
        );
        assert_eq!(
            (report.components, report.genus),
            (was.components, was.genus)
        );
    }
    assert!(2 * after < before, "{before} triangles, {after} simplified");

    // Compressed, smaller than the full case, each kept vertex's original riding along: a
    // vertex of the staircase (exactly, once snapped to the voxel grid).
    let compressed = CaseGltfOptions {
        compressed: true,
        ..options
    };
    let small = write_case(&case, &compressed).expect("writes");
    assert!(
        small.len() < full.len(),
        "{} bytes simplified, {} not",
        small.len(),
        full.len()
    );
    let reopened =
        from_gltf_scene(load_gltf_scene(&small, "s.glb").expect("reads"), "s.glb").expect("a case");
    for (a, b) in case.structures.iter().zip(&reopened.structures) {
        let staircase: std::collections::HashSet<[u32; 3]> = (a.original.positions.iter())
            .map(|p| p.map(f32::to_bits))
            .collect();
        let on = |p: &[f32; 3]| staircase.contains(&p.map(f32::to_bits));
        assert!(b.original.positions.iter().all(on), "{}", a.name);
    }

    // The tumour still lies inside the liver, and no structure crosses another.
    let relations = case::check(&back, true);
    let names: Vec<&str> = back.structures.iter().map(|s| s.name.as_str()).collect();
    let (liver, tumour) = (
        names.iter().position(|n| *n == "liver").expect("liver"),
        names
            .iter()
            .position(|n| n.starts_with("tumo"))
            .expect("tumour"),
    );
    let pair = relations
        .iter()
        .find(|r| (r.a, r.b) == (liver.min(tumour), liver.max(tumour)))
        .expect("the liver and the tumour meet");
    assert!(if liver < tumour {
        pair.b_inside_a
    } else {
        pair.a_inside_b
    });
    let changes = case::relations::changes(&case::check(&case, true), &relations);
    label_maps::assert_relations_kept(&changes);
}

#[test]
fn a_triangle_budget_shares_the_case_between_its_structures() {
    let case = smoothed_phantom();
    let total: usize = case
        .structures
        .iter()
        .map(|s| s.original.triangle_count())
        .sum();
    let budget = total / 5;
    let options = CaseGltfOptions {
        simplify: Some(Simplification::TriangleBudget(budget)),
        ..Default::default()
    };
    let bytes = write_case(&case, &options).expect("writes");
    let back =
        from_gltf_scene(load_gltf_scene(&bytes, "b.glb").expect("reads"), "b.glb").expect("a case");
    let written: usize = back
        .structures
        .iter()
        .map(|s| s.original.triangle_count())
        .sum();
    assert!(
        written <= budget + budget / 10,
        "{written} triangles for a budget of {budget}"
    );
    for (a, b) in case.structures.iter().zip(&back.structures) {
        assert!(
            b.original.triangle_count() < a.original.triangle_count(),
            "{}",
            a.name
        );
    }
}
