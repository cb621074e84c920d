//! Shared meshes and runs of the GPU measure and drift tests.
#![allow(dead_code)]

use super::data;
use super::device::Gpu;
use super::open_scalp::open_scalp;
use meshsmooth::gpu::{read_result, GpuMesh, SmoothResult};
use meshsmooth::mesh::Topology;
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

/// The scalp opened (see `open_scalp`), as the measures see it.
pub fn open_original() -> Original {
    let (scalp, _) = data::load(SCALP);
    let mesh = open_scalp(&scalp);
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
