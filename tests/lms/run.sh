#!/usr/bin/env bash
# The LMS packages' checks that need no browser: the launch page's runtime against scorm-again's
# SCORM APIs and a fake record store (node --test tests/lms_runtime/), and the shared phantom
# case with its lesson packaged by the CLI in each format, its manifest validated against the
# published schemas (validate.sh). The browser's part is tests/e2e/lms.test.mjs.
#
#   bash tests/lms/run.sh          (after `trunk build --release` made dist/; dist/viewer/ is packed)
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/../.."
viewer="${E2E_DIST:-dist}/viewer"
if [ ! -f "$viewer/index.html" ]; then
    echo "tests/lms/run.sh: $viewer/index.html is missing: build the page first (trunk build --release)" >&2
    exit 1
fi

node --test tests/lms_runtime/

# The CLI the other tests use (cargo test's profile); Cargo skips it when it is up to date.
cargo build --profile test --bin meshsmooth --quiet
target_dir="${CARGO_TARGET_DIR:-target}"
cli="$target_dir/debug/meshsmooth"

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
data=../shared/data/labelmaps
for format in scorm12 scorm2004 cmi5; do
    "$cli" case package "$data/case_phantom_shared.nii.gz" \
        --colors "$data/case_phantom_shared_labels.txt" \
        --lesson tests/data/phantom_lesson.json --title "Abdominal phantom" --search local \
        --format "$format" --viewer "$viewer" -o "$out/phantom-$format.zip"
    bash tests/lms/validate.sh "$out/phantom-$format.zip"
done

# The student's viewer leaves the author's work out: none of the writers and readers only the
# author runs (SCORM's and cmi5's manifests, DICOM SEG's and FreeSurfer's tables, Suggest all)
# may reach its wasm, and it stays well under the app's (it was 31 % smaller gzipped when the
# split was made). Something author-only that reaches the viewer fails here by name.
app_wasm=("${E2E_DIST:-dist}"/meshsmooth-*_bg.wasm)
viewer_wasm=("$viewer"/meshsmooth-*_bg.wasm)
for author_only in imsmanifest adlcp:masteryscore Left-Cerebral-White-Matter ReferencedSegmentNumber "Suggest all"; do
    if ! grep -q -a -F "$author_only" "${app_wasm[0]}"; then
        echo "tests/lms/run.sh: the app's wasm lacks '$author_only': the check's strings are stale" >&2
        exit 1
    fi
    if grep -q -a -F "$author_only" "${viewer_wasm[0]}"; then
        echo "tests/lms/run.sh: the viewer's wasm holds the author's '$author_only'" >&2
        exit 1
    fi
done
app_gz=$(gzip -9 -c "${app_wasm[0]}" | wc -c)
viewer_gz=$(gzip -9 -c "${viewer_wasm[0]}" | wc -c)
echo "viewer wasm: $viewer_gz bytes gzipped, the app's $app_gz"
if (( viewer_gz * 100 > app_gz * 80 )); then
    echo "tests/lms/run.sh: the viewer's wasm ($viewer_gz bytes gzipped) is over 80 % of the app's ($app_gz)" >&2
    exit 1
fi
