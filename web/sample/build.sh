#!/usr/bin/env bash
# Builds the bundled sample case (web/sample/abdomen_phantom.glb, what the page opens at start)
# from its label map, lesson and names in other languages, the way an author's pipeline would. A test builds it again and
# checks that the committed case is what this gives: run this after a change that alters it.
#
# Usage: bash web/sample/build.sh [OUTPUT]      (MESHSMOOTH names the binary to use)
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")"
out="${1:-abdomen_phantom.glb}"
if [ -n "${MESHSMOOTH:-}" ]; then
    run=("$MESHSMOOTH")
else
    run=(cargo run --release -q --)
fi
"${run[@]}" case build abdomen_phantom.seg.nrrd \
    --title "Abdominal phantom" \
    --description "A synthetic abdominal case: four structures from a label map, with a tour, labels and a quiz." \
    --lesson abdomen_phantom_lesson.json \
    --names abdomen_phantom_names.json \
    -o "$out"
