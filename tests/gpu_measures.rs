//! The GPU engine's drifting reference, vertex normals and measure pass against the CPU
//! reference (`metrics::DriftingReference`, `mesh::vertex_normals`, `metrics::measure_vertices`)
//! on a software adapter (lavapipe), every filter, on shared meshes and an open mesh with an
//! isolated vertex.
//!
//! - Drift, step by step: Laplace and HC runs of k iterations end where a longer run is after
//!   k iterations, so the CPU's drift can follow the GPU's own positions step by step; the
//!   references must be identical except where two candidates' squared distances differ by
//!   rounding (counted, bounded, printed). Windowed sinc drifts towards one result, which the
//!   CPU replays. End to end (CPU run and CPU drift vs GPU run and GPU drift), mismatches are
//!   counted and must be near-ties too.
//! - Normals within 1e-5 rad of the CPU's.
//! - Measures of the GPU's result: the CPU's numbers for the same positions and references,
//!   within f32 rounding (volume 1e-6 relative).
//!
//! Without an adapter these tests print a notice and pass, unless REQUIRE_GPU=1, where they fail.
#![cfg(not(target_arch = "wasm32"))]

#[path = "common_metrics/data.rs"]
mod data;
#[path = "common_gpu/device.rs"]
mod device;

use device::{gpu, Gpu};
use meshsmooth::gpu::{
    read_normals, read_positions, read_result, GpuError, GpuMesh, ResultReadback, SmoothResult,
};
use meshsmooth::mesh::{vertex_normals, Mesh, Topology};
use meshsmooth::metrics::{
    identity, measure_vertices, vertex_curvatures, DriftingReference, Metrics, Original,
    VertexMeasures,
};
use meshsmooth::smooth::{smooth, Filter, NoObserver, Params};

const TUBE: &str = "synthetic/synthetic_bent_tube_r3.5.ply";
const SCALP: &str = "real/fsaverage_head_scalp_mne.ply";
const PIAL: &str = "real/fsaverage5_pial_left.ply";
const SPHERE: &str = "synthetic/synthetic_sphere_r20.ply";
const BRAINMASK: &str = "segmentations/seg_mni152_brainmask_2mm.ply";

fn original(relative: &str) -> Original {
    let (mesh, topology) = data::load(relative);
    Original::new(&mesh, &topology)
}

/// The scalp opened: a cap cut off the top, every 40th triangle removed, and one vertex no
/// triangle uses (as in tests/gpu_filters.rs).
fn open_original() -> Original {
    let (mesh, _) = data::load(SCALP);
    let (lo, hi) = mesh.bounding_box().expect("not empty");
    let cut = lo[2] + 0.8 * (hi[2] - lo[2]);
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|&(t, tri)| {
            t % 40 != 7 && !tri.iter().all(|&v| mesh.positions[v as usize][2] > cut)
        })
        .map(|(_, &tri)| tri)
        .collect();
    let mut positions = mesh.positions.clone();
    positions.push(lo);
    let mesh = Mesh::new(positions, triangles);
    let topology = Topology::build(&mesh);
    assert!(topology.has_boundary());
    Original::new(&mesh, &topology)
}

fn params(filter: Filter, iterations: u32) -> Params {
    Params {
        iterations,
        ..Params::defaults(filter)
    }
}

fn run(gpu: &Gpu, mesh: &mut GpuMesh, p: &Params) -> SmoothResult {
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    gpu.smoother.smooth(device, queue, mesh, p).expect("valid");
    read_result(device, queue, mesh).expect("readback")
}

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

/// Weights in [0, 1], every 7th vertex locked (as in tests/gpu_filters.rs).
fn test_weights(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            if i % 7 == 0 {
                0.0
            } else {
                ((i as u64 * 2_654_435_761) % 1000) as f32 / 999.0
            }
        })
        .collect()
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

fn angle(a: [f32; 3], b: [f32; 3]) -> f64 {
    let a = a.map(f64::from);
    let b = b.map(f64::from);
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let s = (cross[0].powi(2) + cross[1].powi(2) + cross[2].powi(2)).sqrt();
    let c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    s.atan2(c)
}

