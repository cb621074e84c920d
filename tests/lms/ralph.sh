#!/usr/bin/env bash
# A real xAPI record store (LRS) for the cmi5 tests: Ralph (PyPI: ralph-malph), its statements
# API over HTTP Basic auth, statements kept in a JSON-lines file under a folder the caller gives.
# Installed into a virtual environment outside the checkout on first use; skipped when present.
#
# Usage: bash tests/lms/ralph.sh install                 install only (prints nothing on success)
#        bash tests/lms/ralph.sh start DATA_DIR PORT     start in the background on 127.0.0.1:PORT,
#                                                        wait until it answers, print its PID
#        bash tests/lms/ralph.sh stop DATA_DIR           stop the one started with DATA_DIR
#        bash tests/lms/ralph.sh status DATA_DIR         exit 0 when it runs (prints PID and URL)
#
# With it started:
#   endpoint     http://127.0.0.1:PORT/xAPI/   (statements: /xAPI/statements; GET, POST, PUT)
#   credentials  student / secret (Basic), agent mailto:student@example.org, scope "all"
#   health       GET /__heartbeat__ (no auth)   whoami: GET /whoami (auth)
#   in DATA_DIR  auth.json (Ralph's credentials file, rewritten on each start), lrs/fs_lrs.jsonl
#                (the statements; kept across restarts), ralph.log, ralph.pid, app/ (Ralph's
#                own settings folder)
# Ralph 5.1.0 serves the Statement API only: no Activity State API (/xAPI/activities/state), no
# Agent Profile or Activity Profile API, no /xAPI/about (all 404). cmi5's LMS.LaunchData (a State
# API document) needs a server of its own in front of it. Two faults of its fs backend are
# worked around (see LAUNCHER below). It does not check nor send X-Experience-API-Version; GET
# with statementId answers {"statements": [...]}, not the bare statement; a statement it cannot
# parse gets a 500 (a 400 in xAPI). For a page of another origin, export
# RALPH_RUNSERVER_CORS_ALLOW_ORIGINS (a JSON list of origins) before start.
#
# Environment: MESHSMOOTH_LMS_CACHE (default $HOME/.cache/meshsmooth/lms; the virtual environment
# is ralph-venv in it), RALPH_START_TIMEOUT (seconds to wait for it to answer, default 60).
# Needs: python3 with its venv module, the PyPI registry (first run), curl.
set -euo pipefail

RALPH_VERSION=5.1.0
# What pip installs. requests: ralph.api.auth.oidc imports it, but ralph-malph 5.1.0's lrs extra
# does not pull it in. pydantic and pydantic-settings, which Ralph leaves open below 3.0: the
# versions this was tested with (see LAUNCHER for what Ralph's fs backend already gets wrong).
PIP_SPECS=("ralph-malph[cli,lrs]==$RALPH_VERSION" "requests==2.34.2" "pydantic==2.14.4"
    "pydantic-settings==2.16.3")
CACHE="${MESHSMOOTH_LMS_CACHE:-$HOME/.cache/meshsmooth/lms}"
VENV="$CACHE/ralph-venv"
USERNAME=student
PASSWORD=secret
AGENT_MBOX=mailto:student@example.org

fail() {
    echo "tests/lms/ralph.sh: $*" >&2
    exit 1
}

usage() {
    echo "usage: bash tests/lms/ralph.sh install | start DATA_DIR PORT | stop DATA_DIR | status DATA_DIR" >&2
    exit 2
}

installed() {
    [ -x "$VENV/bin/python" ] && [ -x "$VENV/bin/ralph" ] &&
        [ "$(cat "$VENV/.meshsmooth-specs" 2>/dev/null)" = "${PIP_SPECS[*]}" ] &&
        "$VENV/bin/python" - "$RALPH_VERSION" <<'PY' >/dev/null 2>&1
import sys
from importlib.metadata import version
assert version("ralph-malph") == sys.argv[1]
import bcrypt, click, fastapi, uvicorn  # the cli and lrs extras
import requests  # imported by ralph.api.auth.oidc, see PIP_SPECS
import ralph.cli
PY
}

