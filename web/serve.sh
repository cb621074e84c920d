#!/usr/bin/env bash
# The serve command: installs what the web build needs (idempotent, see .ci/install.sh), then
# builds the web app in release mode and serves it on http://127.0.0.1:8080, rebuilding on
# changes. PORT=9000 bash web/serve.sh picks another port.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash .ci/install.sh web
export PATH="$PWD/web/node_modules/.bin:$HOME/.cargo/bin:$PATH"
exec trunk serve --release --address 127.0.0.1 --port "${PORT:-8080}"
