#![no_main]
//! Fuzzes the PLY parser through `load_as(data, Format::Ply)`.

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(data, meshsmooth::io::Format::Ply);
});
