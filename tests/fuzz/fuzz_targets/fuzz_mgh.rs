#![no_main]
//! Fuzzes the MGH/MGZ label-map parser (raw and gzip) through `load_label_map(data, "fuzz.mgz")`:
//! it either refuses the input or returns a label map whose codes are consistent and whose
//! surfaces are closed; and through `load_image(data, "fuzz.mgz")`, as a FreeSurfer image.

mod common;

use meshsmooth::io::{load_label_map, LabelMapOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(map) = load_label_map(data, "fuzz.mgz", &LabelMapOptions::default()) {
        assert_eq!(map.layers.len(), 1, "MGH has one layer");
        common::check_label_map(&map);
    }
    common::check_image(data, "fuzz.mgz");
});
