#!/usr/bin/env bash
# Installs what building, serving and testing meshsmooth need, skipping whatever is already
# present at the right version, so running it again costs a few seconds. Called by
# web/serve.sh (the serve command) and tests/run.sh (the test command).
#
# Usage: bash .ci/install.sh [web]
#   (no argument) everything the tests need;
#   web           only what building the web app needs (no browser, no test tools).
# Needs: Debian 12, Rust by rustup, Node 20 with npm; root or sudo for apt.
set -euo pipefail

MODE="${1:-all}"
case "$MODE" in
    all | web) ;;
    *)
        echo "usage: bash .ci/install.sh [web]" >&2
        exit 2
        ;;
esac

cd "$(dirname "${BASH_SOURCE[0]}")/.."
export PATH="$HOME/.cargo/bin:$PATH"

TRUNK_VERSION=0.21.14
APT_PACKAGES=(chromium chromium-driver mesa-vulkan-drivers libvulkan1)

say() { echo "install: $*"; }

# The wasm-bindgen CLI must be exactly the library version Cargo.lock resolved.
lock_version() {
    awk -v want="$1" '
        /^\[\[package\]\]/ { name = "" }
        $1 == "name" && $3 == "\"" want "\"" { name = want }
        $1 == "version" && name != "" { gsub(/"/, "", $3); print $3; exit }
    ' Cargo.lock
}

# Version printed by `tool --version` (its second word), or nothing when absent.
installed_version() {
    command -v "$1" >/dev/null 2>&1 || return 0
    "$1" --version 2>/dev/null | awk '{ print $2; exit }'
}

as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# --- system packages: headless Chromium, its WebDriver, Mesa's software Vulkan (lavapipe) ---
missing=()
if [ "$MODE" = web ]; then
    APT_PACKAGES=()
fi
for pkg in ${APT_PACKAGES[@]+"${APT_PACKAGES[@]}"}; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$pkg")
    fi
done
if [ ${#missing[@]} -gt 0 ]; then
    say "apt: ${missing[*]}"
    as_root apt-get update -q
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"
else
    say "apt packages present"
fi

# --- Rust target and cargo-installed tools ---
if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    say "rustup target wasm32-unknown-unknown"
    rustup target add wasm32-unknown-unknown
fi

bindgen_version="$(lock_version wasm-bindgen)"
if [ -z "$bindgen_version" ]; then
    echo "install: Cargo.lock names no wasm-bindgen version" >&2
    exit 1
fi
if [ "$(installed_version wasm-bindgen)" != "$bindgen_version" ] ||
    [ "$(installed_version wasm-bindgen-test-runner)" != "$bindgen_version" ]; then
    say "wasm-bindgen-cli $bindgen_version"
    # Not --locked: its lock file names a crate version the registry no longer has.
    cargo install wasm-bindgen-cli --version "$bindgen_version" --force
else
    say "wasm-bindgen-cli $bindgen_version present"
fi

if [ "$MODE" = web ]; then
    : # cargo-nextest runs the native tests only
elif ! cargo nextest --version >/dev/null 2>&1; then
    say "cargo-nextest"
    cargo install --locked cargo-nextest
else
    say "cargo-nextest present ($(cargo nextest --version 2>/dev/null | awk '{ print $2; exit }'))"
fi

if [ "$MODE" = web ]; then
    : # cargo-fuzz runs the parsers' fuzz targets in the tests only
elif ! command -v cargo-fuzz >/dev/null 2>&1; then
    say "cargo-fuzz"
    cargo install --locked cargo-fuzz
else
    say "cargo-fuzz present ($(installed_version cargo-fuzz))"
fi

if [ "$(installed_version trunk)" != "$TRUNK_VERSION" ]; then
    # Trunk's own release profile (fat LTO, one code unit) took 13 minutes to compile here; it
    # only drives cargo, wasm-bindgen and wasm-opt, so a lighter optimisation serves as well.
    say "trunk $TRUNK_VERSION (about 7 minutes on 2 cores)"
    CARGO_PROFILE_RELEASE_LTO=off CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16 CARGO_PROFILE_RELEASE_OPT_LEVEL=1 \
        cargo install --locked trunk --version "$TRUNK_VERSION" --force
else
    say "trunk $TRUNK_VERSION present"
fi

# --- npm packages, installed from the lock file: wasm-opt (binaryen) for the web build;
# playwright-core (drives the apt-installed chromium, downloads no browser) and gltf-validator
# for the end-to-end tests ---
lock_sum="$(sha256sum web/package-lock.json | cut -d' ' -f1)"
stamp=web/node_modules/.installed-from-lock
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$lock_sum" ]; then
    say "npm packages of web/"
    (cd web && npm ci --no-audit --no-fund)
    echo "$lock_sum" >"$stamp"
else
    say "npm packages of web/ present"
fi

say "done"
