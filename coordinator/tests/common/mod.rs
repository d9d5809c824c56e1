//! Helpers shared by the command-line tests.

use std::process::Command;

/// Runs `gapfleet` with `args` (which end in `--json`), asserts that it succeeded and parses
/// the one JSON object it printed.
pub fn gapfleet_json(args: &[&str]) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_gapfleet"))
        .args(args)
        .output()
        .expect("gapfleet runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}