/// GPU normals of `positions` (the mesh's current result) against the CPU's: the largest
/// angle between them.
fn normals_error(gpu: &Gpu, mesh: &GpuMesh, m: &Mesh, positions: &[[f32; 3]]) -> f64 {
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    gpu.smoother
        .compute_normals(device, queue, mesh)
        .expect("has measures");
    let on_gpu = read_normals(device, queue, mesh).expect("readback");
    let cpu = vertex_normals(positions, &m.triangles);
    let mut worst = 0.0f64;
    for (i, (&g, &c)) in on_gpu.iter().zip(&cpu).enumerate() {
        if c == [0.0; 3] {
            assert_eq!(g, [0.0; 3], "vertex {i}: no normal on the CPU");
            continue;
        }
        let len = g.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() < 1e-6, "vertex {i}: |n| = {len}");
        worst = worst.max(angle(g, c));
    }
    worst
}

#[test]
fn normals_match_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let device = &gpu.ctx.device;
    let open = open_original();
    for (name, original) in [
        (TUBE, original(TUBE)),
        (PIAL, original(PIAL)),
        ("open scalp", open),
    ] {
        let m = original.mesh();
        let mut mesh = gpu
            .smoother
            .upload_with_measures(device, &original)
            .expect("fits");
        let normals = mesh.normals_buffer().expect("has measures");
        assert!(normals
            .usage()
            .contains(wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_SRC));
        assert_eq!(normals.size(), 16 * m.vertex_count() as u64);
        let e = normals_error(gpu, &mesh, m, &m.positions);
        eprintln!("{name:>10} original: normals within {e:.1e} rad of the CPU's");
        assert!(e < 1e-5, "{name}: {e}");
        for filter in Filter::ALL {
            let result = run(gpu, &mut mesh, &params(filter, 20));
            assert!(mesh
                .positions_buffer()
                .usage()
                .contains(wgpu::BufferUsages::VERTEX));
            let e = normals_error(gpu, &mesh, m, &result.positions);
            eprintln!("{name:>10} {filter:>7}: normals within {e:.1e} rad of the CPU's");
            assert!(e < 1e-5, "{name} {filter}: {e}");
        }
    }
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

/// How closely the GPU's measures follow the CPU's on the same positions and references.
#[derive(Default, Debug)]
struct Agreement {
    volume: f64,
    curvature: f64,
    mean_error: f64,
    max_error: f64,
    /// Largest per-vertex local error difference over the mean local error.
    vertex_error: f64,
    /// Largest per-vertex difference of `K_G * A_mixed` (the angle defect, radians).
    vertex_defect: f64,
    /// What K may differ by when every angle defect differs by 1e-6 rad at most: 1e-6 times the
    /// mean of `1 / A_mixed` over the vertices K averages.
    curvature_bound: f64,
}

fn compare(
    original: &Original,
    positions: &[[f32; 3]],
    cpu: &(Metrics, VertexMeasures),
    gpu: &(Metrics, VertexMeasures),
) -> Agreement {
    let (cm, cv) = cpu;
    let (gm, gv) = gpu;
    assert_eq!(gm.volume0, cm.volume0);
    assert_eq!(gm.curvature0, cm.curvature0);
    assert_eq!(gm.volume.is_some(), cm.volume.is_some());
    let areas = vertex_curvatures(positions, &original.mesh().triangles, original.topology());
    let mut a = Agreement {
        volume: relative(gm.volume.unwrap_or(0.0), cm.volume.unwrap_or(0.0)),
        curvature: relative(gm.curvature, cm.curvature),
        mean_error: relative(gm.mean_error, cm.mean_error),
        max_error: relative(gm.max_error, cm.max_error),
        ..Agreement::default()
    };
    let mut inverse_areas = (0.0, 0usize);
    for (i, area) in areas.iter().enumerate() {
        if cv.gaussian_curvature[i] != 0.0 {
            inverse_areas.0 += 1.0 / area.mixed_area;
            inverse_areas.1 += 1;
        }
        let de = f64::from((gv.local_error[i] - cv.local_error[i]).abs());
        a.vertex_error = a.vertex_error.max(de / cm.mean_error.max(1e-12));
        let (gk, ck) = (gv.gaussian_curvature[i], cv.gaussian_curvature[i]);
        assert_eq!(
            gk == 0.0,
            ck == 0.0,
            "vertex {i}: K_G {gk} on the GPU, {ck} on the CPU"
        );
        let dd = f64::from((gk - ck).abs()) * area.mixed_area;
        a.vertex_defect = a.vertex_defect.max(dd);
    }
    a.curvature_bound = 1e-6 * inverse_areas.0 / inverse_areas.1.max(1) as f64;
    a
}

