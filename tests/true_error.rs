//! True surface error of the synthetic staircase meshes against their analytic shapes, before and
//! after smoothing. Run with `--nocapture` for the table of every filter at its defaults.

#[path = "common_metrics/data.rs"]
mod data;
#[path = "common_metrics/ground_truth.rs"]
mod ground_truth;

use ground_truth::{true_error, Shape, TrueError};
use meshsmooth::metrics::{measure, DriftingReference, Metrics, Original};
use meshsmooth::smooth::{self, Filter, Params};

fn mesh_file(shape_name: &str) -> String {
    format!("synthetic/synthetic_{shape_name}.ply")
}

#[test]
fn analytic_distances_reproduce_the_stated_staircase_error() {
    let gt = ground_truth::load();
    assert_eq!(gt.shapes.len(), 4);
    for (name, shape) in &gt.shapes {
        let (mesh, topology) = data::load(&mesh_file(name));
        let e = true_error(shape, &mesh.positions);
        let want = &shape.mc_mesh_error_vs_analytic;
        for (what, got, want) in [
            ("mean |d|", e.mean_abs, want.mean_abs),
            ("rms", e.rms, want.rms),
            ("max |d|", e.max_abs, want.max_abs),
            ("mean d", e.mean_signed, want.mean_signed),
        ] {
            assert!((got - want).abs() < 1e-3, "{name} {what}: {got} vs {want}");
        }
        // The data README's summary for every synthetic mesh.
        assert!((e.mean_abs - 0.167).abs() < 0.005, "{name}: {e:?}");
        assert!((e.rms - 0.205).abs() < 0.005, "{name}: {e:?}");
        assert!((e.max_abs - 0.49).abs() < 0.01, "{name}: {e:?}");
        let v = Original::new(&mesh, &topology).volume().expect("closed");
        assert!(
            (v - shape.mesh_volume).abs() < 1e-9 * v,
            "{name}: {v} vs {}",
            shape.mesh_volume
        );
    }
}

#[test]
fn analytic_distances_have_the_right_sign_and_size() {
    let gt = ground_truth::load();
    for (name, shape) in &gt.shapes {
        // World point of local coordinates q: p = center + R q.
        let world = |q: [f64; 3]| {
            let r = &shape.rotation;
            [0, 1, 2].map(|k| shape.center[k] + r[k][0] * q[0] + r[k][1] * q[1] + r[k][2] * q[2])
        };
        let (probe, want) = match shape.kind.as_str() {
            "sphere" => ([0.0, 0.0, 0.0], -20.0),
            // Halfway to the pole of the shortest axis.
            "ellipsoid" => ([0.0, 0.0, 6.0], -6.0),
            // The centre lies in the hole: 24 - 8 from the tube.
            "torus" => ([0.0, 0.0, 0.0], 16.0),
            // The bend centre: 20 - 3.5 from the tube; and the middle of the arc's tube.
            "arc_tube" => ([0.0, 0.0, 0.0], 16.5),
            other => panic!("unexpected shape {other}"),
        };
        let got = shape.signed_distance(world(probe));
        assert!((got - want).abs() < 1e-9, "{name}: {got} vs {want}");
        if shape.kind == "arc_tube" {
            let mid = shape.signed_distance(world([20.0, 0.0, 1.0]));
            assert!((mid + 2.5).abs() < 1e-9, "{name}: {mid}");
            // Beyond the end at phi0 = -pi/2 (local (0, -20, 0)): the hemispherical cap.
            let cap = shape.signed_distance(world([-5.0, -20.0, 0.0]));
            assert!((cap - 1.5).abs() < 1e-9, "{name}: {cap}");
        }
    }
}

struct Row {
    shape: String,
    filter: Filter,
    error: TrueError,
    metrics: Metrics,
    /// Relative to the exact volume of the analytic shape.
    volume_vs_exact: f64,
}

fn smooth_shape(name: &str, shape: &Shape, filter: Filter) -> Row {
    let (mesh, topology) = data::load(&mesh_file(name));
    let original = Original::new(&mesh, &topology);
    let mut drift = DriftingReference::new(&original);
    let q = smooth::smooth(
        &mesh,
        &topology,
        &Params::defaults(filter),
        None,
        &mut drift,
    );
    let metrics = measure(&original, &q, drift.reference(), 0.5);
    let volume = metrics.volume.expect("closed");
    Row {
        shape: name.to_string(),
        filter,
        error: true_error(shape, &q),
        volume_vs_exact: (volume - shape.volume) / shape.volume,
        metrics,
    }
}

fn table() -> Vec<Row> {
    let gt = ground_truth::load();
    let mut rows = Vec::new();
    println!(
        "{:<20} {:<8} {:>8} {:>8} {:>8} {:>9} {:>11} {:>10} {:>8}",
        "shape", "filter", "rms", "mean|d|", "mean d", "max|d|", "dV/V0 %", "dV/Vtrue %", "E"
    );
    for (name, shape) in &gt.shapes {
        let e = &shape.mc_mesh_error_vs_analytic;
        println!(
            "{:<20} {:<8} {:>8.4} {:>8.4} {:>8.4} {:>9.4} {:>11} {:>10.3} {:>8}",
            name,
            "none",
            e.rms,
            e.mean_abs,
            e.mean_signed,
            e.max_abs,
            "",
            100.0 * (shape.mesh_volume - shape.volume) / shape.volume,
            ""
        );
        for filter in Filter::ALL {
            let r = smooth_shape(name, shape, filter);
            println!(
                "{:<20} {:<8} {:>8.4} {:>8.4} {:>8.4} {:>9.4} {:>11.3} {:>10.3} {:>8.4}",
                r.shape,
                r.filter.name(),
                r.error.rms,
                r.error.mean_abs,
                r.error.mean_signed,
                r.error.max_abs,
                100.0 * r.metrics.volume_change.expect("closed"),
                100.0 * r.volume_vs_exact,
                r.metrics.mean_error,
            );
            rows.push(r);
        }
    }
    rows
}

#[test]
fn filters_at_defaults_against_the_analytic_shapes() {
    let gt = ground_truth::load();
    let rows = table();
    let row = |shape: &str, filter: Filter| {
        rows.iter()
            .find(|r| r.shape == shape && r.filter == filter)
            .expect("every shape and filter is in the table")
    };
    for name in gt.shapes.keys() {
        // Laplace+HC at its defaults removes most of the staircase: below 0.12 mm RMS everywhere.
        let hc = row(name, Filter::Hc);
        assert!(hc.error.rms < 0.12, "{name}: HC rms {}", hc.error.rms);
        for filter in Filter::ALL {
            let r = row(name, filter);
            assert!(r.metrics.mean_error > 0.0, "{name} {filter}: nothing moved");
        }
    }
    // Plain Laplace shrinks the thin tube: its error grows past the staircase's own and past
    // HC's, and it loses volume.
    let tube = "bent_tube_r3.5";
    let unsmoothed = gt.shapes[tube].mc_mesh_error_vs_analytic.rms;
    let laplace = row(tube, Filter::Laplace);
    assert!(
        laplace.error.rms > unsmoothed,
        "tube laplace rms {}",
        laplace.error.rms
    );
    assert!(laplace.error.rms > 2.0 * row(tube, Filter::Hc).error.rms);
    assert!(laplace.error.mean_signed < -0.1, "{:?}", laplace.error);
    let change = laplace.metrics.volume_change.expect("closed");
    assert!(change < -0.05, "tube laplace volume change {change}");
}
