#!/usr/bin/env bash
# gapfleet's test command (the one README.md names). It does its own set-up, then runs every
# check and test of the workspace. Long experiments are not run here; their smoke versions are.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/gapfleet-target}"

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
cargo test --workspace --locked
