#!/usr/bin/env bash
# Runs every parser's fuzz target for a bounded time (libFuzzer through cargo-fuzz), starting
# from a corpus of the shared test files, so the test command catches a parser that panics,
# loops or allocates without bound on malformed input.
#
#   bash tests/fuzz/run.sh            (FUZZ_SECONDS per target, default 20)
#
# No sanitizer: the parsers are safe Rust, so what a run can find is a panic, a time-out or an
# allocation past -malloc_limit_mb; ASan would only slow the runs down. RUSTC_BOOTSTRAP lets the
# stable toolchain take the -Z flags cargo-fuzz passes.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/../.."
export RUSTC_BOOTSTRAP=1
seconds="${FUZZ_SECONDS:-20}"
data=../shared/data
work=target/fuzz
mkdir -p "$work"

corpus() {
    # A seed directory of small shared files with the given extensions, the tests' own files
    # (tests/data: MGZ volumes, DICOM SEGs) and this folder's seeds (tests/fuzz/seeds: a compressed case
    # GLB), which the shared data has none of.
    local dir="$work/corpus-$1"
    shift
    mkdir -p "$dir"
    for pattern in "$@"; do
        find "$data" tests/data tests/fuzz/seeds -name "$pattern" -size -2M -exec cp -n {} "$dir/" \;
    done
    echo "$dir"
}

run() {
    local target="$1" seeds="$2" max_len="${3:-65536}" log="$work/$1.log"
    echo "fuzz: $target for ${seconds} s"
    if ! cargo fuzz run --fuzz-dir tests/fuzz --sanitizer none "$target" "$seeds" -- \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
        -max_len="$max_len" -dict=tests/fuzz/meshes.dict -print_final_stats=1 >"$log" 2>&1; then
        tail -n 60 "$log"
        echo "fuzz: $target found a problem (whole log: $log)" >&2
        return 1
    fi
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" || true
}

# Label maps: a short input still declares volumes up to what deflate could expand it to, so
# shorter inputs keep each run's buffers small and the runs many.
run fuzz_nifti "$(corpus nifti '*.nii.gz')" 8192
run fuzz_nrrd "$(corpus nrrd '*.nrrd')" 8192
run fuzz_mgh "$(corpus mgh '*.mgz')" 8192
# DICOM SEG: the seeds are up to 180 KB; longer inputs let the fuzzer keep whole frames.
run fuzz_dicom_seg "$(corpus dicom_seg '*.dcm')" 32768
# DICOM image slices (and the SEGs, which it must refuse).
run fuzz_dicom_series "$(corpus dicom_series '*.dcm')" 8192
run fuzz_stl "$(corpus stl '*.stl')"
run fuzz_obj "$(corpus obj '*.obj')"
run fuzz_ply "$(corpus ply '*.ply')"
run fuzz_gltf "$(corpus gltf '*.glb' '*.gltf')"
echo "fuzz: every target ran ${seconds} s without a finding"
