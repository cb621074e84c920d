//! The GPU engine's drifting reference against the CPU's (`metrics::DriftingReference`) on a
//! software adapter (lavapipe), on shared meshes, every filter.
//!
//! - Step by step: Laplace and HC runs of k iterations end where a longer run is after k
//!   iterations, so the CPU's drift can follow the GPU's own positions step by step; windowed
//!   sinc drifts towards its one result, which the CPU replays. The references must be identical
//!   except where two candidates' squared distances differ by rounding (counted, printed).
//! - End to end (CPU run and CPU drift against GPU run and GPU drift, with and without weights):
//!   mismatches are counted and must be near-ties.
//! - The reference's life cycle (identity at upload and at every run's start, untracked runs)
//!   and its readback together with the positions, polled as in the browser.
//!
//! Without an adapter these tests print a notice and pass, unless REQUIRE_GPU=1, where they fail.
#![cfg(not(target_arch = "wasm32"))]

#[path = "common_metrics/data.rs"]
mod data;
#[path = "common_gpu/device.rs"]
mod device;
#[path = "common_gpu/open_scalp.rs"]
mod open_scalp;
#[path = "common_gpu/runs.rs"]
mod runs;

use device::{gpu, Gpu};
use meshsmooth::gpu::{read_positions, read_result, GpuError, ResultReadback, SmoothResult};
use meshsmooth::metrics::{identity, DriftingReference, Original};
use meshsmooth::smooth::{smooth, Filter, NoObserver, Params};
use runs::{original, params, run, test_weights, PIAL, SCALP, SPHERE, TUBE};

/// Squared distance as the CPU's drift computes it.
fn distance2(q: [f32; 3], p: [f32; 3]) -> f32 {
    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// Relative gap between the squared distances from `q` to two candidates of the original.
fn tie_gap(original: &Original, q: [f32; 3], r1: u32, r2: u32) -> f64 {
    let p = &original.mesh().positions;
    let (a, b) = (
        f64::from(distance2(q, p[r1 as usize])),
        f64::from(distance2(q, p[r2 as usize])),
    );
    (a - b).abs() / a.max(b).max(f64::MIN_POSITIVE)
}

/// Squared distances within this relative gap are ties up to rounding: a few f32 ulps.
const TIE: f64 = 4.0 * f32::EPSILON as f64;

/// Per-vertex step-by-step drift comparison: the CPU drift follows the GPU's positions after
/// every step; each vertex's reference must equal the GPU's until the first step where the two
/// candidates tie within rounding (its path then differs legitimately). Returns how many
/// vertices ever differed.
fn drift_follows_the_gpu(
    gpu: &Gpu,
    name: &str,
    original: &Original,
    filter: Filter,
    k: u32,
) -> usize {
    let device = &gpu.ctx.device;
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, original)
        .expect("fits");
    let n = original.mesh().vertex_count();
    // What the CPU's observer sees, step by step: Laplace and HC's k-step result is a k-iteration
    // run's; windowed sinc shows its one result `k` times.
    let steps: Vec<SmoothResult> = if filter == Filter::Sinc {
        vec![run(gpu, &mut mesh, &params(filter, k)); k as usize]
    } else {
        (1..=k)
            .map(|i| run(gpu, &mut mesh, &params(filter, i)))
            .collect()
    };
    let mut cpu = DriftingReference::new(original);
    let mut diverged = vec![false; n];
    let mut worst_gap = 0.0f64;
    for (s, result) in steps.iter().enumerate() {
        cpu.update(&result.positions);
        if filter == Filter::Sinc && s + 1 < steps.len() {
            // Only the last run's reference is the GPU's after this many steps.
            continue;
        }
        let pairs = result.reference.iter().zip(cpu.reference());
        for (i, ((&g, &c), first)) in pairs.zip(diverged.iter_mut()).enumerate() {
            if g != c && !*first {
                *first = true;
                let gap = tie_gap(original, result.positions[i], g, c);
                worst_gap = worst_gap.max(gap);
                assert!(
                    gap <= TIE,
                    "{name} {filter} step {}: vertex {i} GPU reference {g}, CPU {c}, squared distances differ by {gap:.2e} relative",
                    s + 1
                );
            }
        }
    }
    let count = diverged.iter().filter(|&&d| d).count();
    let moved = (0..n).filter(|&i| cpu.reference()[i] != i as u32).count();
    eprintln!(
        "{name:>10} {filter:>7} {k:>2} it: drift on the GPU's positions: {count} of {n} references differ (near-ties, worst gap {worst_gap:.1e}); {moved} drifted"
    );
    count
}

