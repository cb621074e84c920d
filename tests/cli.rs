//! The command-line contract: JSON keys, exit codes, messages on stderr.

use std::path::PathBuf;
use std::process::{Command, Output};

fn data(rel: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data")).join(rel)
}

fn meshsmooth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meshsmooth"))
        .args(args)
        .output()
        .expect("the meshsmooth binary runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("meshsmooth-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

#[test]
fn info_json_has_the_contract_keys() {
    let path = data("real/fsaverage_head_scalp_mne.ply");
    let v = json(&meshsmooth(&["info", path.to_str().unwrap(), "--json"]));
    for key in [
        "vertices",
        "faces",
        "unreferenced_vertices",
        "degenerate_faces",
        "duplicate_faces",
        "boundary_edges",
        "nonmanifold_edges",
        "nonmanifold_vertices",
        "components",
        "euler",
        "genus",
        "closed",
        "volume",
        "bbox_min",
        "bbox_max",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(v["vertices"], 2033);
    assert_eq!(v["faces"], 4062);
    assert_eq!(v["euler"], 2);
    assert_eq!(v["genus"], 0);
    assert_eq!(v["closed"], true);
    let volume = v["volume"].as_f64().unwrap();
    assert!(
        (volume - 5_142_590.0).abs() / 5_142_590.0 < 1e-6,
        "{volume}"
    );
}

#[test]
fn info_of_an_open_mesh_has_null_volume_and_genus() {
    let path = tmp("open.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let v = json(&meshsmooth(&["info", path.to_str().unwrap(), "--json"]));
    assert_eq!(v["closed"], false);
    assert!(v["volume"].is_null());
    assert!(v["genus"].is_null());
    assert_eq!(v["boundary_edges"], 3);
}

#[test]
fn errors_exit_non_zero_with_a_message_naming_the_file() {
    let path = tmp("broken.ply");
    std::fs::write(
        &path,
        b"ply\nformat binary_little_endian 1.0\nelement vertex 99999999999\n",
    )
    .unwrap();
    let out = meshsmooth(&["info", path.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("broken.ply"), "{err}");
    assert!(out.stdout.is_empty());

    let out = meshsmooth(&[
        "convert",
        data("real/fsaverage_head_scalp_mne.ply").to_str().unwrap(),
        "x.xyz",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains(".glb"));
}

#[test]
fn convert_keeps_vertex_order_through_every_format() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let original = json(&meshsmooth(&["info", input.to_str().unwrap(), "--json"]));
    for ext in ["ply", "stl", "obj", "glb"] {
        let out = tmp(&format!("tube.{ext}"));
        let run = meshsmooth(&["convert", input.to_str().unwrap(), out.to_str().unwrap()]);
        assert!(
            run.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let back = json(&meshsmooth(&["info", out.to_str().unwrap(), "--json"]));
        for key in [
            "vertices", "faces", "euler", "genus", "bbox_min", "bbox_max",
        ] {
            assert_eq!(back[key], original[key], "{ext}: {key}");
        }
        let (v0, v1) = (
            original["volume"].as_f64().unwrap(),
            back["volume"].as_f64().unwrap(),
        );
        assert!((v0 - v1).abs() <= 1e-9 * v0.abs(), "{ext}: {v0} vs {v1}");
    }
}
