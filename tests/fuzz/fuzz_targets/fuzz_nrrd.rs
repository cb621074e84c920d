#![no_main]
//! Fuzzes the NRRD label-map parser (raw and gzip, layers, Slicer's segment keys) through
//! `load_label_map(data, "fuzz.seg.nrrd")`: it either refuses the input or returns a label map
//! whose codes and segments are consistent.

use meshsmooth::io::{load_label_map, LabelMapOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(map) = load_label_map(data, "fuzz.seg.nrrd", &LabelMapOptions::default()) else {
        return;
    };
    let voxels = map.voxel_count();
    assert!(
        map.affine.0.iter().flatten().all(|v| v.is_finite()),
        "a finite affine"
    );
    assert!(!map.layers.is_empty(), "at least one layer");
    for layer in &map.layers {
        assert_eq!(layer.codes.len(), voxels, "a code per voxel");
        assert_eq!(layer.values[0], 0, "code 0 is background");
        assert!(
            layer
                .codes
                .iter()
                .all(|&c| (c as usize) < layer.values.len()),
            "codes in range"
        );
    }
    assert!(
        map.segments.iter().all(|s| s.layer < map.layers.len()),
        "segments in a layer"
    );
    // Small enough maps go on to the surfaces, which must come out closed (or be refused).
    if voxels <= 1 << 16 {
        if let Ok(structures) = meshsmooth::segmentation::extract(&map, &[], &Default::default()) {
            for s in &structures {
                let report = meshsmooth::mesh::MeshReport::new(
                    &s.mesh,
                    &meshsmooth::mesh::Topology::build(&s.mesh),
                );
                assert_eq!(report.boundary_edges, 0, "a closed surface");
                assert_eq!(report.nonmanifold_edges, 0, "a manifold surface");
            }
        }
    }
});