ensure_installed() {
    installed && return 0
    command -v python3 >/dev/null 2>&1 || fail "python3 is missing"
    echo "tests/lms/ralph.sh: installing ralph-malph $RALPH_VERSION into $VENV" >&2
    mkdir -p "$CACHE"
    rm -rf "$VENV"
    local log
    log="$(mktemp)"
    if ! python3 -m venv "$VENV" >"$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        fail "python3 -m venv failed (output above; on Debian's own python3 install python3-venv)"
    fi
    if ! "$VENV/bin/python" -m pip install --disable-pip-version-check --no-input -q \
        "${PIP_SPECS[@]}" >"$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        rm -rf "$VENV"
        fail "pip install ${PIP_SPECS[*]} failed (output above): is PyPI reachable?"
    fi
    rm -f "$log"
    echo "${PIP_SPECS[*]}" >"$VENV/.meshsmooth-specs"
    installed || fail "ralph-malph $RALPH_VERSION installed but does not import; see $VENV"
}

# The PID in DATA_DIR/ralph.pid when that process still runs, else nothing.
running_pid() {
    local pidfile="$1/ralph.pid" pid
    [ -f "$pidfile" ] || return 0
    pid="$(cat "$pidfile")"
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
        echo "$pid"
    fi
}

# Ralph's settings for a server of DATA_DIR, as environment variables (what `ralph runserver
# --backend fs` sets before starting uvicorn).
ralph_env() {
    local data="$1"
    export RALPH_APP_DIR="$data/app"
    export RALPH_AUTH_FILE="$data/auth.json"
    export RALPH_RUNSERVER_BACKEND=fs
    export RALPH_RUNSERVER_AUTH_BACKENDS=basic
    export RALPH_BACKENDS__LRS__FS__DEFAULT_DIRECTORY_PATH="$data/lrs"
    export RALPH_BACKENDS__DATA__FS__DEFAULT_DIRECTORY_PATH="$data/lrs"
    export RALPH_LRS_RESTRICT_BY_AUTHORITY=false
    export RALPH_LRS_RESTRICT_BY_SCOPES=false
}

# Two faults of Ralph 5.1.0's fs backend, worked around in the server process:
# - The statements API writes with the backend's default operation, CREATE, which the fs backend
#   refuses once its file exists (500 "Statements bulk indexation failed", log: "fs_lrs.jsonl
#   already exists and overwrite is not allowed"): every POST or PUT after the first would fail.
#   The backend appends instead.
# - The verb and activity filters of GET /xAPI/statements compare the query's IRI object with the
#   stored string, never equal: ?verb= and ?activity= always answered no statement. They are
#   given the IRI as a string.
LAUNCHER='
import sys
from ralph.backends.data.base import BaseOperationType
from ralph.backends.lrs.fs import FSLRSBackend
FSLRSBackend.default_operation_type = BaseOperationType.APPEND
def as_str(value):
    return None if value is None else str(getattr(value, "root", value))
by_verb, by_activity = FSLRSBackend._add_filter_by_verb, FSLRSBackend._add_filter_by_activity
FSLRSBackend._add_filter_by_verb = staticmethod(lambda filters, verb: by_verb(filters, as_str(verb)))
FSLRSBackend._add_filter_by_activity = staticmethod(
    lambda filters, activity, related: by_activity(filters, as_str(activity), related))
import uvicorn
uvicorn.run("ralph.api:app", host=sys.argv[1], port=int(sys.argv[2]), log_level="warning")
'

start() {
    local data="$1" port="$2"
    case "$port" in
        '' | *[!0-9]*) fail "PORT must be a number, not '$port'" ;;
    esac
    ensure_installed
    command -v curl >/dev/null 2>&1 || fail "curl is missing"
    local pid
    if [ -d "$data" ]; then
        pid="$(running_pid "$data")"
        [ -z "$pid" ] || fail "a Ralph started with $data already runs (PID $pid): stop it first"
    fi
    if curl -s -o /dev/null --max-time 2 "http://127.0.0.1:$port/"; then
        fail "something already answers on 127.0.0.1:$port"
    fi
    mkdir -p "$data/lrs" "$data/app"
    data="$(cd "$data" && pwd)"
    ralph_env "$data"

    # Fresh credentials each start: `ralph auth -w` appends to the file.
    rm -f "$data/auth.json"
    local log
    log="$(mktemp)"
    if ! "$VENV/bin/ralph" auth -u "$USERNAME" -p "$PASSWORD" -s all -M "$AGENT_MBOX" \
        -N Student -w >"$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        fail "ralph auth could not write $data/auth.json (output above)"
    fi
    rm -f "$log"

    # Started through uvicorn like `ralph runserver --backend fs` does, but without its
    # reload=True (a file watcher over the current folder and a second process to stop), and
    # with the fs backend appending (see LAUNCHER).
    (
        cd "$data"
        exec setsid "$VENV/bin/python" -c "$LAUNCHER" 127.0.0.1 "$port" \
            </dev/null >>"$data/ralph.log" 2>&1
    ) &
    pid=$!
    echo "$pid" >"$data/ralph.pid"

    local deadline=$((SECONDS + ${RALPH_START_TIMEOUT:-60}))
    until curl -s -o /dev/null --max-time 2 -f "http://127.0.0.1:$port/__heartbeat__"; do
        if ! kill -0 "$pid" 2>/dev/null; then
            rm -f "$data/ralph.pid"
            tail -n 40 "$data/ralph.log" >&2
            fail "Ralph exited before it answered (the end of $data/ralph.log is above)"
        fi
        if [ "$SECONDS" -ge "$deadline" ]; then
            kill "$pid" 2>/dev/null || true
            rm -f "$data/ralph.pid"
            tail -n 40 "$data/ralph.log" >&2
            fail "Ralph did not answer on 127.0.0.1:$port within ${RALPH_START_TIMEOUT:-60} s"
        fi
        sleep 0.2
    done
    # The credentials work, not only the heartbeat.
    if ! curl -s -o /dev/null -f --max-time 5 -u "$USERNAME:$PASSWORD" "http://127.0.0.1:$port/whoami"; then
        kill "$pid" 2>/dev/null || true
        rm -f "$data/ralph.pid"
        fail "Ralph answers but rejects $USERNAME/$PASSWORD on /whoami (see $data/ralph.log)"
    fi
    echo "$port" >"$data/ralph.port"
    echo "$pid"
}

