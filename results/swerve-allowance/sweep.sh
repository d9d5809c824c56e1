# One fleet_contacts run per seed, its lines appended to OUT.
#   bash sweep.sh OUT SITE ROBOTS PLANNER LAYER FIRST LAST
# LAYER is the layer's parameters to change ('' for none). The probe is
# $CARGO_TARGET_DIR/release/examples/fleet_contacts (cargo build --release -p world-sim --examples);
# PROBE overrides it.
set -euo pipefail
out=$1 site=$2 robots=$3 planner=$4 layer=$5 first=$6 last=$7
probe=${PROBE:-${CARGO_TARGET_DIR:-target}/release/examples/fleet_contacts}
: > "$out"
for seed in $(seq "$first" "$last"); do
  "$probe" "$site" "$robots" "$seed" 300 "$planner" "$layer" >> "$out"
done