#[test]
fn drift_matches_the_cpu_on_the_gpus_positions() {
    let Some(gpu) = gpu() else { return };
    for name in [TUBE, SCALP, PIAL] {
        let original = original(name);
        let n = original.mesh().vertex_count();
        for (filter, k) in [(Filter::Laplace, 30), (Filter::Hc, 30), (Filter::Sinc, 20)] {
            let differing = drift_follows_the_gpu(gpu, name, &original, filter, k);
            assert!(differing * 1000 <= n, "{name} {filter}: {differing} of {n}");
        }
    }
}

/// End to end: the CPU's run with its drift against the GPU's run with its drift. Positions
/// may differ by rounding (they do with weights on lavapipe), so a few references may differ;
/// each must be a near-tie at the end (relative gap of the distances below 1e-4), and few.
fn end_to_end(
    gpu: &Gpu,
    name: &str,
    original: &Original,
    p: &Params,
    weights: Option<&[f32]>,
) -> (usize, f64) {
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, original)
        .expect("fits");
    mesh.set_weights(queue, weights).expect("one per vertex");
    let mut drift = DriftingReference::new(original);
    let cpu_positions = smooth(original.mesh(), original.topology(), p, weights, &mut drift);
    let on_gpu = run(gpu, &mut mesh, p);
    let mut differing = 0;
    let mut worst = 0.0f64;
    for (i, (&g, &c)) in on_gpu.reference.iter().zip(drift.reference()).enumerate() {
        if g != c {
            differing += 1;
            worst = worst.max(tie_gap(original, cpu_positions[i], g, c));
        }
    }
    let moved = (0..cpu_positions.len())
        .filter(|&i| drift.reference()[i] != i as u32)
        .count();
    let positions_differ = on_gpu
        .positions
        .iter()
        .zip(&cpu_positions)
        .filter(|(a, b)| a != b)
        .count();
    eprintln!(
        "{name:>10} {:>7} {:>2} it{}: end to end, {differing} of {} references differ (worst distance gap {worst:.1e}); {moved} drifted; {positions_differ} positions not bitwise equal",
        p.filter,
        p.iterations,
        if weights.is_some() { " weighted" } else { "" },
        cpu_positions.len()
    );
    (differing, worst)
}

#[test]
fn drift_end_to_end_differs_only_at_near_ties() {
    let Some(gpu) = gpu() else { return };
    for name in [TUBE, SCALP, PIAL, SPHERE] {
        let original = original(name);
        let n = original.mesh().vertex_count();
        let weights = test_weights(n);
        for filter in Filter::ALL {
            for (iterations, w) in [(10, None), (50, None), (50, Some(weights.as_slice()))] {
                let (differing, worst) =
                    end_to_end(gpu, name, &original, &params(filter, iterations), w);
                assert!(differing * 200 <= n, "{name} {filter}: {differing} of {n}");
                assert!(worst <= 1e-4, "{name} {filter}: gap {worst}");
            }
        }
    }
}

