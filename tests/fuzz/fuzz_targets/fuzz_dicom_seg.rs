#![no_main]
//! Fuzzes the DICOM SEG label-map parser through `load_label_map(data, "fuzz.dcm")`: it either
//! refuses the input or returns a label map whose codes are consistent and whose surfaces are
//! closed.

mod common;

use meshsmooth::io::{load_label_map, LabelMapOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(map) = load_label_map(data, "fuzz.dcm", &LabelMapOptions::default()) {
        common::check_label_map(&map);
    }
});
