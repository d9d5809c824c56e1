#!/usr/bin/env python3
"""The tables of results/hallway/REPORT.md, from runs.csv (standard library only), with the
runs of any sub-folders named on the command line added (e.g. `pnp-agile`).

    python3 results/hallway/tables.py [FOLDER ...]
"""
import csv
import os
import statistics
import sys
from collections import defaultdict

HERE = os.path.dirname(os.path.abspath(__file__))


def load():
    rows = []
    for folder in ["."] + sys.argv[1:]:
        with open(os.path.join(HERE, folder, "runs.csv"), newline="") as f:
            rows += list(csv.DictReader(f))
    return rows


def mean(xs):
    xs = list(xs)
    return statistics.fmean(xs) if xs else float("nan")


def main():
    rows = load()
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    lengths = sorted({float(r["length_m"]) for r in rows})
    speeds = sorted({float(r["human_speed"]) for r in rows})
    seeds = len({r["seed"] for r in rows})
    print(f"{len(rows)} runs: {len(planners)} planners × {len(lengths)} lengths × "
          f"{len(speeds)} human speeds × {seeds} seeds\n")

    # Runs every planner finished: the fair ground for times.
    by_trial = defaultdict(dict)
    for r in rows:
        by_trial[(r["length_m"], r["human_speed"], r["seed"])][r["planner"]] = r
    common = {k for k, v in by_trial.items()
              if len(v) == len(planners) and all(x["reached"] == "true" for x in v.values())}

    print("### Per planner and length (all human speeds)\n")
    print("| planner | length (m) | reached | time to goal, runs it reached (s) | time to goal, "
          "trials every planner finished (s) | path changes / run | personal-space entries "
          "/ run | robot-caused contacts |")
    print("|---|---|---|---|---|---|---|---|")
    for p in planners:
        for l in lengths:
            mine = [r for r in rows if r["planner"] == p and float(r["length_m"]) == l]
            reached = [r for r in mine if r["reached"] == "true"]
            fair = [r for r in mine
                    if (r["length_m"], r["human_speed"], r["seed"]) in common]
            print(f"| {p} | {l:g} | {len(reached) / len(mine):.0%} "
                  f"| {mean(float(r['time_to_goal_s']) for r in reached):.1f} "
                  f"| {mean(float(r['time_to_goal_s']) for r in fair):.1f} ({len(fair)}) "
                  f"| {mean(int(r['path_changes']) for r in mine):.2f} "
                  f"| {mean(int(r['personal_space_entries']) for r in mine):.2f} "
                  f"| {sum(int(r['robot_caused_contacts']) for r in mine)} |")
    print()

    if 50.0 in lengths:
        print("### 50 m hallway: time to goal (s, runs that reached it) against human speed\n")
        print("| human speed (m/s) | " + " | ".join(planners) + " |")
        print("|---|" + "---|" * len(planners))
        for v in speeds:
            cells = []
            for p in planners:
                mine = [r for r in rows if r["planner"] == p and float(r["length_m"]) == 50.0
                        and float(r["human_speed"]) == v]
                reached = [float(r["time_to_goal_s"]) for r in mine if r["reached"] == "true"]
                cells.append(f"{mean(reached):.1f} ({len(reached)}/{len(mine)})")
            print(f"| {v:g} | " + " | ".join(cells) + " |")
        print()

        print("### 50 m hallway: metres driven per metre of hallway (runs that reached the end) "
              "against human speed: dodging shows as more than 1\n")
        print("| human speed (m/s) | " + " | ".join(planners) + " |")
        print("|---|" + "---|" * len(planners))
        for v in speeds:
            cells = []
            for p in planners:
                mine = [r for r in rows if r["planner"] == p and float(r["length_m"]) == 50.0
                        and float(r["human_speed"]) == v and r["reached"] == "true"]
                cells.append(f"{mean(float(r['path_m']) / 49.0 for r in mine):.3f}")
            print(f"| {v:g} | " + " | ".join(cells) + " |")
        print()


if __name__ == "__main__":
    main()
