#![no_main]
//! Fuzzes the DICOM image series reader: the input alone as a one-slice image, and beside a real
//! slice as a series of two, so that the checks between slices meet fuzzed geometry. Either the
//! input is refused or the image has one value per voxel of a grid no larger than asked.

mod common;

use meshsmooth::io::load_image_series;

const SLICE: &[u8] = include_bytes!("../../data/dicom_series/oblique/03cc5f9046.dcm");

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check_image(data, "fuzz.dcm");
    if let Ok(image) = load_image_series(&[("slice.dcm", SLICE), ("fuzz.dcm", data)], 4096) {
        let voxels: usize = image.dims.iter().product();
        assert!(voxels <= 4096 && voxels > 0, "{:?}", image.dims);
        assert_eq!(image.values.len(), voxels);
        assert!(image.affine.0.iter().flatten().all(|v| v.is_finite()));
    }
});
