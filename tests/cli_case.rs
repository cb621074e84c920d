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
    // What the file states of how it was written rides beside each structure's record.
    let (read, files) = records_and_files(&info);
    assert!(files
        .iter()
        .all(|f| f["quantization"]["max_error_mm"].as_f64().is_some()));
    assert_eq!(read, built["structures"]);

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
    let (read_raw, files_raw) = records_and_files(&info_raw);
    assert_eq!(read_raw, read);
    assert!(files_raw.iter().all(|f| f["quantization"].is_null()));
}

/// `case info --json`'s structures without their `file` objects, and those objects.
fn records_and_files(info: &serde_json::Value) -> (serde_json::Value, Vec<serde_json::Value>) {
    let mut records = info["structures"].clone();
    let files = (records.as_array_mut().expect("structures").iter_mut())
        .map(|s| {
            s.as_object_mut()
                .expect("record")
                .remove("file")
                .expect("file")
        })
        .collect();
    (records, files)
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

/// `--simplify` writes a smaller case whose records state each structure's deviation, which
/// `case info` reads back; a distance that is no distance is refused.
#[test]
fn case_build_simplifies_within_a_distance_and_case_info_reads_it() {
    let (full, small) = (tmp("phantom_full.glb"), tmp("phantom_simplified.glb"));
    assert!(build_phantom(&full, &[]).status.success());
    let built = json(&build_phantom(&small, &["--simplify", "0.1", "--json"]));
    assert!(built["export_seconds"].as_f64().is_some());
    let size = |p: &std::path::Path| std::fs::metadata(p).expect("written").len();
    assert!(
        size(&small) < size(&full),
        "{} >= {}",
        size(&small),
        size(&full)
    );
    let info = json(&meshsmooth(&[
        "case",
        "info",
        small.to_str().expect("utf-8"),
        "--json",
    ]));
    let structures = info["structures"].as_array().expect("structures");
    assert_eq!(structures.len(), 4);
    for s in structures {
        let r = &s["file"]["simplification"];
        assert_eq!(r["simplified"], true, "{s}");
        let vd = r["max_deviation_voxel_diagonals"].as_f64().expect("stated");
        assert!(vd > 0.0 && vd <= 0.1, "{vd}");
    }
    for bad in ["0", "nan", "inf"] {
        let out = build_phantom(&tmp("never.glb"), &["--simplify", bad]);
        assert!(!out.status.success(), "--simplify {bad}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--simplify"));
    }
}
