//! The GPU engine against the CPU reference (`smooth::smooth`) on a software adapter
//! (lavapipe): every filter, with and without weights and the displacement bound, 50 iterations,
//! on shared meshes and an open mesh with an isolated vertex. Positions must agree within 1e-4
//! of the bounding-box diagonal.
//!
//! Without an adapter these tests print a notice and pass, unless REQUIRE_GPU=1, where they fail.
//! Native only: the browser's device comes from the page, not from these helpers.
#![cfg(not(target_arch = "wasm32"))]

#[path = "common_gpu/device.rs"]
mod device;
#[path = "common_gpu/open_scalp.rs"]
mod open_scalp;

use device::{gpu, gpu_with, Gpu};
use meshsmooth::gpu::{read_positions, GpuError};
use meshsmooth::mesh::{Mesh, Topology};
use meshsmooth::smooth::{smooth, Filter, NoObserver, Params};
use open_scalp::open_scalp;

fn load(relative: &str) -> Mesh {
    let path = format!("{}/../shared/data/{relative}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    meshsmooth::io::load(&bytes, relative).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn open_mesh() -> Mesh {
    open_scalp(&load("real/fsaverage_head_scalp_mne.ply"))
}

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

fn params(filter: Filter) -> Params {
    Params {
        iterations: 50,
        ..Params::defaults(filter)
    }
}

fn distance(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| (f64::from(a[k]) - f64::from(b[k])).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn max_distance(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(&p, &q)| distance(p, q))
        .fold(0.0, f64::max)
}

/// Every filter, free, weighted, bounded and both, on one mesh: GPU within 1e-4 of the diagonal.
fn check_mesh(gpu: &Gpu, name: &str, mesh: &Mesh) {
    let topology = Topology::build(mesh);
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mut uploaded = gpu.smoother.upload(device, mesh, &topology).expect("fits");
    let diagonal = mesh.bounding_box_diagonal();
    let tolerance = 1e-4 * diagonal;
    let weights = test_weights(mesh.positions.len());
    for filter in Filter::ALL {
        let free = params(filter);
        let cpu_free = smooth(mesh, &topology, &free, None, &mut NoObserver);
        // A bound that binds: the median displacement of the free run.
        let mut moved: Vec<f64> = cpu_free
            .iter()
            .zip(&mesh.positions)
            .map(|(&p, &o)| distance(p, o))
            .collect();
        moved.sort_by(f64::total_cmp);
        let median = moved[moved.len() / 2] as f32;
        let largest = moved.last().copied().unwrap_or(0.0);
        eprintln!(
            "{name:>10} {filter:>7}: CPU moves vertices by up to {:.2e}, median {:.2e} of the diagonal",
            largest / diagonal,
            f64::from(median) / diagonal
        );
        assert!(
            largest > 20.0 * tolerance && median > 0.0,
            "{name} {filter}: the filter barely moves the mesh, the comparison would mean little"
        );
        for (with_weights, d_max) in [
            (false, None),
            (true, None),
            (false, Some(median)),
            (true, Some(median)),
        ] {
            let p = Params {
                max_displacement: d_max,
                ..free
            };
            let w = with_weights.then_some(weights.as_slice());
            let cpu = smooth(mesh, &topology, &p, w, &mut NoObserver);
            uploaded
                .set_weights(queue, w)
                .expect("one weight per vertex");
            gpu.smoother
                .smooth(device, queue, &mut uploaded, &p)
                .expect("valid parameters");
            let on_gpu = read_positions(device, queue, &uploaded).expect("readback");
            let error = max_distance(&on_gpu, &cpu);
            eprintln!(
                "{name:>10} {filter:>7} weights {with_weights:>5} bound {:>5}: max |gpu - cpu| = {:.2e} of the diagonal",
                d_max.is_some(),
                error / diagonal
            );
            assert!(
                error <= tolerance,
                "{name} {filter} weights {with_weights} bound {d_max:?}: {error} > {tolerance}"
            );
            for (i, (&g, &o)) in on_gpu.iter().zip(&mesh.positions).enumerate() {
                if topology.smoothing_ring().0[i] == topology.smoothing_ring().0[i + 1] {
                    assert_eq!(g, o, "{name} {filter}: isolated vertex {i} moved");
                }
                if with_weights && weights[i] == 0.0 {
                    assert_eq!(g, o, "{name} {filter}: locked vertex {i} moved");
                }
                if let Some(d) = d_max {
                    // Up to the f32 rounding of the coordinates.
                    assert!(distance(g, o) <= f64::from(d) + 1e-6 * diagonal);
                }
            }
        }
    }
}

#[test]
fn bent_tube_matches_the_cpu() {
    let Some(gpu) = gpu() else { return };
    check_mesh(
        gpu,
        "bent tube",
        &load("synthetic/synthetic_bent_tube_r3.5.ply"),
    );
}

#[test]
fn scalp_matches_the_cpu() {
    let Some(gpu) = gpu() else { return };
    check_mesh(gpu, "scalp", &load("real/fsaverage_head_scalp_mne.ply"));
}

#[test]
fn open_mesh_with_an_isolated_vertex_matches_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let mesh = open_mesh();
    let topology = Topology::build(&mesh);
    assert!(topology.has_boundary());
    check_mesh(gpu, "open scalp", &mesh);
}

