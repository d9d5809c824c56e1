#!/usr/bin/env bash
# Saves a screenshot of the fleet dashboard in the Rerun web viewer, opened in headless
# Chromium (Debian's `chromium`, software WebGL).
#   [DEMO_SECONDS=90] [WAIT_MS=30000] [FROM_RECORDING=1 [SPEED=10]] \
#       scripts/screenshot.sh [OUT=docs/dashboard.png] [extra demo args...]
# Live (default): starts `gapfleet demo --web` and takes the picture WAIT_MS after the page
# opens; on a busy machine the software-rendered viewer lags the demo, and catches up once the
# demo (DEMO_SECONDS of simulation) has ended.
# FROM_RECORDING=1: runs the demo first (at SPEED simulated seconds per wall second) into an
# .rrd file, then serves that file with the official `rerun` CLI (GAPFLEET_RERUN, else `rerun`
# on PATH; `pip install rerun-sdk==0.36.3`) and takes the picture at the recording's end, where
# the heatmaps have DEMO_SECONDS of events in them. (On a 2-core machine the software-rendered
# viewer cannot keep up with a live 30-robot fleet for long.)
set -euo pipefail
out="${1:-docs/dashboard.png}"; shift || true
bin="${GAPFLEET_BIN:-${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release/gapfleet}"
[ -x "$bin" ] || { echo "missing $bin: cargo build --release -p coordinator" >&2; exit 1; }
command -v chromium >/dev/null || { echo "needs Debian's chromium: apt-get install chromium" >&2; exit 1; }
log=$(mktemp)
work=$(mktemp -d)
server=""
# The server runs in a session of its own, and the whole session goes at the end: the `rerun`
# on PATH may be pip's wrapper, whose viewer process would otherwise outlive it (and keep
# using the CPU).
trap '[ -n "$server" ] && kill -- -"$server" 2>/dev/null; rm -rf "$log" "$work"' EXIT
if [ "${FROM_RECORDING:-0}" = 1 ]; then
    rerun_cli="${GAPFLEET_RERUN:-rerun}"
    command -v "$rerun_cli" >/dev/null || { echo "needs the rerun CLI: pip install rerun-sdk==0.36.3" >&2; exit 1; }
    rrd="$work/demo.rrd"
    echo "recording ${DEMO_SECONDS:-90} s of the demo at ${SPEED:-10}x into $rrd"
    "$bin" demo --rrd "$rrd" --seconds "${DEMO_SECONDS:-90}" --speed "${SPEED:-10}" "$@" >/dev/null
    port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    web_port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    RERUN_ANALYTICS=0 setsid "$rerun_cli" --serve-web --bind 127.0.0.1 --port "$port" \
        --web-viewer-port "$web_port" "$rrd" 2>"$log" >/dev/null &
    server=$!
    for _ in $(seq 1 100); do
        curl -s -o /dev/null "http://127.0.0.1:$web_port" && break
        sleep 0.2
    done
    url="http://127.0.0.1:$web_port/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A$port%2Fproxy"
else
    setsid "$bin" demo --web --seconds "${DEMO_SECONDS:-90}" "$@" 2>"$log" >/dev/null &
    server=$!
    url=""
    for _ in $(seq 1 100); do
        url=$(sed -n 's/^dashboard: open //p' "$log" | head -1)
        [ -n "$url" ] && break
        sleep 0.2
    done
    [ -n "$url" ] || { cat "$log" >&2; echo "the demo printed no dashboard URL" >&2; exit 1; }
fi
echo "viewer: $url"
mkdir -p "$(dirname "$out")"
# playwright-core drives Debian's chromium; installed outside the work tree.
node_dir="${GAPFLEET_NODE:-$HOME/.cache/gapfleet-node}"
[ -d "$node_dir/node_modules/playwright-core" ] ||
    npm install --silent --no-audit --no-fund --prefix "$node_dir" playwright-core@1.64.1
# ES modules resolve packages next to the script: run a copy inside the node folder.
cp "$(dirname "$0")/screenshot.mjs" "$node_dir/screenshot.mjs"
node "$node_dir/screenshot.mjs" "$url" "$(realpath -m "$out")" "${WAIT_MS:-30000}"
