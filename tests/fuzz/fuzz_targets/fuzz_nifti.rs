#![no_main]
//! Fuzzes the NIfTI parser (raw and gzip) through `load_label_map(data, "fuzz.nii")`: it
//! either refuses the input or returns a label map whose codes are consistent and whose
//! surfaces are closed; and through `load_image`, the same header feeding an image's reduced
//! intensities: refused, or one value per voxel of a grid no larger than asked.

mod common;

use meshsmooth::io::{load_label_map, LabelMapOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(map) = load_label_map(data, "fuzz.nii", &LabelMapOptions::default()) {
        assert_eq!(map.layers.len(), 1, "NIfTI has one layer");
        common::check_label_map(&map);
    }
    common::check_image(data, "fuzz.nii");
});
