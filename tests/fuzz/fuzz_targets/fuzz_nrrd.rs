#![no_main]
//! Fuzzes the NRRD label-map parser (raw and gzip, layers, Slicer's segment keys) through
//! `load_label_map(data, "fuzz.seg.nrrd")`: it either refuses the input or returns a label map
//! whose codes and segments are consistent and whose surfaces are closed; and through
//! `load_image(data, "fuzz.nrrd")`, the same header feeding an image's reduced intensities.

mod common;

use meshsmooth::io::{load_label_map, LabelMapOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(map) = load_label_map(data, "fuzz.seg.nrrd", &LabelMapOptions::default()) {
        common::check_label_map(&map);
    }
    common::check_image(data, "fuzz.nrrd");
});
