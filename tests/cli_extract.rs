//! `meshsmooth extract` and `info` on label maps: what they write and print, and their refusals.

#[path = "common/cli.rs"]
mod common_cli;

use common_cli::{json, meshsmooth, tmp};

/// A path below ../shared/data, as an argument.
fn data(rel: &str) -> String {
    common_cli::data(rel).display().to_string()
}

/// The JSON chunk of a GLB.
fn glb_json(bytes: &[u8]) -> serde_json::Value {
    assert_eq!(&bytes[..4], b"glTF");
    let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
    serde_json::from_slice(&bytes[20..20 + len]).expect("JSON chunk")
}

#[test]
fn extract_writes_one_named_ply_per_structure_and_lists_them() {
    let dir = tmp("phantom/");
    let out = meshsmooth(&[
        "extract",
        &data("labelmaps/case_phantom_shared.nii.gz"),
        "--colors",
        &data("labelmaps/case_phantom_shared_labels.txt"),
        "-o",
        dir.to_str().expect("utf-8"),
        "--json",
    ]);
    let v = json(&out);
    let list = v["structures"].as_array().expect("structures");
    assert_eq!(list.len(), 4);
    let keys = [
        "label",
        "name",
        "color",
        "voxels",
        "vertices",
        "triangles",
        "volume",
        "voxel_size",
        "file",
    ];
    for s in list {
        for key in keys {
            assert!(s.get(key).is_some(), "missing {key}");
        }
        let file = s["file"].as_str().expect("a path");
        let info = json(&meshsmooth(&["info", file, "--json"]));
        assert_eq!(info["vertices"], s["vertices"]);
        assert_eq!(info["closed"], true);
        assert_eq!(info["nonmanifold_edges"], 0);
    }
    assert_eq!(list[1]["name"], "portal_vein");
    assert!(list[1]["file"]
        .as_str()
        .expect("path")
        .ends_with("portal_vein.ply"));
    assert_eq!(list[0]["voxels"], 81887);
}

