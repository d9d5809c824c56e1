#!/usr/bin/env bash
# gapfleet's test command (the one README.md names). It does its own set-up, then runs every
# check and test of the workspace. Long experiments are not run here; their smoke versions are.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}"
# Every clone path builds its own copies of the workspace crates; incremental caches on top of
# that filled a 250 GB disk over a dozen CI runs. Clean clones gain nothing from them.
export CARGO_INCREMENTAL=0
# A fresh machine has no cache folder yet: make it, so that df has something to measure.
mkdir -p "$CARGO_TARGET_DIR"
free_kb=$(df -Pk "$CARGO_TARGET_DIR" 2>/dev/null | awk 'NR == 2 { print $4 }' || true)
if [ -n "$free_kb" ] && [ "$free_kb" -lt $((20 * 1024 * 1024)) ]; then
    echo "tests/run.sh: only $((free_kb / 1024 / 1024)) GB free for $CARGO_TARGET_DIR; a clean" \
        "build needs about 20 GB (cargo clean, or remove its debug/incremental, to make room)" >&2
fi

# The Python client test's packages and the rerun CLI, pinned, in a venv of their own (outside
# the work tree).
pyenv="${GAPFLEET_PYENV:-$HOME/.cache/gapfleet-pyenv}"
if [ ! -x "$pyenv/bin/python" ]; then
    python3 -m venv "$pyenv"
fi
"$pyenv/bin/python" -m pip install --quiet --disable-pip-version-check \
    eclipse-zenoh==1.10.2 msgpack==1.2.4 rerun-sdk==0.36.3 rosbags==0.11.9 \
    zenoh-ros2-sdk==0.1.8
export GAPFLEET_PYTHON="$pyenv/bin/python"
# The official rerun CLI (same version as the rerun crate) checks the dashboards' recordings.
export GAPFLEET_RERUN="$pyenv/bin/rerun"
export RERUN_ANALYTICS=0

# A real zenohd router, the version of the zenoh crate (tests/tests/secure_site.rs puts it between
# the coordinator and the agents with the site's access-control list). Built once, with the
# transports and authentication the site uses, into a folder of its own outside the work tree.
zenohd_root="${GAPFLEET_ZENOHD_ROOT:-$HOME/.cache/gapfleet-zenohd}"
if ! "$zenohd_root/bin/zenohd" --version 2>/dev/null | grep -q "1\.10\.2"; then
    cargo install zenohd --version "=1.10.2" --locked --root "$zenohd_root" --no-default-features \
        --features zenoh/transport_tcp,zenoh/transport_tls,zenoh/auth_usrpwd
fi
export GAPFLEET_ZENOHD="$zenohd_root/bin/zenohd"

if cargo fmt --version >/dev/null 2>&1; then
    cargo fmt --all -- --check
else
    echo "tests/run.sh: rustfmt not installed, format check skipped" >&2
fi
if cargo clippy --version >/dev/null 2>&1; then
    cargo clippy --workspace --all-targets --locked -- -D warnings
else
    echo "tests/run.sh: clippy not installed, lint check skipped" >&2
fi
# Module lists live in the //! docs: rustdoc checks their links.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
# The ROS 2 CDR fixtures still match what rosbags writes (schemas/ros2/tests/rosbags.rs holds our
# bytes to the committed file; this holds the file to rosbags).
"$pyenv/bin/python" schemas/ros2/fixtures/make_fixtures.py --check || status=$?
cargo test --workspace --locked 2>&1 | tee "$log" || status=$?
# Coverage-guided fuzzing of schemas::decode and of the ROS 2 decoders (AFL++, through
# cargo-afl), a short run of each: a crash fails the tests. The hour-long run and its figures:
# schemas/README.md.
bash schemas/fuzz/run.sh 60 || status=$?
# One closing line for the whole workspace (cargo ends on the doc-test summary otherwise).
awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($i ~ /^passed/) p += $(i-1); if ($i ~ /^failed/) f += $(i-1); if ($i ~ /^ignored/) s += $(i-1) } }
     END { printf "gapfleet: %d passed, %d failed, %d skipped\n", p, f, s }' "$log"
exit "$status"
