//! The `meshsmooth` binary: the command-line tool natively, the web app on wasm32.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    meshsmooth::cli::main()
}

#[cfg(target_arch = "wasm32")]
fn main() {
    meshsmooth::app::start();
}