/// The GPU's measures of its own result against the CPU's measures of the same result.
fn check_measures(gpu: &Gpu, name: &str, original: &Original, p: &Params) -> Agreement {
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, original)
        .expect("fits");
    let result = run(gpu, &mut mesh, p);
    let cpu = measure_vertices(original, &result.positions, &result.reference, 0.5);
    let measured = gpu
        .smoother
        .measure(device, queue, &mesh, true)
        .expect("has measures")
        .wait(device, original, 0.5)
        .expect("readback");
    let on_gpu = (measured.metrics, measured.vertex.expect("asked for"));
    let a = compare(original, &result.positions, &cpu, &on_gpu);
    eprintln!(
        "{name:>10} {:>7} {:>2} it: relative V {:.1e}, K {:.1e}, E {:.1e}, max E {:.1e}; per vertex: error {:.1e} of E, defect {:.1e} rad (E = {:.3e}, K/K0 = {:.3})",
        p.filter,
        p.iterations,
        a.volume,
        a.curvature,
        a.mean_error,
        a.max_error,
        a.vertex_error,
        a.vertex_defect,
        cpu.0.mean_error,
        cpu.0.curvature / cpu.0.curvature0,
    );
    let m = &on_gpu.0;
    assert!(a.volume <= 1e-6, "{name} {}: volume {}", p.filter, a.volume);
    // f32 leaves each angle defect a few 1e-7 rad off, which is 1e-5 of K on a smoothed
    // sphere (K/K0 = 0.04): bounded through the defects rather than relative to K.
    let dk = (m.curvature - cpu.0.curvature).abs();
    assert!(
        dk <= a.curvature_bound,
        "{name} {}: K {dk} > {}",
        p.filter,
        a.curvature_bound
    );
    assert!(
        a.vertex_defect <= 1e-6,
        "{name} {}: defect {}",
        p.filter,
        a.vertex_defect
    );
    assert!(
        a.mean_error <= 1e-5,
        "{name} {}: E {}",
        p.filter,
        a.mean_error
    );
    assert!(
        a.max_error <= 1e-4,
        "{name} {}: max E {}",
        p.filter,
        a.max_error
    );
    assert!(
        (m.score - cpu.0.score).abs() <= 1e-5,
        "{name} {}: score",
        p.filter
    );
    a
}

#[test]
fn measures_match_the_cpu_on_closed_meshes() {
    let Some(gpu) = gpu() else { return };
    for name in [TUBE, SCALP, PIAL, SPHERE, BRAINMASK] {
        let original = original(name);
        for filter in Filter::ALL {
            for iterations in [10, 50] {
                check_measures(gpu, name, &original, &params(filter, iterations));
            }
        }
    }
}

#[test]
fn measures_match_the_cpu_on_an_open_mesh_with_an_isolated_vertex() {
    let Some(gpu) = gpu() else { return };
    let original = open_original();
    for filter in Filter::ALL {
        check_measures(gpu, "open scalp", &original, &params(filter, 20));
    }
}

