#!/usr/bin/env bash
# End-to-end tests of the built web app in headless Chromium, in two runs:
#   webgpu  WebGPU on SwiftShader (the app's GPU engine): every test but the CPU engine's own;
#   cpu     no WebGPU: eframe falls back to WebGL2 and the app uses its CPU engine: the tests
#           whose outcome the engine or the renderer changes (testIn in lib/suite.mjs).
# Both runs always happen; the script fails if either failed.
#
#   bash tests/e2e/run.sh              (after `trunk build --release` made dist/)
#   E2E_MODES=cpu bash tests/e2e/run.sh
#   bash tests/e2e/run.sh --test-name-pattern='^5 '   (extra arguments go to node --test)
#   bash tests/e2e/run.sh --bench      the browser benchmarks (*.bench.mjs) instead of the tests
#
# Screenshots and exported files: target/e2e/<mode>/; benchmark lines: target/e2e/bench.json;
# the whole-body label map: target/e2e/whole_body/ (E2E_WHOLE_BODY=DIR takes one made before).
# Needs: web/node_modules (npm ci in web/, .ci/install.sh), /usr/bin/chromium, ../shared/data.
# To test another build: E2E_DIST=/path/to/dist MESHSMOOTH_CLI=/path/to/meshsmooth (then the
# CLI is not built here).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/../.."
export PATH="$PWD/web/node_modules/.bin:$HOME/.cargo/bin:$PATH"

dist="${E2E_DIST:-dist}"
if [ ! -f "$dist/index.html" ]; then
    echo "tests/e2e/run.sh: $dist/index.html is missing: build the page first (trunk build --release)" >&2
    exit 1
fi
if [ ! -d web/node_modules/playwright-core ] || [ ! -d web/node_modules/gltf-validator ]; then
    echo "tests/e2e/run.sh: web/node_modules lacks playwright-core or gltf-validator: run bash .ci/install.sh" >&2
    exit 1
fi

files=(tests/e2e/*.test.mjs)
# The CLI is the reference for every number the app reports. The tests take the build that
# `cargo test` made (the test profile optimises as release does), so the test command compiles
# the CLI once; the benchmarks time it, so they take the release build. Cargo skips a build that
# is up to date.
profile=test
profile_dir=debug
if [ "${1:-}" = "--bench" ]; then
    shift
    files=(tests/e2e/*.bench.mjs)
    profile=release
    profile_dir=release
fi
if [ -z "${MESHSMOOTH_CLI:-}" ]; then
    cargo build --profile "$profile" --bin meshsmooth --quiet
    target_dir="${CARGO_TARGET_DIR:-target}"
    case "$target_dir" in
        /*) ;;
        *) target_dir="$PWD/$target_dir" ;;
    esac
    export MESHSMOOTH_CLI="$target_dir/$profile_dir/meshsmooth"
fi

rm -rf target/e2e
mkdir -p target/e2e

# The whole-body CT label map whole_body.test.mjs and the benchmarks open, made afresh by its
# generator (never committed).
if [ -z "${E2E_WHOLE_BODY:-}" ]; then
    cargo build --profile "$profile" --example whole_body --quiet
    examples="${CARGO_TARGET_DIR:-target}/$profile_dir/examples"
    export E2E_WHOLE_BODY="$PWD/target/e2e/whole_body"
    "$examples/whole_body" "$E2E_WHOLE_BODY" > /dev/null
fi

failed=()
for mode in ${E2E_MODES:-webgpu cpu}; do
    echo
    echo "=== e2e ($mode)"
    if ! E2E_MODE="$mode" node --test --test-reporter=spec "$@" "${files[@]}"; then
        failed+=("$mode")
    fi
done

echo
if [ ${#failed[@]} -gt 0 ]; then
    echo "tests/e2e/run.sh: failed in: ${failed[*]} (screenshots in target/e2e/)" >&2
    exit 1
fi
echo "tests/e2e/run.sh: ${E2E_MODES:-webgpu cpu}: passed (screenshots in target/e2e/)"
