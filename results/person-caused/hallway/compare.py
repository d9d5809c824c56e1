#!/usr/bin/env python3
"""The hallway table of results/person-caused/REPORT.md: each planner at each length, the
layer's default warning_scale against 0.75, from the two study folders (standard library only).
Run from results/person-caused:

    python3 hallway/compare.py hallway/default-seeds-101-130 hallway/warning-scale-0.75-seeds-101-130
"""
import csv
import statistics
import sys

NEVER = float("inf")


def time(r):
    return float(r["time_to_goal_s"]) if r["reached"] == "true" else NEVER


def main():
    folders = sys.argv[1:3]
    tables = [list(csv.DictReader(open(f"{f}/runs.csv"))) for f in folders]
    print("| planner | length (m) | `warning_scale` | reached | median time to goal (s) | "
          "personal-space entries / run | robot-caused contacts | person-caused contacts |")
    print("|---|---|---|---|---|---|---|---|")
    planners = sorted({r["planner"] for r in tables[0]})
    for p in planners:
        for length in sorted({float(r["length_m"]) for r in tables[0]}):
            for label, rows in zip(["0.5", "0.75"], tables):
                rs = [r for r in rows if r["planner"] == p and float(r["length_m"]) == length]
                reached = sum(r["reached"] == "true" for r in rs)
                m = statistics.median(time(r) for r in rs)
                print(f"| {p} | {length:g} | {label} | {reached / len(rs):.0%} | "
                      f"{'–' if m == NEVER else f'{m:.1f}'} | "
                      f"{statistics.mean(int(r['personal_space_entries']) for r in rs):.2f} | "
                      f"{sum(int(r['robot_caused_contacts']) for r in rs)} | "
                      f"{sum(int(r['person_caused_contacts']) for r in rs)} |")


if __name__ == "__main__":
    main()
