//! The `meshsmooth` binary: the command-line tool natively, the web app on wasm32.

#[cfg(all(not(target_arch = "wasm32"), feature = "cli"))]
fn main() -> std::process::ExitCode {
    meshsmooth::cli::main()
}

#[cfg(all(not(target_arch = "wasm32"), not(feature = "cli")))]
fn main() -> std::process::ExitCode {
    eprintln!("meshsmooth: built without its command-line tool (the `cli` feature)");
    std::process::ExitCode::FAILURE
}

#[cfg(target_arch = "wasm32")]
fn main() {
    meshsmooth::app::start();
}
