#!/usr/bin/env python3
"""Prints criterion's median per benchmark, in µs, from its saved estimates.

Criterion's printed `time:` line is the slope estimate (close to the mean); the issue targets
are medians, which criterion saves in `<target>/criterion/<group>/<bench>/<input>/new/
estimates.json`. Run after `cargo bench`:

    python3 agent/benches/medians.py [GROUP ...]    # default group: plan

The target folder is $CARGO_TARGET_DIR, else ./target.
"""

import json
import os
import sys
from pathlib import Path


def main() -> int:
    root = Path(os.environ.get("CARGO_TARGET_DIR", "target")) / "criterion"
    groups = sys.argv[1:] or ["plan"]
    found = False
    for group in groups:
        for path in sorted((root / group).glob("**/new/estimates.json")):
            estimates = json.loads(path.read_text())
            name = path.parent.parent.relative_to(root)
            median = estimates["median"]
            low = median["confidence_interval"]["lower_bound"]
            high = median["confidence_interval"]["upper_bound"]
            slope = (estimates.get("slope") or estimates["mean"])["point_estimate"]
            print(
                f"{str(name):32} median {median['point_estimate'] / 1e3:9.2f} µs "
                f"[{low / 1e3:.2f}, {high / 1e3:.2f}]   printed (slope) {slope / 1e3:9.2f} µs"
            )
            found = True
    if not found:
        print(f"no criterion estimates under {root} for {groups}; run cargo bench first",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
