//! The command-line contract: JSON keys, exit codes, messages on stderr.

#[path = "common/cli.rs"]
mod common_cli;

use common_cli::{data, json, meshsmooth, tmp};

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
fn an_output_that_cannot_be_written_is_refused_and_what_was_there_is_kept() {
    let input = data("synthetic/synthetic_sphere_r20.ply");
    let input = input.to_str().unwrap();
    let missing = tmp("no such folder/out.ply");
    let out = meshsmooth(&["smooth", input, "-o", missing.to_str().unwrap(), "--auto"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("does not exist"), "{err}");
    let plot = tmp("no such folder/graphs.png");
    let out = meshsmooth(&["sweep", input, "--plot", plot.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));

    // A file the user protected stays as it was; a writable one is replaced whole, no
    // temporary file left beside it.
    // A folder of its own: other tests write beside each other at the same time.
    let kept = tmp("protected").join("model.ply");
    std::fs::create_dir_all(kept.parent().unwrap()).unwrap();
    std::fs::write(&kept, b"the user's model").unwrap();
    let mut permissions = std::fs::metadata(&kept).unwrap().permissions();
    permissions.set_readonly(true);
    std::fs::set_permissions(&kept, permissions.clone()).unwrap();
    let out = meshsmooth(&["smooth", input, "-o", kept.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("read-only"));
    assert_eq!(std::fs::read(&kept).unwrap(), b"the user's model");
    #[allow(clippy::permissions_set_readonly_false)]
    permissions.set_readonly(false);
    std::fs::set_permissions(&kept, permissions).unwrap();
    json(&meshsmooth(&[
        "smooth",
        input,
        "-o",
        kept.to_str().unwrap(),
        "--json",
    ]));
    assert!(meshsmooth_load(&kept) > 0);
    let litter: Vec<_> = std::fs::read_dir(kept.parent().unwrap())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(litter.is_empty(), "{litter:?}");
}

/// The vertex count `meshsmooth info` reads from `path`.
fn meshsmooth_load(path: &std::path::Path) -> u64 {
    json(&meshsmooth(&["info", path.to_str().unwrap(), "--json"]))["vertices"]
        .as_u64()
        .unwrap()
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

const MEASURE_KEYS: [&str; 8] = [
    "volume",
    "volume0",
    "volume_change",
    "curvature",
    "curvature0",
    "mean_error",
    "max_error",
    "score",
];

#[test]
fn smooth_writes_the_mesh_and_measure_agrees_with_it() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let out = tmp("tube_hc.ply");
    let v = json(&meshsmooth(&[
        "smooth",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--filter",
        "hc",
        "--iterations",
        "12",
        "--json",
    ]));
    assert_eq!(v["filter"], "hc");
    assert_eq!(v["params"]["iterations"], 12);
    assert_eq!(v["params"]["alpha"], 0.1);
    assert!(v["seconds"].as_f64().unwrap() >= 0.0);
    for key in MEASURE_KEYS {
        assert!(v["metrics"].get(key).is_some(), "missing metrics.{key}");
    }
    let m = &v["metrics"];
    assert!(m["curvature"].as_f64().unwrap() < m["curvature0"].as_f64().unwrap());
    assert!(m["mean_error"].as_f64().unwrap() > 0.0);

    // The written file is the smoothed mesh: measuring it again gives the same volume and
    // curvature, and a local error close to the one tracked during smoothing.
    let again = json(&meshsmooth(&[
        "measure",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--exact",
        "--json",
    ]));
    for key in MEASURE_KEYS {
        assert!(again.get(key).is_some(), "missing {key}");
    }
    let close = |a: &serde_json::Value, b: &serde_json::Value, tol: f64| {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        (a - b).abs() <= tol * a.abs().max(b.abs())
    };
    assert!(close(&again["volume"], &m["volume"], 1e-9));
    assert!(close(&again["curvature"], &m["curvature"], 1e-9));
    assert!(close(&again["mean_error"], &m["mean_error"], 0.05));
    let exact = again["exact_mean_error"].as_f64().unwrap();
    assert!(again["mean_error"].as_f64().unwrap() >= exact - 1e-6);
}

#[test]
fn measure_of_a_mesh_against_itself_is_zero_error() {
    let input = data("real/fsaverage_head_scalp_mne.stl");
    let p = input.to_str().unwrap();
    let v = json(&meshsmooth(&["measure", p, p, "--json"]));
    assert_eq!(v["mean_error"], 0.0);
    assert_eq!(v["max_error"], 0.0);
    assert_eq!(v["volume_change"], 0.0);
    assert!(v.get("exact_mean_error").is_none());
}

#[test]
fn measure_refuses_different_meshes_and_out_of_range_parameters_are_refused() {
    let a = data("real/fsaverage_head_scalp_mne.ply");
    let b = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let out = meshsmooth(&["measure", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not the same mesh"));

    let o = tmp("never.ply");
    for (flags, expect) in [
        (vec!["--filter", "taubin", "--mu", "-0.3"], "mu < -lambda"),
        (vec!["--filter", "laplace", "--lambda", "1.5"], "[0, 1]"),
        (vec!["--filter", "sinc", "--iterations", "0"], "[1, 100]"),
        (vec!["--filter", "gauss"], "laplace, taubin, hc or sinc"),
        (vec!["--tau", "2"], "tau"),
    ] {
        let mut args = vec!["smooth", a.to_str().unwrap(), "-o", o.to_str().unwrap()];
        args.extend(flags);
        let out = meshsmooth(&args);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{err}");
        assert!(!o.exists(), "nothing is written on a refused run");
    }
}

#[test]
fn bench_json_has_the_contract_keys() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let v = json(&meshsmooth(&[
        "bench",
        input.to_str().unwrap(),
        "--filter",
        "laplace",
        "--iterations",
        "5",
        "--repeat",
        "1",
        "--json",
    ]));
    for key in [
        "filter",
        "vertices",
        "iterations",
        "seconds",
        "vertex_iterations_per_second",
        "measure_seconds",
        "backend",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["backend"], "cpu");
    assert_eq!(v["vertices"], 2296);
    assert!(v["vertex_iterations_per_second"].as_f64().unwrap() > 0.0);
}

#[test]
fn smooth_auto_takes_the_suggestion_and_tau_zero_leaves_the_mesh() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let out = tmp("tube_auto.ply");
    let run = |tau: &str| {
        json(&meshsmooth(&[
            "smooth",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--filter",
            "hc",
            "--auto",
            "--search",
            "local",
            "--tau",
            tau,
            "--json",
        ]))
    };
    let none = run("0");
    assert_eq!(none["metrics"]["mean_error"], 0.0);
    assert_eq!(none["metrics"]["volume_change"], 0.0);
    assert_eq!(none["suggestion"]["search"], "local");
    let smooth = run("0.5");
    let suggested = json(&meshsmooth(&[
        "suggest",
        input.to_str().unwrap(),
        "--filter",
        "hc",
        "--search",
        "local",
        "--tau",
        "0.5",
        "--json",
    ]));
    assert_eq!(smooth["params"], suggested["params"]);
    assert!(smooth["suggestion"]["evaluations"].as_u64().unwrap() > 1);
    assert!(
        (smooth["metrics"]["score"].as_f64().unwrap() - suggested["score"].as_f64().unwrap()).abs()
            < 1e-12
    );
}

#[test]
fn bench_runs_on_the_gpu_backend() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let out = meshsmooth(&[
        "bench",
        input.to_str().unwrap(),
        "--filter",
        "sinc",
        "--repeat",
        "1",
        "--backend",
        "gpu",
        "--json",
    ]);
    if !out.status.success() && std::env::var_os("REQUIRE_GPU").is_none() {
        eprintln!(
            "NOTICE: no GPU adapter, bench --backend gpu not run: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        return;
    }
    let v = json(&out);
    assert_eq!(v["backend"], "gpu");
    assert_eq!(v["iterations"], 20);
    assert!(v["adapter"].as_str().is_some_and(|a| !a.is_empty()));
    assert!(v["vertex_iterations_per_second"].as_f64().unwrap() > 0.0);
    assert!(v["gpu_measure_seconds"].as_f64().unwrap() > 0.0);
    assert!(v["gpu_drift_seconds"].as_f64().unwrap() >= 0.0);
}

/// `cmd` with `--backend gpu --json` and with the CPU, or `None` (with a notice) when this
/// machine has no adapter and REQUIRE_GPU is not set.
fn on_both_backends(cmd: &[&str]) -> Option<[serde_json::Value; 2]> {
    let mut args = cmd.to_vec();
    args.extend(["--json", "--backend", "gpu"]);
    let gpu = meshsmooth(&args);
    if !gpu.status.success() && std::env::var_os("REQUIRE_GPU").is_none() {
        eprintln!(
            "NOTICE: no GPU adapter, {} --backend gpu not run: {}",
            cmd[0],
            String::from_utf8_lossy(&gpu.stderr)
        );
        return None;
    }
    args.truncate(args.len() - 2);
    Some([json(&meshsmooth(&args)), json(&gpu)])
}

fn assert_close(cpu: &serde_json::Value, gpu: &serde_json::Value, what: &str) {
    let (c, g) = (cpu.as_f64().unwrap(), gpu.as_f64().unwrap());
    assert!(
        (c - g).abs() <= 1e-4 * c.abs().max(g.abs()).max(1e-6),
        "{what}: cpu {c}, gpu {g}"
    );
}

#[test]
fn smooth_sweep_and_suggest_run_on_the_gpu_backend() {
    let input = data("synthetic/synthetic_bent_tube_r3.5.ply");
    let input = input.to_str().unwrap();
    let out = tmp("gpu-smoothed.ply");
    let out = out.to_str().unwrap();

    let Some([cpu, gpu]) = on_both_backends(&["smooth", input, "-o", out, "--filter", "taubin"])
    else {
        return;
    };
    assert_eq!(
        (cpu["backend"].as_str(), gpu["backend"].as_str()),
        (Some("cpu"), Some("gpu"))
    );
    for key in ["volume", "curvature", "mean_error", "max_error", "score"] {
        assert_close(&cpu["metrics"][key], &gpu["metrics"][key], key);
    }

    let suggest = [
        "suggest", input, "--filter", "hc", "--search", "local", "--tau", "0.6",
    ];
    let [cpu, gpu] = on_both_backends(&suggest).expect("the adapter found above");
    assert_eq!(cpu["params"], gpu["params"]);
    assert_close(&cpu["score"], &gpu["score"], "suggest score");

    let auto = [
        "smooth", input, "-o", out, "--auto", "--search", "local", "--filter", "laplace",
    ];
    let [cpu, gpu] = on_both_backends(&auto).expect("the adapter found above");
    assert_eq!(cpu["params"], gpu["params"]);
    assert_eq!(cpu["suggestion"], gpu["suggestion"]);

    let [cpu, gpu] = on_both_backends(&["sweep", input, "--filter", "laplace"])
        .expect("the adapter found above");
    let curves = |v: &serde_json::Value| v["curves"].as_array().unwrap().clone();
    assert_eq!(curves(&cpu).len(), 2);
    for (c, g) in curves(&cpu).iter().zip(curves(&gpu).iter()) {
        assert_eq!(c["best"], g["best"], "{}", c["param"]);
        let samples = |v: &serde_json::Value| v["samples"].as_array().unwrap().clone();
        assert_eq!(samples(c).len(), samples(g).len());
        for (cs, gs) in samples(c).iter().zip(samples(g).iter()) {
            assert_eq!(cs["value"], gs["value"]);
            assert_close(&cs["score"], &gs["score"], "sweep sample score");
        }
    }
}

/// A reader that goes away (`meshsmooth info brain.ply | head -0`) ends the tool quietly, with
/// no panic message, as Unix tools end.
#[test]
fn a_closed_output_pipe_ends_quietly() {
    use std::process::{Command, Stdio};
    let scalp = data("real/fsaverage_head_scalp_mne.ply");
    let mut child = Command::new(env!("CARGO_BIN_EXE_meshsmooth"))
        .args(["info", scalp.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the meshsmooth binary runs");
    // Closed before the tool has read the mesh, so its first write finds no reader.
    child.stdout = None;
    let out = child.wait_with_output().expect("it ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "status {:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
}
