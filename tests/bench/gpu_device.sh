#!/usr/bin/env bash
# The GPU engine on real hardware, for a session lent a device machine (the `device` tool): the
# machine reaches nothing outside it, so what it runs is prepared here and carried.
#
#   bash tests/bench/gpu_device.sh prepare        # here: .device/ (git-ignored) with a stripped
#                                                 # release build, the 206k-vertex brain and the
#                                                 # whole-body CT map
#   bash tests/bench/gpu_device.sh run [MESH]     # there (carry .device and the .gl loaders the
#                                                 # device README names), or here on lavapipe
#
# Printed, not asserted: on the mesh (the brain unless MESH is given), `bench` with HC on the CPU
# and on the GPU engine (its first line names the adapter), and `suggest --search local` with
# each engine, with their seconds; last `case build` on the whole-body map on the machine's
# cores (the CLI's Suggest all runs on the CPU engine; the GPU engine takes it in the page only).
set -euo pipefail
cd "$(dirname "$0")/../.."
DEV=.device

prepare() {
    local target=${CARGO_TARGET_DIR:-target}
    cargo build --release --bin meshsmooth --example whole_body
    mkdir -p "$DEV"
    grep -qx "/$DEV/" .git/info/exclude 2>/dev/null || echo "/$DEV/" >>.git/info/exclude
    strip -o "$DEV/meshsmooth" "$target/release/meshsmooth"
    cp ../shared/data/segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply "$DEV/brain.ply"
    "$target/release/examples/whole_body" "$DEV/"
    du -sh "$DEV"
}

timed() {
    local start end
    start=$(date +%s.%N)
    "$@"
    end=$(date +%s.%N)
    echo "($(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }') s: $*)"
}

run() {
    local mesh=${1:-$DEV/brain.ply}
    local ms=$DEV/meshsmooth
    for f in .gl/*.deb; do
        [ -e "$f" ] && dpkg -x "$f" /
    done
    command -v ldconfig >/dev/null && ldconfig 2>/dev/null || true
    if [ -d /usr/local/nvidia/share/vulkan/icd.d ]; then
        export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    fi
    echo "$(nproc) cores"
    for backend in cpu gpu; do
        timed "$ms" bench "$mesh" --filter hc --iterations 20 --repeat 3 --backend "$backend" || true
    done
    for backend in cpu gpu; do
        timed "$ms" suggest "$mesh" --filter hc --search local --backend "$backend" --json || true
    done
    if [ -e "$DEV/whole_body.nii.gz" ]; then
        timed "$ms" case build "$DEV/whole_body.nii.gz" --colors "$DEV/whole_body_labels.txt" \
            -o /tmp/whole_body_case.glb --json | grep -oE '"([a-z_]*seconds|evaluations)": [0-9.]+'
    fi
}

case "${1:-}" in
prepare) prepare ;;
run) shift; run "$@" ;;
*) echo "usage: $0 prepare | run [MESH]" >&2; exit 2 ;;
esac
