#!/usr/bin/env python3
"""The held-out tables of results/hallway-layer-heldout/REPORT.md from the committed runs (standard
library only). Run from the repository's root:

    python3 results/hallway-layer-heldout/tables.py PLANNER[,PLANNER...]

Each planner's runs are read from whichever folder holds them: this folder (the seven planners
of the first table), `pnp-omni/` (which also holds ORCA and `pgp+orca` with the hallway closed
at its ends), `pnp-fine-agile/`, `pnp-omni-across/`, `pnp-side/` or `pnp-right/`.
"""
import csv
import os
import statistics
import sys

HERE = "results/hallway-layer-heldout"
FOLDERS = [HERE, f"{HERE}/pnp-omni", f"{HERE}/pnp-fine-agile", f"{HERE}/pnp-omni-across", f"{HERE}/pnp-side", f"{HERE}/pnp-right"]
NEVER = float("inf")


def runs(planner):
    for folder in FOLDERS:
        path = os.path.join(folder, "runs.csv")
        if not os.path.exists(path):
            continue
        rows = [r for r in csv.DictReader(open(path)) if r["planner"] == planner]
        if rows:
            return rows
    sys.exit(f"no runs of {planner}")


def time(r):
    return float(r["time_to_goal_s"]) if r["reached"] == "true" else NEVER


def median(rows):
    m = statistics.median(time(r) for r in rows)
    return "–" if m == NEVER else f"{m:.1f}"


def main():
    planners = sys.argv[1].split(",")
    print("| planner | length (m) | reached | median time to goal (s) | mean time, reached (s) | "
          "path changes / run | personal-space entries / run | robot-caused contacts | "
          "person-caused contacts |")
    print("|---|---|---|---|---|---|---|---|---|")
    for p in planners:
        rows = runs(p)
        for length in sorted({float(r["length_m"]) for r in rows}):
            rs = [r for r in rows if float(r["length_m"]) == length]
            reached = [time(r) for r in rs if r["reached"] == "true"]
            print(f"| {p} | {length:g} | {len(reached) / len(rs):.0%} | {median(rs)} | "
                  f"{statistics.mean(reached):.1f} | "
                  f"{statistics.mean(int(r['path_changes']) for r in rs):.2f} | "
                  f"{statistics.mean(int(r['personal_space_entries']) for r in rs):.2f} | "
                  f"{sum(int(r['robot_caused_contacts']) for r in rs)} | "
                  f"{sum(int(r['person_caused_contacts']) for r in rs)} |")
    print("\n50 m, median time to goal against human speed (reached in brackets):\n")
    speeds = sorted({float(r["human_speed"]) for r in runs(planners[0])})
    print("| human speed (m/s) | " + " | ".join(planners) + " |")
    print("|---|" + "---|" * len(planners))
    for v in speeds:
        cells = []
        for p in planners:
            rs = [r for r in runs(p) if float(r["length_m"]) == 50 and float(r["human_speed"]) == v]
            n = sum(r["reached"] == "true" for r in rs)
            cells.append(f"{median(rs)} ({n}/{len(rs)})")
        print(f"| {v:g} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