#[test]
fn measures_of_the_original_and_of_untracked_runs() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let original = original(SCALP);
    let n = original.mesh().vertex_count();
    let mut mesh = gpu
        .smoother
        .upload_with_measures(device, &original)
        .expect("fits");
    // Before any run: the original against itself.
    let own = gpu
        .smoother
        .measure(device, queue, &mesh, false)
        .expect("has measures")
        .wait(device, &original, 0.5)
        .expect("readback");
    assert!(own.vertex.is_none());
    assert_eq!(own.metrics.mean_error, 0.0);
    assert_eq!(own.metrics.max_error, 0.0);
    assert!(
        relative(
            own.metrics.volume.expect("closed"),
            original.volume().expect("closed")
        ) < 1e-6
    );
    assert!(relative(own.metrics.curvature, original.curvature()) < 1e-5);
    assert_eq!(own.metrics.curvature0, original.curvature());
    // Not tracking: every vertex measured against its own fan.
    mesh.set_track_reference(false).expect("has measures");
    let p = params(Filter::Hc, 30);
    let positions = run(gpu, &mut mesh, &p).positions;
    let cpu = measure_vertices(&original, &positions, &identity(n), 0.5);
    let measured = gpu
        .smoother
        .measure(device, queue, &mesh, true)
        .expect("has measures")
        .wait(device, &original, 0.5)
        .expect("readback");
    let a = compare(
        &original,
        &positions,
        &cpu,
        &(measured.metrics, measured.vertex.expect("asked for")),
    );
    assert!(
        a.volume <= 1e-6 && a.mean_error <= 1e-5 && a.vertex_defect <= 1e-6,
        "{a:?}"
    );
}

/// The big staircase mesh (206,512 vertices, genus 304), once.
#[test]
fn measures_match_the_cpu_on_the_large_mesh() {
    let Some(gpu) = gpu() else { return };
    let original = original(data::LARGE);
    check_measures(gpu, "large", &original, &params(Filter::Taubin, 10));
    let (differing, worst) = end_to_end(gpu, "large", &original, &params(Filter::Taubin, 10), None);
    assert!(differing * 200 <= original.mesh().vertex_count() && worst <= 1e-4);
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

/// Rows of 16 workgroups (a 2-D dispatch on a small mesh): the drift, the normals and the
/// per-workgroup sums index the same vertices and give the same numbers as one row.
#[test]
fn a_2d_grid_gives_the_same_drift_normals_and_measures() {
    let Some(gpu) = gpu() else { return };
    let limits = wgpu::Limits {
        max_compute_workgroups_per_dimension: 16,
        ..wgpu::Limits::default()
    };
    let Some(small) = device::gpu_with(Some(limits)) else {
        return;
    };
    let original = original(SCALP);
    let n = original.mesh().vertex_count() as u32;
    let groups = n.div_ceil(meshsmooth::gpu::WORKGROUP_SIZE);
    assert!(groups > 16 && groups <= 256, "{groups} workgroups");
    let p = params(Filter::Laplace, 50);
    let mut results = Vec::new();
    for g in [gpu, &small] {
        let (device, queue) = (&g.ctx.device, &g.ctx.queue);
        let mut mesh = g
            .smoother
            .upload_with_measures(device, &original)
            .expect("fits");
        let result = run(g, &mut mesh, &p);
        g.smoother
            .compute_normals(device, queue, &mesh)
            .expect("has measures");
        let normals = read_normals(device, queue, &mesh).expect("readback");
        let measured = g
            .smoother
            .measure(device, queue, &mesh, true)
            .expect("has measures")
            .wait(device, &original, 0.5)
            .expect("readback");
        results.push((result, normals, measured));
    }
    let (one_row, two_d) = (&results[0], &results[1]);
    assert!(
        one_row.0.reference != identity(n as usize),
        "the run drifts"
    );
    assert_eq!(one_row.0, two_d.0);
    assert_eq!(one_row.1, two_d.1);
    assert_eq!(one_row.2.vertex, two_d.2.vertex);
    let (a, b) = (&one_row.2.metrics, &two_d.2.metrics);
    assert_eq!(a.max_error, b.max_error);
    assert!(relative(a.mean_error, b.mean_error) < 1e-6);
    assert!(relative(a.curvature, b.curvature) < 1e-6);
    assert!(relative(a.volume.expect("closed"), b.volume.expect("closed")) < 1e-6);
}
