#!/bin/bash
# budget.sh SCENARIO ROBOTS PLANNER SEED... : stuck_probe's time and metre lines for each seed
# (300 s, the traffic policy on, the layer as the scenario says). PROBE overrides the binary.
probe=${PROBE:-${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release/examples/stuck_probe}
sc=$1; robots=$2; pl=$3; shift 3
for s in "$@"; do
  echo "## seed $s"
  "$probe" "$sc" "$robots" "$s" 300 - "$pl" \
    | grep -E "^tasks|with a task:|along the route|^  layer|^robot-s without|^robot-s with a task|^of those"
done