#[test]
fn zero_iterations_and_no_run_give_the_original() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mesh = load("synthetic/synthetic_bent_tube_r3.5.ply");
    let topology = Topology::build(&mesh);
    let mut uploaded = gpu.smoother.upload(device, &mesh, &topology).expect("fits");
    assert_eq!(
        read_positions(device, queue, &uploaded).expect("readback"),
        mesh.positions
    );
    let p = Params {
        iterations: 0,
        ..Params::defaults(Filter::Taubin)
    };
    gpu.smoother
        .smooth(device, queue, &mut uploaded, &p)
        .expect("valid");
    assert_eq!(
        read_positions(device, queue, &uploaded).expect("readback"),
        mesh.positions
    );
}

#[test]
fn bad_input_is_refused_with_a_clear_error() {
    let Some(gpu) = gpu() else { return };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mesh = load("synthetic/synthetic_bent_tube_r3.5.ply");
    let topology = Topology::build(&mesh);
    let mut uploaded = gpu.smoother.upload(device, &mesh, &topology).expect("fits");
    let e = uploaded
        .set_weights(queue, Some(&[1.0; 3]))
        .expect_err("3 weights");
    assert!(matches!(e, GpuError::WeightCount { given: 3, .. }), "{e}");
    let mut p = Params::defaults(Filter::Taubin);
    p.mu = -0.1;
    let e = gpu
        .smoother
        .smooth(device, queue, &mut uploaded, &p)
        .expect_err("mu > -lambda");
    assert!(e.to_string().contains("mu < -lambda"), "{e}");
    // A topology built for another mesh.
    let other = Topology::build(&open_mesh());
    let e = gpu
        .smoother
        .upload(device, &mesh, &other)
        .err()
        .expect("mismatch");
    assert!(matches!(e, GpuError::TopologyMismatch(_)), "{e}");
}

/// Low limits on a real device: a small mesh takes the 2-D dispatch (rows of 4 workgroups) and
/// still matches the CPU; a storage binding limit below the mesh's size refuses the upload.
#[test]
fn small_limits_use_a_2d_grid_and_refuse_what_does_not_fit() {
    let limits = wgpu::Limits {
        max_compute_workgroups_per_dimension: 16,
        ..wgpu::Limits::default()
    };
    let Some(gpu) = gpu_with(Some(limits)) else {
        return;
    };
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    let mesh = load("real/fsaverage_head_scalp_mne.ply");
    let n = mesh.positions.len() as u32;
    let groups = n.div_ceil(meshsmooth::gpu::WORKGROUP_SIZE);
    assert!(
        groups > 16 && groups <= 256,
        "{n} vertices: {groups} workgroups"
    );
    let topology = Topology::build(&mesh);
    let mut uploaded = gpu
        .smoother
        .upload(device, &mesh, &topology)
        .expect("fits a 16 x 16 grid");
    for filter in [Filter::Laplace, Filter::Sinc] {
        let p = params(filter);
        let cpu = smooth(&mesh, &topology, &p, None, &mut NoObserver);
        gpu.smoother
            .smooth(device, queue, &mut uploaded, &p)
            .expect("valid");
        let on_gpu = read_positions(device, queue, &uploaded).expect("readback");
        assert!(
            max_distance(&on_gpu, &cpu) <= 1e-4 * mesh.bounding_box_diagonal(),
            "{filter}"
        );
    }
    drop(gpu);

    let limits = wgpu::Limits {
        max_storage_buffer_binding_size: 16 * 1024,
        ..wgpu::Limits::default()
    };
    let Some(gpu) = gpu_with(Some(limits)) else {
        return;
    };
    let e = gpu
        .smoother
        .upload(&gpu.ctx.device, &mesh, &topology)
        .err()
        .expect("too large");
    assert!(
        matches!(
            e,
            GpuError::TooLarge {
                limit: "max_storage_buffer_binding_size",
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains("max_storage_buffer_binding_size"),
        "{e}"
    );
}
