#!/usr/bin/env bash
# Coverage-guided fuzzing with AFL++ (cargo-afl, stable toolchain) of two harnesses:
#   decode  schemas::decode, the fleet's MessagePack messages (src/decode.rs);
#   ros2    ros2-wire's CDR decoders and rmw_zenoh attachments (src/ros2.rs).
#
#   bash schemas/fuzz/run.sh [SECONDS] [OUT] [TARGETS]
#
# Installs cargo-afl 0.18.2 and builds AFL++ if they are missing, builds the harnesses
# instrumented, and fuzzes each of TARGETS (comma-separated, default decode,ros2) for SECONDS
# (default 60) from its seeds and what earlier runs kept:
#   decode  seeds/ (the sample messages), ../tests/fuzz-corpus/ (hand-made hard shapes), corpus/;
#   ros2    seeds-ros2/ (rosbags' bytes for each message type), corpus-ros2/.
# Prints AFL++'s figures per target and exits 1 if any input crashed a harness (a panic, or a
# message that does not round-trip); the crashing inputs are left in OUT/TARGET/default/crashes/.
# Without OUT, the output goes to a temporary folder, removed when nothing crashed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
seconds="${1:-60}"
targets="${3:-decode,ros2}"
for target in ${targets//,/ }; do
    case "$target" in
        decode | ros2) ;;
        *) echo "run.sh: unknown target '$target' (decode, ros2)" >&2; exit 2 ;;
    esac
done
if [ -n "${2:-}" ]; then
    out="$2"
    mkdir -p "$out"
else
    # A folder of its own, removed after a run that found nothing.
    scratch="$(mktemp -d)"
    out="$scratch"
fi
export CARGO_TARGET_DIR="${GAPFLEET_FUZZ_TARGET:-$HOME/.cache/gapfleet-fuzz-target}"

if ! cargo afl --version 2>/dev/null | grep -q "0\.18\.2"; then
    cargo install cargo-afl --version "=0.18.2" --locked
fi
# Builds AFL++ and its LLVM runtime for this rustc, once (it refuses, harmlessly, when done).
cargo afl config --build >/dev/null 2>&1 || true
(cd "$here" && cargo afl build --release --locked)

# No terminal UI; this machine's core_pattern and CPU governor are not AFL++'s business.
export AFL_NO_UI=1 AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_AFFINITY=1

inputs="$(mktemp -d)"
trap 'rm -rf "$inputs"' EXIT
crashed=0
for target in ${targets//,/ }; do
    case "$target" in
        decode) sources=("$here"/seeds/*.msgpack "$here"/../tests/fuzz-corpus/*.msgpack "$here"/corpus/*)
                what="schemas::decode" ;;
        ros2)   sources=("$here"/seeds-ros2/*.cdr "$here"/corpus-ros2/*)
                what="the ROS 2 decoders" ;;
    esac
    rm -rf "${inputs:?}"/*
    for f in "${sources[@]}"; do
        # AFL++ skips empty files; the empty input is replayed by the tests.
        if [ -s "$f" ]; then cp "$f" "$inputs/$(basename "$(dirname "$f")")-$(basename "$f")"; fi
    done
    result="$out/$target"
    cargo afl fuzz -i "$inputs" -o "$result" -V "$seconds" -t 2000 -- "$CARGO_TARGET_DIR/release/$target" \
        >"$result.log" 2>&1 || { tail -30 "$result.log" >&2; exit 1; }

    stats="$result/default/fuzzer_stats"
    field() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
    echo "AFL++ on $what, ${seconds} s: $(field execs_done) execs ($(field execs_per_sec)/s)," \
        "$(field corpus_count) inputs kept, edges $(field edges_found) of $(field total_edges)" \
        "($(field bitmap_cvg)), $(field saved_crashes) crashes, $(field saved_hangs) hangs${2:+; out: $result}"
    if [ "$(field saved_crashes)" != "0" ]; then
        ls "$result"/default/crashes/ >&2
        crashed=1
    fi
done
if [ "$crashed" != 0 ]; then exit 1; fi
if [ -n "${scratch:-}" ]; then rm -rf "$scratch"; fi
