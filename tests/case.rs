//! Cases: opening a segmentation as a case, the case glTF and reading it back.

use meshsmooth::case::{self, from_gltf_scene, smooth_structure, Case};
use meshsmooth::export::{write_case, CaseGltfOptions, Container, SceneFrame};
use meshsmooth::io::load_gltf_scene;
use meshsmooth::smooth::Filter;
use serde_json::Value;

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::phantom_case as phantom;

#[path = "common/glb.rs"]
mod glb;

#[path = "common/vertex_match.rs"]
mod vertex_match;

use vertex_match::{match_vertices, triangles_as_written, triangles_sorted};

fn glb_json(bytes: &[u8]) -> Value {
    let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
    serde_json::from_slice(&bytes[20..20 + len]).expect("JSON")
}

#[test]
fn label_map_structures_are_bounded_at_half_their_voxel_diagonal() {
    let case = phantom();
    let names: Vec<&str> = case.structures.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["liver", "portal_vein", "tumor", "right_kidney"]);
    for s in &case.structures {
        let d = s
            .voxel_diagonal()
            .expect("a label-map structure knows its voxels");
        assert!((d - (0.78f64.powi(2) * 2.0 + 2.5f64.powi(2)).sqrt()).abs() < 1e-9);
        assert_eq!(s.params.max_displacement, Some((0.5 * d) as f32));
        assert_eq!(s.params.filter, Filter::Hc);
        // Only the file's name is kept, never its folder.
        assert_eq!(s.source.as_deref(), Some("case_phantom_shared.nii.gz"));
        assert!(s.smoothed.is_none());
    }
}

/// Export, reopen, export again: the same bytes, so the same names, colours, groups,
/// parameters, measures and positions; and the reopened case's originals are the staircase.
#[test]
fn a_case_glb_reads_back_as_the_same_case() {
    let mut case = phantom();
    case.title = "Abdominal phantom".into();
    case.description = "Liver with a tumour, portal vein, right kidney".into();
    case.structures[1].group = Some("Vessels".into());
    case.structures[0].color[3] = 0.4;
    case.structures[3].visible = false;
    case.structures[2].params.iterations = 7;
    for s in case.structures.iter_mut().take(3) {
        smooth_structure(s);
    }
    for container in [Container::Glb, Container::Gltf] {
        // Float arrays as they are: exact. The compressed default is checked below.
        let options = CaseGltfOptions {
            container,
            local_error: true,
            compressed: false,
            ..Default::default()
        };
        let first = write_case(&case, &options).expect("writes");
        let name = match container {
            Container::Glb => "case.glb",
            Container::Gltf => "case.gltf",
        };
        let scene = load_gltf_scene(&first, name).expect("reads");
        let back = from_gltf_scene(scene, name).expect("a case");
        assert_eq!(back.title, case.title);
        assert_eq!(back.description, case.description);
        assert_eq!(back.structures.len(), case.structures.len());
        for (a, b) in case.structures.iter().zip(&back.structures) {
            assert_eq!(a.name, b.name);
            assert_eq!(a.color, b.color, "{}", a.name);
            assert_eq!(a.group, b.group);
            assert_eq!(a.visible, b.visible);
            assert_eq!(a.params.to_json(), b.params.to_json());
            assert_eq!(a.voxel_size, b.voxel_size);
            assert_eq!(
                a.original, b.original,
                "{}: the original comes back exactly",
                a.name
            );
            assert_eq!(a.positions(), b.positions(), "{}", a.name);
            assert!(
                a.closed_outward() && b.closed_outward(),
                "{}: the viewer draws only its front faces",
                a.name
            );
            assert_eq!(
                a.smoothed.as_ref().map(|s| &s.metrics),
                b.smoothed.as_ref().map(|s| &s.metrics)
            );
        }
        let again = write_case(&back, &options).expect("writes again");
        assert!(
            first == again,
            "{name}: the second export differs from the first"
        );
    }
}

