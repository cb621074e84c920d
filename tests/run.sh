#!/usr/bin/env bash
# The test command: everything CI runs, in order, stopping at the first failure.
#
#   bash tests/run.sh
#
# Installs what it needs first (idempotent, see .ci/install.sh). The test meshes are read from
# ../shared/data, beside the checkout.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
export PATH="$PWD/web/node_modules/.bin:$HOME/.cargo/bin:$PATH"
# GPU tests must find an adapter (lavapipe on CI machines) instead of skipping.
export REQUIRE_GPU=1
# Build outputs live outside the checkout, so a fresh clone on the same machine reuses the
# compiled dependencies (native, wasm32 tests, the web build, fuzz) and compiles only this crate.
# Every install step still runs (.ci/install.sh); a new machine starts with an empty cache.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/meshsmooth/target}"
mkdir -p "$CARGO_TARGET_DIR"
# Each clone path adds its own copy of this crate's outputs; start over once they pile up.
cache_kib=$(du -sk "$CARGO_TARGET_DIR" 2>/dev/null | cut -f1)
if [ "${cache_kib:-0}" -gt $((40 * 1024 * 1024)) ]; then
    echo "tests/run.sh: build cache $CARGO_TARGET_DIR past 40 GiB: emptying it"
    rm -rf "$CARGO_TARGET_DIR" && mkdir -p "$CARGO_TARGET_DIR"
fi

if [ ! -d ../shared/data ]; then
    echo "tests/run.sh: the test meshes are missing: expected ../shared/data beside the checkout" >&2
    exit 1
fi

started=$SECONDS
passed=()
current=""
on_exit() {
    local status=$?
    if [ "$status" -ne 0 ]; then
        echo >&2
        echo "tests/run.sh: FAILED in stage '$current' (exit $status) after $((SECONDS - started)) s; passed: ${passed[*]:-none}" >&2
    fi
}
trap on_exit EXIT

stage() {
    current="$1"
    shift
    echo
    echo "=== $current: $*"
    local t=$SECONDS
    "$@"
    echo "--- $current: ok ($((SECONDS - t)) s)"
    passed+=("$current")
}

stage install bash .ci/install.sh
stage fmt cargo fmt --check
stage clippy-native cargo clippy --all-targets -- -D warnings
stage clippy-wasm32 cargo clippy --target wasm32-unknown-unknown --all-targets -- -D warnings
# The library's documentation builds without a broken or private link.
stage doc env RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --lib
# cargo-nextest runs the test binaries side by side (cargo test runs them one after another).
stage test-native cargo nextest run --no-fail-fast
# Every parser's fuzz target, a bounded time each (tests/fuzz/run.sh).
stage fuzz env FUZZ_SECONDS="${FUZZ_SECONDS:-10}" bash tests/fuzz/run.sh
# The library's tests, tests/wasm_io.rs and tests/wasm_gpu.rs (the GPU engine on the browser's
# WebGPU) compiled to wasm32 and run in headless Chromium by wasm-bindgen's test runner (the
# runner in .cargo/config.toml, flags in webdriver.json): what `wasm-pack test --headless
# --chrome` runs, without the second build of the library it makes first. The other integration
# tests read files and start processes: native only, so they are not built for the browser.
stage test-wasm32-browser env CHROMEDRIVER="${CHROMEDRIVER:-/usr/bin/chromedriver}" \
    cargo test --target wasm32-unknown-unknown --lib --test wasm_io --test wasm_gpu
stage web-build trunk build --release
# The LMS packages: the launch page's runtime against scorm-again, and the phantom's SCORM 1.2,
# SCORM 2004 and cmi5 packages against their manifests' schemas (tests/lms/run.sh).
stage lms bash tests/lms/run.sh
# End-to-end tests of the built app (dist/) in headless Chromium, with WebGPU and without, against
# the CLI's numbers; screenshots in target/e2e/. (The browser benchmarks are a command of their
# own: bash tests/e2e/run.sh --bench.)
stage e2e bash tests/e2e/run.sh

echo
echo "tests/run.sh: all ${#passed[@]} stages passed (${passed[*]}) in $((SECONDS - started)) s"
