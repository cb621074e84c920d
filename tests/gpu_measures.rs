//! The GPU engine's vertex normals and measure pass against the CPU reference
//! (`mesh::vertex_normals`, `metrics::measure_vertices`) on a software adapter (lavapipe), every
//! filter, on shared meshes and an open mesh with an isolated vertex.
//!
//! - Normals within 1e-5 rad of the CPU's.
//! - Measures of the GPU's result against the CPU's measures of the same positions and
//!   references: volume within 1e-6 relative, mean local error 1e-5, maximum 1e-4, every angle
//!   defect within 2e-6 rad (both engines' angles are f32, each within a few 1e-7), hence K
//!   within 2e-6 times the mean of 1 / A_mixed.
//! - The same numbers from a 2-D workgroup grid, and from a run sent in pieces.
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
use meshsmooth::gpu::{read_normals, read_result, GpuMeasures, GpuMesh, RunPieces};
use meshsmooth::mesh::{vertex_normals, Mesh};
use meshsmooth::metrics::{
    identity, measure_vertices, vertex_curvatures, Metrics, Original, VertexMeasures,
};
use meshsmooth::smooth::{Filter, Params};
use runs::{open_original, original, params, run, BRAINMASK, PIAL, SCALP, SPHERE, TUBE};

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

/// How far one vertex's angle defect may differ between the engines (radians).
const DEFECT: f64 = 2e-6;

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
    /// What K may differ by when every angle defect differs by [`DEFECT`] at most: that times
    /// the mean of `1 / A_mixed` over the vertices K averages.
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
        let dd = f64::from((gk - ck).abs()) * area.mixed_area;
        // 0 marks a vertex left out (boundary, no area); an angle defect within the rounding
        // of the angles may also come out as exactly 0 on one side.
        assert!(
            (gk == 0.0) == (ck == 0.0) || dd <= DEFECT,
            "vertex {i}: K_G {gk} on the GPU, {ck} on the CPU"
        );
        a.vertex_defect = a.vertex_defect.max(dd);
    }
    a.curvature_bound = DEFECT * inverse_areas.0 / inverse_areas.1.max(1) as f64;
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
    // The roughness: f32 terms summed pairwise per workgroup on the GPU, in f64 on the CPU.
    let roughness = original.roughness_ratio(&result.positions);
    assert!(
        relative(measured.roughness_ratio, roughness) <= 1e-5,
        "{name} {}: R/R0 {} on the GPU, {roughness} on the CPU",
        p.filter,
        measured.roughness_ratio
    );
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
        a.vertex_defect <= DEFECT,
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
    assert!(
        relative(own.roughness_ratio, 1.0) <= 1e-5,
        "{}",
        own.roughness_ratio
    );
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
        a.volume <= 1e-6 && a.mean_error <= 1e-5 && a.vertex_defect <= DEFECT,
        "{a:?}"
    );
}

/// The big staircase mesh (206,512 vertices, genus 304), once.
#[test]
fn measures_match_the_cpu_on_the_large_mesh() {
    let Some(gpu) = gpu() else { return };
    let original = original(data::LARGE);
    check_measures(gpu, "large", &original, &params(Filter::Taubin, 10));
}

/// A whole run of `p`, then the normals and the measure pass, each in one submission: the
/// positions with the references, the normals and the measures.
fn whole_run(
    g: &Gpu,
    mesh: &mut GpuMesh,
    original: &Original,
    p: &Params,
) -> (meshsmooth::gpu::SmoothResult, Vec<[f32; 3]>, GpuMeasures) {
    let (device, queue) = (&g.ctx.device, &g.ctx.queue);
    let result = run(g, mesh, p);
    g.smoother
        .compute_normals(device, queue, mesh)
        .expect("has measures");
    let normals = read_normals(device, queue, mesh).expect("readback");
    let measured = g
        .smoother
        .measure(device, queue, mesh, true)
        .expect("has measures")
        .wait(device, original, 0.5)
        .expect("readback");
    (result, normals, measured)
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
        let mut mesh = g
            .smoother
            .upload_with_measures(&g.ctx.device, &original)
            .expect("fits");
        results.push(whole_run(g, &mut mesh, &original, &p));
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

/// A run sent in pieces (as the web app sends one per frame: some iterations, the normals,
/// parts of the measure pass) leaves the same positions, references, normals and measures as
/// the whole run, bit for bit.
#[test]
fn a_run_in_pieces_equals_the_whole_run() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let original = original(SCALP);
    let n = original.mesh().vertex_count() as u64;
    for filter in Filter::ALL {
        for iterations in [0, 7] {
            let p = params(filter, iterations.max(u32::from(filter == Filter::Sinc)));
            let mut mesh = gpu
                .smoother
                .upload_with_measures(device, &original)
                .expect("fits");
            let (whole, whole_normals, whole_measures) = whole_run(gpu, &mut mesh, &original, &p);

            let mut mesh = gpu
                .smoother
                .upload_with_measures(device, &original)
                .expect("fits");
            let mut pieces = RunPieces::new(&p);
            let mut calls = 0;
            while !pieces.done() {
                // About one iteration (or a few parts of the measure) per call.
                let sent = pieces
                    .advance(&gpu.smoother, device, queue, &mut mesh, n)
                    .expect("valid");
                assert!(sent.spent > 0);
                calls += 1;
                assert!(calls < 100, "{filter}: no end");
            }
            let what = format!("{filter}, {iterations} iterations");
            assert!(calls >= 4, "{what}: {calls} pieces");
            let (positions, measures) = pieces.read_back(device, queue, &mesh).expect("done");
            let in_pieces = positions.wait(device).expect("readback");
            let normals = read_normals(device, queue, &mesh).expect("readback");
            let measured = measures.wait(device, &original, 0.5).expect("readback");
            assert_eq!(
                in_pieces,
                read_result(device, queue, &mesh).expect("readback")
            );
            assert_eq!(in_pieces, whole, "{what}: positions");
            assert_eq!(normals, whole_normals, "{what}: normals");
            assert_eq!(measured, whole_measures, "{what}: measures");
        }
    }
}