/// The compressed default: what reopens is the case within the quantization error each
/// structure's record states (far below 0.05 voxel diagonals), and quantizing it again changes
/// no position.
#[test]
fn a_compressed_case_reads_back_within_its_stated_quantization_error() {
    let mut case = phantom();
    case.structures[1].group = Some("Vessels".into());
    case.structures[0].color[3] = 0.4;
    for s in case.structures.iter_mut().take(3) {
        smooth_structure(s);
    }
    let options = CaseGltfOptions {
        local_error: true,
        ..Default::default()
    };
    let first = write_case(&case, &options).expect("writes");
    let raw = CaseGltfOptions {
        compressed: false,
        ..options
    };
    let uncompressed = write_case(&case, &raw).expect("writes");
    assert!(
        first.len() * 2 < uncompressed.len(),
        "compressed {} bytes, uncompressed {}",
        first.len(),
        uncompressed.len()
    );
    let doc = glb_json(&first);
    let snapped = from_gltf_scene(load_gltf_scene(&first, "case.glb").expect("reads"), "c.glb")
        .expect("a case");
    // Read without the voxel grid, the originals stay where the file put them.
    let mut unsnapped = doc.clone();
    for n in unsnapped["nodes"].as_array_mut().expect("nodes") {
        if let Some(r) = n
            .pointer_mut("/extras/meshsmooth")
            .and_then(Value::as_object_mut)
        {
            r.remove("voxel_to_world");
        }
    }
    let bin_at = 20 + u32::from_le_bytes(first[12..16].try_into().expect("4")) as usize;
    let bin = &first[bin_at + 8..];
    let back = from_gltf_scene(
        load_gltf_scene(&glb::glb(&unsnapped, bin), "case.glb").expect("reads"),
        "c.glb",
    )
    .expect("a case");
    assert_eq!(back.structures.len(), case.structures.len());
    let far = |a: &[[f32; 3]], b: &[[f32; 3]], m: &[usize]| {
        (b.iter().enumerate())
            .map(|(i, q)| {
                let p = a[m[i]];
                (0..3)
                    .map(|k| f64::from(p[k] - q[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max)
    };
    for (a, b) in case.structures.iter().zip(&back.structures) {
        let node = (doc["nodes"].as_array().expect("nodes").iter())
            .find(|n| n["name"] == a.name.as_str())
            .expect("a node per structure");
        let q = &node["extras"]["meshsmooth"]["quantization"];
        let stated = q["max_error_mm"].as_f64().expect("stated in mm");
        let diagonal = a.voxel_diagonal().expect("a label map's structure");
        assert_eq!(
            q["max_error_voxel_diagonals"].as_f64(),
            Some(stated / diagonal)
        );
        assert!(
            stated < 0.05 * diagonal && stated > 0.0,
            "{}: {stated} mm",
            a.name
        );
        // Vertices come back in the codecs' order: the staircase says which is which.
        let m = match_vertices(&a.original.positions, &b.original.positions, stated * 1.001);
        let moved = far(a.positions(), b.positions(), &m).max(far(
            &a.original.positions,
            &b.original.positions,
            &m,
        ));
        // The record states the largest of these exactly.
        assert_eq!(moved, stated, "{}", a.name);
        assert_eq!(
            triangles_sorted(&a.original.triangles),
            triangles_as_written(&b.original.triangles, &m),
            "{}",
            a.name
        );
        assert_eq!((&a.name, a.color, &a.group), (&b.name, b.color, &b.group));
        assert_eq!(
            a.smoothed.as_ref().map(|s| &s.metrics),
            b.smoothed.as_ref().map(|s| &s.metrics)
        );
        let errors = |s: &meshsmooth::case::CaseStructure| {
            s.smoothed.as_ref().and_then(|s| s.local_error.clone())
        };
        let reordered = errors(b).map(|e| {
            let mut out = vec![0.0; e.len()];
            for (i, v) in e.into_iter().enumerate() {
                out[m[i]] = v;
            }
            out
        });
        assert_eq!(errors(a), reordered, "{}", a.name);
    }
    // With it, each staircase comes back exactly where extraction placed it.
    for (a, b) in case.structures.iter().zip(&snapped.structures) {
        let m = match_vertices(&a.original.positions, &b.original.positions, 1e-3);
        assert_eq!(
            far(&a.original.positions, &b.original.positions, &m),
            0.0,
            "{}",
            a.name
        );
        assert_eq!(b.grid, a.grid);
    }
    let again = write_case(&back, &options).expect("writes again");
    let twice = from_gltf_scene(
        load_gltf_scene(&again, "again.glb").expect("reads"),
        "again.glb",
    )
    .expect("a case");
    for (b, c) in back.structures.iter().zip(&twice.structures) {
        // Lattice points quantized again are the same points, exactly.
        let m = match_vertices(&b.original.positions, &c.original.positions, 0.0);
        assert_eq!(
            far(b.positions(), c.positions(), &m),
            0.0,
            "{}: quantized again",
            b.name
        );
        assert_eq!(
            triangles_sorted(&b.original.triangles),
            triangles_as_written(&c.original.triangles, &m),
            "{}",
            b.name
        );
    }
}

#[test]
fn the_case_glb_has_groups_materials_and_the_quality_record() {
    let mut case = phantom();
    case.structures[1].group = Some("Vessels".into());
    case.structures[2].color[3] = 0.5;
    smooth_structure(&mut case.structures[2]);
    let options = CaseGltfOptions {
        unlit: true,
        local_error: true,
        ..Default::default()
    };
    let doc = glb_json(&write_case(&case, &options).expect("writes"));
    let nodes = doc["nodes"].as_array().expect("nodes");
    let root = &nodes[0];
    assert_eq!(root["matrix"][6], 0.001, "anterior goes to +Z");
    let group = nodes
        .iter()
        .find(|n| n["name"] == "Vessels")
        .expect("a group node");
    let vein = &nodes[group["children"][0].as_u64().expect("child") as usize];
    assert_eq!(vein["name"], "portal_vein");
    let tumour = nodes.iter().find(|n| n["name"] == "tumor").expect("tumour");
    let record = &tumour["extras"]["meshsmooth"];
    assert_eq!(record["filter"], "hc");
    assert_eq!(record["source"], "case_phantom_shared.nii.gz");
    assert_eq!(record["smoothed"], true);
    let vd = record["voxel_diagonal_mm"].as_f64().expect("vd");
    let mean = record["mean_error_mm"].as_f64().expect("mm");
    let in_vd = record["mean_error_voxel_diagonals"].as_f64().expect("vd");
    assert!((mean / vd - in_vd).abs() < 1e-12);
    let mesh = &doc["meshes"][tumour["mesh"].as_u64().expect("mesh") as usize];
    let primitive = &mesh["primitives"][0];
    assert!(primitive["attributes"]["_LOCAL_ERROR"].is_u64());
    assert_eq!(mesh["weights"], serde_json::json!([0.0]));
    assert!(primitive["targets"][0]["POSITION"].is_u64());
    let material = &doc["materials"][primitive["material"].as_u64().expect("m") as usize];
    assert_eq!(material["alphaMode"], "BLEND");
    assert!(material["extensions"]["KHR_materials_unlit"].is_object());
    assert_eq!(
        doc["extensionsUsed"],
        serde_json::json!([
            "EXT_meshopt_compression",
            "KHR_mesh_quantization",
            "KHR_materials_unlit"
        ])
    );
    assert_eq!(
        doc["extensionsRequired"],
        serde_json::json!(["EXT_meshopt_compression", "KHR_mesh_quantization"])
    );
    // An unsmoothed structure has no morph target to slide to.
    let liver = nodes.iter().find(|n| n["name"] == "liver").expect("liver");
    let liver_mesh = &doc["meshes"][liver["mesh"].as_u64().expect("mesh") as usize];
    assert!(liver_mesh["primitives"][0].get("targets").is_none());
    let raw = CaseGltfOptions {
        frame: SceneFrame::Millimetres,
        ..Default::default()
    };
    let doc = glb_json(&write_case(&case, &raw).expect("writes"));
    assert!(doc["nodes"][0].get("matrix").is_none());
    assert_eq!(
        doc["scenes"][0]["extras"]["meshsmooth"]["frame"],
        "millimetres"
    );
}

/// A glTF from elsewhere opens as a structure per placed mesh, named by its node.
#[test]
fn any_gltf_opens_as_a_case_of_its_nodes() {
    let mesh = |dx: f32| {
        meshsmooth::mesh::Mesh::new(
            vec![
                [dx, 0.0, 0.0],
                [dx + 1.0, 0.0, 0.0],
                [dx, 1.0, 0.0],
                [dx, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    };
    let mut case = Case::default();
    case.structures.push(case::CaseStructure::from_mesh(
        "a",
        mesh(0.0),
        [1.0, 0.0, 0.0],
    ));
    case.structures.push(case::CaseStructure::from_mesh(
        "b",
        mesh(5.0),
        [0.0, 1.0, 0.0],
    ));
    let bytes = write_case(&case, &CaseGltfOptions::default()).expect("writes");
    let mut doc = glb_json(&bytes);
    // Strip our record: what is left is any glTF with two named nodes under a root.
    doc["scenes"][0]
        .as_object_mut()
        .expect("scene")
        .remove("extras");
    for n in doc["nodes"].as_array_mut().expect("nodes") {
        n.as_object_mut().expect("node").remove("extras");
    }
    let bin_at = 20 + u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
    let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().expect("4")) as usize;
    let bin = &bytes[bin_at + 8..bin_at + 8 + bin_len];
    use base64::Engine as _;
    doc["buffers"][0]["uri"] = Value::String(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bin)
    ));
    let text = serde_json::to_vec(&doc).expect("JSON");
    let scene = load_gltf_scene(&text, "other.gltf").expect("reads");
    let back = from_gltf_scene(scene, "other.gltf").expect("a case");
    let names: Vec<&str> = back.structures.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["a", "b"]);
    // Placed by the root's transform: metres, +Y up, as any glTF is read.
    let points = &back.structures[1].original.positions;
    let near = |p: &[f32; 3], q: [f32; 3]| (0..3).all(|k| (p[k] - q[k]).abs() < 1e-7);
    assert!(
        points.iter().any(|p| near(p, [-0.006, 0.0, 0.0])),
        "{points:?}"
    );
    assert!(back.structures.iter().all(|s| s.smoothed.is_none()));
    let green = back.structures[1].color;
    assert!((green[1] - 1.0).abs() < 1e-6 && green[0].abs() < 1e-6);
}