stop() {
    local data="$1" pid
    [ -d "$data" ] || fail "$data: no such folder"
    pid="$(running_pid "$data")"
    if [ -z "$pid" ]; then
        rm -f "$data/ralph.pid"
        echo "tests/lms/ralph.sh: no Ralph runs for $data" >&2
        return 0
    fi
    kill "$pid" 2>/dev/null || true
    local i
    for i in $(seq 1 50); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.2
    done
    if kill -0 "$pid" 2>/dev/null; then
        echo "tests/lms/ralph.sh: PID $pid did not stop in 10 s: killing it" >&2
        kill -9 "$pid" 2>/dev/null || true
    fi
    rm -f "$data/ralph.pid"
}

status() {
    local data="$1" pid
    pid="$(running_pid "$data")"
    [ -n "$pid" ] || { echo "not running" >&2; exit 1; }
    echo "$pid http://127.0.0.1:$(cat "$data/ralph.port" 2>/dev/null)/xAPI/"
}

case "${1:-}" in
    install)
        [ $# -eq 1 ] || usage
        ensure_installed
        ;;
    start)
        [ $# -eq 3 ] || usage
        start "$2" "$3"
        ;;
    stop)
        [ $# -eq 2 ] || usage
        stop "$2"
        ;;
    status)
        [ $# -eq 2 ] || usage
        status "$2"
        ;;
    *) usage ;;
esac
