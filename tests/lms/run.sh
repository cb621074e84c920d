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
