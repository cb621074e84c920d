#!/usr/bin/env bash
# Trunk's post-build hook (Trunk.toml): builds the student's viewer, the web app without its
# authoring half (the `web-app` feature alone), into the app's `viewer/` folder. The page's
# Export for LMS and `meshsmooth case package` put that build in a package.
set -euo pipefail

# The viewer's own build runs this hook too; it has no viewer to add.
if [ -n "${MESHSMOOTH_VIEWER_BUILD:-}" ]; then
    exit 0
fi
release=()
if [ "${TRUNK_PROFILE:-}" = release ]; then
    release=(--release)
fi
MESHSMOOTH_VIEWER_BUILD=1 trunk build "${release[@]}" --no-default-features --features web-app \
    --dist "$TRUNK_STAGING_DIR/viewer"
