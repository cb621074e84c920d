#![no_main]
//! Fuzzes the glTF parsers through `load_as(data, Format::Gltf)` and `load_as(data, Format::Glb)`.

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(data, meshsmooth::io::Format::Gltf);
    common::check(data, meshsmooth::io::Format::Glb);
});
