//! The shared test meshes (../shared/data beside the repository, or `MESHSMOOTH_DATA`).
#![allow(dead_code)]

use meshsmooth::mesh::{Mesh, Topology};
use std::path::PathBuf;

/// Every closed shared mesh, with its Euler characteristic from the data README.
pub const CLOSED_MESHES: [(&str, i64); 8] = [
    ("real/fsaverage5_pial_left.ply", 2),
    ("real/fsaverage_head_scalp_mne.ply", 2),
    ("segmentations/seg_mni152_brainmask_2mm.ply", 2),
    ("segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply", -606),
    ("synthetic/synthetic_sphere_r20.ply", 2),
    ("synthetic/synthetic_torus_R24_r8.ply", 0),
    ("synthetic/synthetic_bent_tube_r3.5.ply", 2),
    ("synthetic/synthetic_ellipsoid_30_20_12.ply", 2),
];

/// The large staircase benchmark mesh (206,512 vertices).
pub const LARGE: &str = "segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply";

pub fn data_dir() -> PathBuf {
    match std::env::var_os("MESHSMOOTH_DATA") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
    }
}

pub fn read(relative: &str) -> Vec<u8> {
    let path = data_dir().join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// Loads a shared mesh and builds its topology.
pub fn load(relative: &str) -> (Mesh, Topology) {
    let mesh = meshsmooth::io::load(&read(relative), relative)
        .unwrap_or_else(|e| panic!("{relative}: {e}"));
    let topology = Topology::build(&mesh);
    (mesh, topology)
}
