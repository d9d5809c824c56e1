#!/usr/bin/env bash
# Starts `gapfleet demo --web`, opens the served Rerun web viewer in headless Chromium (Debian's
# `chromium`, software WebGL) and saves a screenshot of the live fleet.
#   scripts/screenshot.sh [OUT=docs/dashboard.png] [extra demo args...]
set -euo pipefail
out="${1:-docs/dashboard.png}"; shift || true
bin="${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release/gapfleet"
[ -x "$bin" ] || { echo "missing $bin: cargo build --release -p coordinator" >&2; exit 1; }
command -v chromium >/dev/null || { echo "needs Debian's chromium: apt-get install chromium" >&2; exit 1; }
log=$(mktemp)
"$bin" demo --web --seconds 90 "$@" 2>"$log" >/dev/null &
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
sleep 15  # let the fleet run a while, so the plots have history
mkdir -p "$(dirname "$out")"
profile=$(mktemp -d)
chromium --headless=new --no-sandbox --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --disable-quic --user-data-dir="$profile" \
    --use-angle=swiftshader --enable-unsafe-swiftshader --ignore-gpu-blocklist \
    --window-size=1600,900 --virtual-time-budget=20000 \
    --screenshot="$(realpath -m "$out")" "$url" 2>/dev/null
rm -rf "$profile"
echo "saved $out"
