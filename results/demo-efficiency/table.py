#!/usr/bin/env python3
"""The demo runs of this folder, with the fleet's efficiency under both baselines.

Usage: python3 results/demo-efficiency/table.py

Each demo-seedN.txt is `gapfleet demo --planner pnp-right --seed N --seconds 300 --speed 2`.
The demo prints its efficiency against one robot alone over the run's own 300 s. The
efficiency it printed before, against 600 s of free flow, is computed here from the same
run's tasks and the 600 s free flows in results/fleet-pnp-right/free-flow-300-600.txt.
"""
import pathlib
import re

HERE = pathlib.Path(__file__).resolve().parent
FREE = HERE.parent / "fleet-pnp-right" / "free-flow-300-600.txt"


def free_flows():
    out = {}
    for line in FREE.read_text().splitlines():
        planner, seed, seconds, tasks = line.split()
        if planner == "pnp-right":
            out[(int(seed), int(seconds))] = int(tasks)
    return out


def main():
    free = free_flows()
    rows = []
    for path in sorted(HERE.glob("demo-seed*.txt"), key=lambda p: int(p.stem[9:])):
        seed = int(path.stem[9:])
        text = path.read_text()
        head = re.search(r"^(\d+) robots \(.*?\), (\d+) people, (\d+) simulated seconds", text, re.M)
        eff = re.search(r"^fleet efficiency (\d+)%.*\((\d+) tasks in (\d+) s, no people\)", text, re.M)
        tasks = re.search(r"^tasks done (\d+)", text, re.M)
        contacts = re.search(
            r"with people (\d+) robot-caused, (\d+) person-caused; robot-robot (\d+).*total (\d+)", text, re.M)
        stale = re.search(r"stale-command ticks (\d+)", text)
        # The per-robot table: robot, tasks, path_m, collision%, SVR, min_human_m, ...
        closest = min(float(m.group(1)) for m in re.finditer(
            r"^\s+\d+\s+\d+\s+[\d.]+\s+[\d.]+\s+[\d.]+\s+([\d.]+)\s", text, re.M))
        if not (head and eff and tasks and contacts):
            print(f"{path.name}: incomplete, skipped")
            continue
        robots, seconds = int(head.group(1)), int(head.group(3))
        done = int(tasks.group(1))
        old_free = free[(seed, 600)] / 600.0
        old = done / robots / seconds / old_free
        rows.append((seed, done, int(eff.group(2)), int(eff.group(1)), free[(seed, 600)], old,
                     contacts.groups(), closest, stale.group(1)))
    print("| seed | tasks | one robot alone, 300 s | efficiency (same 300 s) | "
          "one robot alone, 600 s | efficiency against 600 s (before) | robot-caused | "
          "person-caused | robot-robot | total contacts | closest to a person (m) | stale ticks |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for seed, done, f300, e, f600, old, c, closest, stale in rows:
        print(f"| {seed} | {done} | {f300} | {e} % | {f600} | {100 * old:.0f} % | "
              f"{c[0]} | {c[1]} | {c[2]} | {c[3]} | {closest:.2f} | {stale} |")


if __name__ == "__main__":
    main()
