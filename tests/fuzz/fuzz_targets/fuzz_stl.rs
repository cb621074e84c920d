#![no_main]
//! Fuzzes the STL parser through `load_as(data, Format::Stl)`.

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(data, meshsmooth::io::Format::Stl);
});
