#!/bin/bash
# budget.sh SCENARIO PLANNER SEEDS... : the probe's distance and time lines for each seed
sc=$1; pl=$2; shift 2
for s in "$@"; do
  echo "## seed $s"
  nice -n 5 ${PROBE:-${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}/release/examples/stuck_probe} $sc 8 $s 300 - $pl | grep -E "^tasks|with a task:|along the route|^  layer|^robot-s without"
done
