//! `meshsmooth case build` and `case info`: the fixed pipeline for a whole segmentation.

#[path = "common/cli.rs"]
mod common_cli;

use common_cli::{json, meshsmooth, tmp};

fn data(rel: &str) -> String {
    common_cli::data(rel).display().to_string()
}

/// `case build` of the phantom with its colour table and the local search into `out`.
fn build_phantom(out: &std::path::Path, more: &[&str]) -> std::process::Output {
    let (map, table) = (
        data("labelmaps/case_phantom_shared.nii.gz"),
        data("labelmaps/case_phantom_shared_labels.txt"),
    );
    let mut args = vec![
        "case", "build", &map, "--colors", &table, "--search", "local",
    ];
    args.extend([
        "--title",
        "Abdominal phantom",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    args.extend(more);
    meshsmooth(&args)
}

#[test]
fn case_build_smooths_every_structure_and_case_info_reads_the_file_back() {
    let glb = tmp("phantom_case.glb");
    let out = build_phantom(&glb, &["--json"]);
    let built = json(&out);
    let list = built["structures"].as_array().expect("structures");
    assert_eq!(list.len(), 4);
    for s in list {
        assert_eq!(s["smoothed"], true, "{s}");
        assert_eq!(s["filter"], "hc");
        assert_eq!(s["source"], "case_phantom_shared.nii.gz");
        let bound = s["params"]["max_displacement"].as_f64().expect("bounded");
        let vd = s["voxel_diagonal_mm"].as_f64().expect("vd");
        assert!((bound - 0.5 * vd).abs() < 1e-6, "{s}");
        assert!(s["volume_change"].as_f64().expect("closed").abs() < 0.1);
    }
    assert_eq!(built["checks"]["left_inside"], serde_json::json!([]));
    assert_eq!(built["checks"]["new_crossings"], serde_json::json!([]));
    assert!(built["evaluations"].as_u64().expect("count") > 4);

    let info = json(&meshsmooth(&[
        "case",
        "info",
        glb.to_str().expect("utf-8"),
        "--json",
    ]));
    assert_eq!(info["title"], "Abdominal phantom");
    assert_eq!(info["structures"], built["structures"]);

    // A case glTF is an input like any other: built again from it, the structures are kept
    // and suggested again from their originals.
    let gltf = tmp("phantom_case.gltf");
    let again = json(&meshsmooth(&[
        "case",
        "build",
        glb.to_str().expect("utf-8"),
        "--search",
        "local",
        "-o",
        gltf.to_str().expect("utf-8"),
        "--json",
    ]));
    assert_eq!(again["title"], "Abdominal phantom");
    // The original comes back from the morph target quantized (the record states by how
    // much: about a thousandth of a millimetre here), which moves the measures of the
    // staircase by a few parts in ten thousand at most.
    for (a, b) in list
        .iter()
        .zip(again["structures"].as_array().expect("list"))
    {
        assert_eq!(a["name"], b["name"]);
        assert_eq!(a["params"], b["params"]);
        for key in ["volume0", "curvature0", "mean_error", "score"] {
            let (x, y) = (&a["metrics"][key], &b["metrics"][key]);
            let (x, y) = (x.as_f64().expect("n"), y.as_f64().expect("n"));
            assert!(
                (x - y).abs() <= 1e-3 * x.abs(),
                "{}: {key} {x} then {y}",
                a["name"]
            );
        }
    }
    let text = std::fs::read_to_string(&gltf).expect("a .gltf is JSON text");
    assert!(text.contains("data:application/octet-stream;base64,"));
    assert!(
        text.contains("\"EXT_meshopt_compression\""),
        "compressed by default"
    );

    // --uncompressed writes float arrays for tools that cannot decode; info reads both alike.
    let raw = tmp("phantom_case_raw.glb");
    build_phantom(&raw, &["--uncompressed"]);
    let bytes = std::fs::read(&raw).expect("written");
    assert!(!String::from_utf8_lossy(&bytes[..4096.min(bytes.len())]).contains("meshopt"));
    let compressed = std::fs::metadata(&glb).expect("written").len();
    assert!(
        compressed * 2 < bytes.len() as u64,
        "{compressed} vs {}",
        bytes.len()
    );
    let info_raw = json(&meshsmooth(&[
        "case",
        "info",
        raw.to_str().expect("utf-8"),
        "--json",
    ]));
    assert_eq!(info_raw["structures"], info["structures"]);
}

#[test]
fn case_build_refuses_what_it_cannot_do_naming_the_file() {
    let out = meshsmooth(&[
        "case",
        "build",
        &data("labelmaps/case_phantom_shared.nii.gz"),
        "-o",
        tmp("case.stl").to_str().expect("utf-8"),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("case.stl"));
    let broken = tmp("broken.nii.gz");
    std::fs::write(&broken, b"\x1f\x8b not really gzip").expect("write");
    let out = meshsmooth(&[
        "case",
        "build",
        broken.to_str().expect("utf-8"),
        "-o",
        tmp("x.glb").to_str().expect("utf-8"),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken.nii.gz"));
    let out = meshsmooth(&["case", "info", broken.to_str().expect("utf-8")]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken.nii.gz"));
}
