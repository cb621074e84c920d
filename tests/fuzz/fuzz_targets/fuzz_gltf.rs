#![no_main]
//! Fuzzes the glTF parsers through `load_as(data, Format::Gltf)` and `load_as(data, Format::Glb)`,
//! and the case reader: a scene node by node, made a case.

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(data, meshsmooth::io::Format::Gltf);
    common::check(data, meshsmooth::io::Format::Glb);
    check_case(data);
});

/// A case read from any bytes has, per structure, indices in range and finite positions, and
/// a smoothed surface (when any) with one position per original vertex.
fn check_case(data: &[u8]) {
    let Ok(scene) = meshsmooth::io::load_gltf_scene(data, "fuzz.glb") else {
        return;
    };
    let Ok(case) = meshsmooth::case::from_gltf_scene(scene, "fuzz.glb") else {
        return;
    };
    if let Some(image) = &case.image {
        assert_eq!(image.voxels.len(), image.dims.iter().product::<usize>());
    }
    for s in &case.structures {
        let n = s.original.positions.len();
        assert!(s
            .original
            .triangles
            .iter()
            .flatten()
            .all(|&v| (v as usize) < n));
        assert!(s.original.positions.iter().flatten().all(|c| c.is_finite()));
        if let Some(smoothed) = &s.smoothed {
            assert_eq!(smoothed.positions.len(), n);
            assert!(smoothed.positions.iter().flatten().all(|c| c.is_finite()));
        }
    }
}
