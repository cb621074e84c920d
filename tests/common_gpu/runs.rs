//! Shared meshes and runs of the GPU measure and drift tests.
#![allow(dead_code)]

use super::data;
use super::device::Gpu;
use meshsmooth::gpu::{read_result, GpuMesh, SmoothResult};
use meshsmooth::mesh::{Mesh, Topology};
use meshsmooth::metrics::Original;
use meshsmooth::smooth::{Filter, Params};

pub const TUBE: &str = "synthetic/synthetic_bent_tube_r3.5.ply";
pub const SCALP: &str = "real/fsaverage_head_scalp_mne.ply";
pub const PIAL: &str = "real/fsaverage5_pial_left.ply";
pub const SPHERE: &str = "synthetic/synthetic_sphere_r20.ply";
pub const BRAINMASK: &str = "segmentations/seg_mni152_brainmask_2mm.ply";

/// A shared mesh as the measures see it.
pub fn original(relative: &str) -> Original {
    let (mesh, topology) = data::load(relative);
    Original::new(&mesh, &topology)
}

/// The scalp opened: a cap cut off the top, every 40th triangle removed, and one vertex no
/// triangle uses (as in tests/gpu_filters.rs).
pub fn open_original() -> Original {
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

pub fn params(filter: Filter, iterations: u32) -> Params {
    Params {
        iterations,
        ..Params::defaults(filter)
    }
}

/// Runs `p` on the GPU and reads back the positions and references.
pub fn run(gpu: &Gpu, mesh: &mut GpuMesh, p: &Params) -> SmoothResult {
    let (device, queue) = (&gpu.ctx.device, &gpu.ctx.queue);
    gpu.smoother.smooth(device, queue, mesh, p).expect("valid");
    read_result(device, queue, mesh).expect("readback")
}

/// Weights in [0, 1], every 7th vertex locked (as in tests/gpu_filters.rs).
pub fn test_weights(n: usize) -> Vec<f32> {
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
