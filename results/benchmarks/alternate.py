#!/usr/bin/env python3
"""Alternates two builds' criterion benchmarks in one period and prints each benchmark's
medians and the new/old ratio of their medians (standard library only).

Build the bench binaries of both commits first, e.g. for `planners` and `world_step`:

    git worktree add /tmp/old OLD_COMMIT
    (cd /tmp/old && cargo bench -p agent --no-default-features --features serde --bench planners --no-run)
    cp "$CARGO_TARGET_DIR"/release/deps/planners-<hash> /tmp/crit/planners-old
    # the same for world_step (-p world-sim --bench world_step), then for the new commit
    python3 results/benchmarks/alternate.py /tmp/crit --rounds 3

DIR holds `<bench>-old` and `<bench>-new` executables; each round runs old then new for
every bench, so that the machine's drift falls on both.
"""
import argparse
import collections
import os
import re
import statistics
import subprocess

UNIT_US = {"ns": 1e-3, "µs": 1.0, "us": 1.0, "ms": 1e3, "s": 1e6}
# Which benchmarks of each binary to run (a criterion filter; empty: all).
FILTERS = {"planners": "plan/.*/50$", "world_step": ""}


def medians(exe, bench_filter):
    """(benchmark, median µs) pairs from one run of a criterion bench binary."""
    args = [exe, "--bench", "--noplot", "--warm-up-time", "1", "--measurement-time", "3"]
    if bench_filter:
        args.append(bench_filter)
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    found, name = [], None
    for line in out.splitlines():
        m = re.match(r"^(\S+)?\s*time:\s*\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", line)
        if m:
            name = m.group(1) or name
            found.append((name, float(m.group(2)) * UNIT_US[m.group(3)]))
        elif line and not line[0].isspace():
            name = line.split()[0]
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir")
    parser.add_argument("--rounds", type=int, default=3)
    a = parser.parse_args()
    benches = sorted({f.rsplit("-", 1)[0] for f in os.listdir(a.dir) if f.endswith("-old")})
    runs = collections.defaultdict(lambda: {"old": [], "new": []})
    for r in range(a.rounds):
        for bench in benches:
            for side in ("old", "new"):
                exe = os.path.join(a.dir, f"{bench}-{side}")
                for name, us in medians(exe, FILTERS.get(bench, "")):
                    runs[name][side].append(us)
        print(f"round {r + 1} of {a.rounds} done", flush=True)
    print("| benchmark | old medians (µs) | new medians (µs) | new / old |")
    print("|---|---|---|---|")
    for name, d in runs.items():
        ratio = statistics.median(d["new"]) / statistics.median(d["old"])
        old = " / ".join(f"{x:.2f}" for x in d["old"])
        new = " / ".join(f"{x:.2f}" for x in d["new"])
        print(f"| {name} | {old} | {new} | {ratio:.3f} |")


if __name__ == "__main__":
    main()
