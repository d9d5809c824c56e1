#!/usr/bin/env bash
# Starts a coordinator (which routes for the fleet) and N gapfleet-agent processes on loopback.
#   scripts/fleet.sh [N=10] [extra coordinator args...]
# With ROUTER=tcp/host:7447 set, starts nothing that routes: the coordinator and the agents
# connect to that zenohd router instead. Ctrl-C stops everything (agents safe-stop first).
# Secured (mutual TLS, user/password, the access-control list; see README.md):
#   SITE_DIR=DIR scripts/fleet.sh N   uses the site `gapfleet site init DIR` wrote (robots 0..N-1
#                                     must have identities; SITE must match its name);
#   SECURE=1 scripts/fleet.sh N       writes a fresh site into a temporary folder first.
#   With either, ZENOHD=1 also starts a zenohd router with the site's list, and the coordinator
#   becomes its client (needs zenohd 1.10.2 on PATH, or GAPFLEET_ZENOHD).
set -euo pipefail
n="${1:-10}"; shift || true
bin="${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release"
for b in gapfleet gapfleet-agent; do
    [ -x "$bin/$b" ] || { echo "missing $bin/$b: cargo build --release -p coordinator -p agent" >&2; exit 1; }
done
site="${SITE:-demo}"
pids=()
tmp_site=""
cleanup() {
    kill -TERM "${pids[@]}" 2>/dev/null || true
    wait
    [ -n "$tmp_site" ] && rm -rf "$tmp_site"
}
trap cleanup INT TERM EXIT
if [ "${SECURE:-0}" = 1 ] && [ -z "${SITE_DIR:-}" ]; then
    tmp_site=$(mktemp -d)
    SITE_DIR="$tmp_site/site"
    port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    "$bin/gapfleet" site init "$SITE_DIR" --site "$site" --robots "$n" \
        --endpoint "tls/127.0.0.1:$port" >/dev/null
    echo "secured site written to $SITE_DIR"
fi
agent_net() { echo --connect "$ROUTER"; }
if [ -n "${SITE_DIR:-}" ]; then
    if [ "${ZENOHD:-0}" = 1 ]; then
        "${GAPFLEET_ZENOHD:-zenohd}" -c "$SITE_DIR/router/zenohd.json5" &
        pids+=($!)
        coord_net=(--zenoh-config "$SITE_DIR/coordinator/behind-router.json5")
    else
        coord_net=(--zenoh-config "$SITE_DIR/coordinator/zenoh.json5")
    fi
    agent_net() { echo --zenoh-config "$SITE_DIR/robot-$1/zenoh.json5"; }
elif [ -n "${ROUTER:-}" ]; then
    coord_net=(--mode client --connect "$ROUTER")
else
    endpoint="${ENDPOINT:-tcp/127.0.0.1:7447}"
    coord_net=(--listen "$endpoint")
    agent_net() { echo --connect "$endpoint"; }
fi
"$bin/gapfleet" coordinator --site "$site" --robots "$n" "${coord_net[@]}" "$@" &
coordinator=$!
pids+=($coordinator)
for ((i = 0; i < n; i++)); do
    # shellcheck disable=SC2046 # the endpoint or config path has no spaces
    RUST_LOG="${AGENT_LOG:-warn}" "$bin/gapfleet-agent" --robot-id "$i" --site "$site" $(agent_net "$i") &
    pids+=($!)
done
wait "$coordinator"