#[test]
fn extract_to_glb_gives_a_named_node_per_structure_in_metres_with_y_up() {
    let path = tmp("phantom.glb");
    let p = path.to_str().expect("utf-8");
    let out = meshsmooth(&[
        "extract",
        &data("labelmaps/case_phantom_shared.seg.nrrd"),
        "--labels",
        "1,3",
        "-o",
        p,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = glb_json(&std::fs::read(&path).expect("written"));
    let names: Vec<&str> = doc["nodes"]
        .as_array()
        .expect("nodes")
        .iter()
        .filter_map(|n| n["name"].as_str())
        .collect();
    assert_eq!(names, ["case", "liver", "tumor"]);
    assert_eq!(doc["nodes"][0]["matrix"][0], -0.001);
    assert_eq!(doc["materials"].as_array().expect("materials").len(), 2);
    assert_eq!(doc["nodes"][2]["extras"]["meshsmooth"]["label"], 3);
    let required = &doc["extensionsRequired"];
    assert!(
        required.to_string().contains("EXT_meshopt_compression"),
        "{required}"
    );
    // Millimetres when asked: no root transform; float arrays when asked.
    let raw = tmp("phantom_mm.glb");
    let out = meshsmooth(&[
        "extract",
        &data("labelmaps/case_phantom_shared.seg.nrrd"),
        "--millimetres",
        "--uncompressed",
        "-o",
        raw.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success());
    let doc = glb_json(&std::fs::read(&raw).expect("written"));
    assert!(doc["nodes"][0].get("matrix").is_none());
    assert!(doc.get("extensionsRequired").is_none());
    assert_eq!(doc["nodes"].as_array().expect("nodes").len(), 5);
}

#[test]
fn info_on_a_label_map_lists_its_structures() {
    let v = json(&meshsmooth(&[
        "info",
        &data("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz"),
        "--json",
    ]));
    assert_eq!(v["dims"], serde_json::json!([182, 218, 182]));
    let list = v["structures"].as_array().expect("structures");
    assert_eq!(list.len(), 48);
    assert_eq!(list[0]["label"], 1);
    assert!(list[0]["voxels"].as_u64().expect("count") > 0);
    let text = meshsmooth(&["info", &data("labelmaps/case_phantom_shared.seg.nrrd")]);
    let text = String::from_utf8(text.stdout).expect("utf-8");
    assert!(
        text.contains("tumor") && text.contains("structures             4"),
        "{text}"
    );
}

#[test]
fn extract_refuses_what_it_cannot_do_naming_the_file() {
    let map = data("labelmaps/case_phantom_shared.nii.gz");
    let refusal = |args: &[&str]| {
        let out = meshsmooth(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let e = refusal(&["extract", &map, "-o", tmp("x.stl").to_str().expect("utf-8")]);
    assert!(e.contains("give a folder"), "{e}");
    let e = refusal(&[
        "extract",
        &map,
        "--labels",
        "9",
        "-o",
        tmp("x.glb").to_str().expect("utf-8"),
    ]);
    assert!(
        e.contains("label 9 is not in the label map") && e.contains("case_phantom_shared.nii.gz"),
        "{e}"
    );
    let broken = tmp("broken.nii.gz");
    let bytes = std::fs::read(&map).expect("phantom");
    std::fs::write(&broken, &bytes[..bytes.len() / 3]).expect("write");
    let e = refusal(&[
        "extract",
        broken.to_str().expect("utf-8"),
        "-o",
        tmp("y/").to_str().expect("utf-8"),
    ]);
    assert!(e.contains("broken.nii.gz"), "{e}");
    let sphere = data("synthetic/sphere_r20_mask.nii.gz");
    let e = refusal(&[
        "extract",
        &map,
        &sphere,
        "--labels",
        "1",
        "-o",
        tmp("z/").to_str().expect("utf-8"),
    ]);
    assert!(e.contains("several mask files"), "{e}");
}

/// A folder given as input opens its files and its subfolders' (hidden files and a DICOMDIR
/// left out) in the order of their paths, as the page opens a dropped folder; a colour table
/// in it names the label map beside it; subfolders nested past the limit are refused.
#[test]
fn extract_reads_a_folder_with_its_subfolders() {
    let masks = tmp("masks");
    let _ = std::fs::remove_dir_all(&masks);
    std::fs::create_dir_all(masks.join("ring")).expect("a temporary folder");
    let placed = [
        ("sphere_r20_mask.nii.gz", "sphere_r20_mask.nii.gz"),
        (
            "ellipsoid_30_20_12_mask.nii.gz",
            "ellipsoid_30_20_12_mask.nii.gz",
        ),
        ("torus_R24_r8_mask.nii.gz", "ring/torus_R24_r8_mask.nii.gz"),
    ];
    for (file, at) in placed {
        let from = common_cli::data(&format!("synthetic/{file}"));
        std::fs::copy(from, masks.join(at)).expect("a copy");
    }
    std::fs::write(masks.join(".DS_Store"), b"Bud1").expect("a file");
    std::fs::write(masks.join("ring/DICOMDIR"), b"an index").expect("a file");
    let extract = |inputs: &[String], out: &str| {
        let mut args = vec!["extract"];
        args.extend(inputs.iter().map(String::as_str));
        let out = tmp(out).display().to_string();
        json(&meshsmooth(&[&args[..], &["-o", &out, "--json"]].concat()))
    };
    let from_folder = extract(&[masks.display().to_string()], "from_folder/");
    let in_order = [
        "ellipsoid_30_20_12_mask.nii.gz",
        "ring/torus_R24_r8_mask.nii.gz",
    ];
    let files: Vec<String> = (in_order.iter().chain(["sphere_r20_mask.nii.gz"].iter()))
        .map(|at| masks.join(at).display().to_string())
        .collect();
    let from_files = extract(&files, "from_files/");
    let summary = |v: &serde_json::Value| -> Vec<(serde_json::Value, serde_json::Value)> {
        (v["structures"].as_array().expect("structures").iter())
            .map(|s| (s["name"].clone(), s["vertices"].clone()))
            .collect()
    };
    assert_eq!(summary(&from_folder).len(), 3);
    assert_eq!(summary(&from_folder), summary(&from_files));
    assert_eq!(from_folder["structures"][1]["name"], "Torus R24 r8 mask");

    let labelled = tmp("labelled");
    std::fs::create_dir_all(&labelled).expect("a temporary folder");
    for file in [
        "case_phantom_shared.nii.gz",
        "case_phantom_shared_labels.txt",
    ] {
        let from = common_cli::data(&format!("labelmaps/{file}"));
        std::fs::copy(from, labelled.join(file)).expect("a copy");
    }
    let named = extract(&[labelled.display().to_string()], "labelled_out/");
    assert_eq!(named["structures"][1]["name"], "portal_vein");

    let deep = tmp("deep");
    let deepest = deep.join("1/2/3/4/5/6/7/8/9");
    std::fs::create_dir_all(&deepest).expect("a temporary folder");
    std::fs::write(deepest.join("mask.nii.gz"), b"never read").expect("a file");
    let deep_out = tmp("deep_out/").display().to_string();
    let out = meshsmooth(&["extract", &deep.display().to_string(), "-o", &deep_out]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("deep: its subfolders go more than 8 levels down"),
        "{stderr}"
    );
}