#[test]
fn references_reset_with_every_run_and_stay_put_when_not_tracked() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let original = original(TUBE);
    let n = original.mesh().vertex_count();
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, &original)
        .expect("fits");
    assert!(mesh.has_measures() && mesh.tracks_reference());
    let before = read_result(device, queue, &mesh).expect("readback");
    assert_eq!(before.reference, identity(n));
    assert_eq!(before.positions, original.mesh().positions);
    let long = run(gpu, &mut mesh, &params(Filter::Laplace, 50));
    assert!(long.reference != identity(n), "50 Laplace iterations drift");
    // Zero iterations: the original and the identity again.
    let none = run(gpu, &mut mesh, &params(Filter::Laplace, 0));
    assert_eq!(none.reference, identity(n));
    assert_eq!(none.positions, original.mesh().positions);
    mesh.set_track_reference(false).expect("has measures");
    let untracked = run(gpu, &mut mesh, &params(Filter::Laplace, 50));
    assert_eq!(untracked.reference, identity(n));
    assert_eq!(untracked.positions, long.positions);

    // A mesh uploaded for smoothing only has no reference.
    let mut plain = gpu
        .smoother
        .upload(device, original.mesh(), original.topology())
        .expect("fits");
    assert!(!plain.has_measures() && !plain.tracks_reference());
    assert!(plain.reference_buffer().is_none() && plain.normals_buffer().is_none());
    let e = ResultReadback::start(device, queue, &plain)
        .err()
        .expect("no reference");
    assert_eq!(e, GpuError::NoMeasures);
    assert_eq!(plain.set_track_reference(true), Err(GpuError::NoMeasures));
    assert!(gpu.smoother.compute_normals(device, queue, &plain).is_err());
    assert!(gpu.smoother.measure(device, queue, &plain, false).is_err());
    gpu.smoother
        .smooth(device, queue, &mut plain, &params(Filter::Laplace, 50))
        .expect("smoothing works without measures");
    assert_eq!(
        read_positions(device, queue, &plain).expect("readback"),
        long.positions
    );
}

#[test]
fn readback_of_the_result_is_polled_not_blocked() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let original = original(SCALP);
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, &original)
        .expect("fits");
    let p = params(Filter::Taubin, 10);
    gpu.smoother
        .smooth(device, queue, &mut mesh, &p)
        .expect("valid");
    let pending = ResultReadback::start(device, queue, &mesh).expect("has measures");
    // As the browser does it: poll without blocking until the mapping completes.
    let mut polls = 0;
    let result = loop {
        if let Some(result) = pending.try_take() {
            break result.expect("mapped");
        }
        polls += 1;
        assert!(polls < 100_000, "the mapping never completed");
        device.poll(wgpu::PollType::Poll).expect("poll");
    };
    assert_eq!(result, read_result(device, queue, &mesh).expect("readback"));
    assert_eq!(result.positions.len(), original.mesh().vertex_count());
}

#[test]
fn smoothing_only_meshes_are_unchanged() {
    // The plain upload still smooths as before (tests/gpu_filters.rs checks it in depth).
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let (m, topology) = data::load(TUBE);
    let mut plain = gpu.smoother.upload(device, &m, &topology).expect("fits");
    let p = params(Filter::Sinc, 20);
    gpu.smoother
        .smooth(device, queue, &mut plain, &p)
        .expect("valid");
    let cpu = smooth(&m, &topology, &p, None, &mut NoObserver);
    let on_gpu = read_positions(device, queue, &plain).expect("readback");
    let worst = on_gpu
        .iter()
        .zip(&cpu)
        .map(|(a, b)| {
            (0..3)
                .map(|k| f64::from(a[k] - b[k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max);
    assert!(worst <= 1e-4 * m.bounding_box_diagonal());
}

/// The big staircase mesh (206,512 vertices, genus 304), once.
#[test]
fn drift_end_to_end_on_the_large_mesh() {
    let Some(gpu) = gpu() else { return };
    let original = original(data::LARGE);
    let (differing, worst) = end_to_end(gpu, "large", &original, &params(Filter::Taubin, 10), None);
    assert!(differing * 200 <= original.mesh().vertex_count() && worst <= 1e-4);
}
