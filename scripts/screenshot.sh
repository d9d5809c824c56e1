#!/usr/bin/env bash
# Starts `gapfleet demo --web`, opens the served Rerun web viewer in headless Chromium (Debian's
# `chromium`, software WebGL) and saves a screenshot of the live fleet.
#   [DEMO_SECONDS=90] [WAIT_MS=30000] scripts/screenshot.sh [OUT=docs/dashboard.png] [extra demo args...]
# The picture is taken WAIT_MS after the page opens; on a busy machine the software-rendered
# viewer lags the demo, and catches up once the demo (DEMO_SECONDS of simulation) has ended.
set -euo pipefail
out="${1:-docs/dashboard.png}"; shift || true
bin="${GAPFLEET_BIN:-${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release/gapfleet}"
[ -x "$bin" ] || { echo "missing $bin: cargo build --release -p coordinator" >&2; exit 1; }
command -v chromium >/dev/null || { echo "needs Debian's chromium: apt-get install chromium" >&2; exit 1; }
log=$(mktemp)
"$bin" demo --web --seconds "${DEMO_SECONDS:-90}" "$@" 2>"$log" >/dev/null &
demo=$!
trap 'kill $demo 2>/dev/null || true; rm -f "$log"' EXIT
url=""
for _ in $(seq 1 100); do
    url=$(sed -n 's/^dashboard: open //p' "$log" | head -1)
    [ -n "$url" ] && break
    sleep 0.2
done
[ -n "$url" ] || { cat "$log" >&2; echo "the demo printed no dashboard URL" >&2; exit 1; }
echo "viewer: $url"
mkdir -p "$(dirname "$out")"
# playwright-core drives Debian's chromium; installed outside the work tree.
node_dir="${GAPFLEET_NODE:-$HOME/.cache/gapfleet-node}"
[ -d "$node_dir/node_modules/playwright-core" ] ||
    npm install --silent --no-audit --no-fund --prefix "$node_dir" playwright-core@1.64.1
# ES modules resolve packages next to the script: run a copy inside the node folder.
cp "$(dirname "$0")/screenshot.mjs" "$node_dir/screenshot.mjs"
node "$node_dir/screenshot.mjs" "$url" "$(realpath -m "$out")" "${WAIT_MS:-30000}"
