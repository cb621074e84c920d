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
});
