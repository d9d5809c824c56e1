#!/usr/bin/env bash
# Coverage-guided fuzzing of schemas::decode with AFL++ (cargo-afl, stable toolchain).
#
#   bash schemas/fuzz/run.sh [SECONDS] [OUT]
#
# Installs cargo-afl 0.18.2 and builds AFL++ if they are missing, builds the harness
# (src/decode.rs) instrumented, and fuzzes for SECONDS (default 60) from seeds/ (the sample
# messages), ../tests/fuzz-corpus/ (hand-made hard shapes) and corpus/ (what earlier runs kept).
# Prints AFL++'s figures and exits 1 if any input crashed the harness (a panic, or a message that
# does not round-trip); the crashing inputs are left in OUT/default/crashes/. Without OUT, the
# output goes to a temporary folder, removed when nothing crashed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
seconds="${1:-60}"
if [ -n "${2:-}" ]; then
    out="$2"
    mkdir -p "$(dirname "$out")"
else
    # A folder of its own, removed after a run that found nothing.
    scratch="$(mktemp -d)"
    out="$scratch/afl-out"
fi
export CARGO_TARGET_DIR="${GAPFLEET_FUZZ_TARGET:-$HOME/.cache/gapfleet-fuzz-target}"

if ! cargo afl --version 2>/dev/null | grep -q "0\.18\.2"; then
    cargo install cargo-afl --version "=0.18.2" --locked
fi
# Builds AFL++ and its LLVM runtime for this rustc, once (it refuses, harmlessly, when done).
cargo afl config --build >/dev/null 2>&1 || true
(cd "$here" && cargo afl build --release --locked)

inputs="$(mktemp -d)"
trap 'rm -rf "$inputs"' EXIT
cp "$here"/seeds/*.msgpack "$inputs"/
for f in "$here"/../tests/fuzz-corpus/*.msgpack "$here"/corpus/*; do
    # AFL++ skips empty files; the empty input is replayed by tests/fuzz.rs.
    if [ -s "$f" ]; then cp "$f" "$inputs/corpus-$(basename "$f")"; fi
done

# No terminal UI; this machine's core_pattern and CPU governor are not AFL++'s business.
export AFL_NO_UI=1 AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_AFFINITY=1
cargo afl fuzz -i "$inputs" -o "$out" -V "$seconds" -t 2000 -- "$CARGO_TARGET_DIR/release/decode" \
    >"$out.log" 2>&1 || { tail -30 "$out.log" >&2; exit 1; }

stats="$out/default/fuzzer_stats"
field() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
echo "AFL++ on schemas::decode, ${seconds} s: $(field execs_done) execs ($(field execs_per_sec)/s)," \
    "$(field corpus_count) inputs kept, edges $(field edges_found) of $(field total_edges)" \
    "($(field bitmap_cvg)), $(field saved_crashes) crashes, $(field saved_hangs) hangs${2:+; out: $out}"
if [ "$(field saved_crashes)" != "0" ]; then
    ls "$out"/default/crashes/ >&2
    exit 1
fi
if [ -n "${scratch:-}" ]; then rm -rf "$scratch"; fi
