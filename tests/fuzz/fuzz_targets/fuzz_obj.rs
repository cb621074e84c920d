#![no_main]
//! Fuzzes the OBJ parser through `load_as(data, Format::Obj)`.

mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::check(data, meshsmooth::io::Format::Obj);
});
