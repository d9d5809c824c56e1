#!/usr/bin/env bash
# Starts a coordinator (which routes for the fleet) and N gapfleet-agent processes on loopback.
#   scripts/fleet.sh [N=10] [extra coordinator args...]
# With ROUTER=tcp/host:7447 set, starts nothing that routes: the coordinator and the agents
# connect to that zenohd router instead. Ctrl-C stops everything (agents safe-stop first).
set -euo pipefail
n="${1:-10}"; shift || true
bin="${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release"
for b in gapfleet gapfleet-agent; do
    [ -x "$bin/$b" ] || { echo "missing $bin/$b: cargo build --release -p coordinator -p agent" >&2; exit 1; }
done
site="${SITE:-demo}"
if [ -n "${ROUTER:-}" ]; then
    coord_net=(--mode client --connect "$ROUTER"); agent_net=(--connect "$ROUTER")
else
    endpoint="${ENDPOINT:-tcp/127.0.0.1:7447}"
    coord_net=(--listen "$endpoint"); agent_net=(--connect "$endpoint")
fi
pids=()
cleanup() { kill -TERM "${pids[@]}" 2>/dev/null || true; wait; }
trap cleanup INT TERM EXIT
"$bin/gapfleet" coordinator --site "$site" --robots "$n" "${coord_net[@]}" "$@" &
pids+=($!)
for ((i = 0; i < n; i++)); do
    RUST_LOG="${AGENT_LOG:-warn}" "$bin/gapfleet-agent" --robot-id "$i" --site "$site" "${agent_net[@]}" &
    pids+=($!)
done
wait "${pids[0]}"
