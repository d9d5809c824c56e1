#!/usr/bin/env python3
"""Before and after the hallway was closed at its ends (results/hallway-layer-heldout/REPORT.md,
"The hallway closed at its ends"): the same held-out runs with open ends (the memory study's
runs, results/safety/memory, as committed at 6f272db) and with closed ends (`pnp-omni/`,
`seeds-131-160/`). Run from the repository's root:

    python3 results/hallway-layer-heldout/closed_ends.py
"""
import csv
import io
import statistics
import subprocess

OPEN = "6f272db"


def committed(path):
    text = subprocess.run(["git", "show", f"{OPEN}:{path}"], check=True,
                          capture_output=True, text=True).stdout
    return list(csv.DictReader(io.StringIO(text)))


def here(path):
    return list(csv.DictReader(open(path)))


def cell(rows, planner, length):
    rs = [r for r in rows if r["planner"] == planner and float(r["length_m"]) == length]
    # A run that did not reach the end counts as never.
    times = [float(r["time_to_goal_s"]) if r["reached"] == "true" else float("inf") for r in rs]
    return {
        "runs": len(rs),
        "reached": sum(r["reached"] == "true" for r in rs),
        "median": statistics.median(times),
        "pse": statistics.mean(int(r["personal_space_entries"]) for r in rs),
        "changes": statistics.mean(int(r["path_changes"]) for r in rs),
        "robot": sum(int(r["robot_caused_contacts"]) for r in rs),
        "person": sum(int(r["person_caused_contacts"]) for r in rs),
    }


def table(title, before, after, planners):
    print(f"\n{title}\n")
    print("| planner | length (m) | reached, open / closed | median time (s), open / closed | "
          "personal-space entries / run | path changes / run | robot-caused | person-caused |")
    print("|---|---:|---|---|---|---|---|---|")
    for p in planners:
        for length in (25.0, 50.0, 100.0):
            b, a = cell(before, p, length), cell(after, p, length)
            if b["runs"] == 0:
                b = {k: float("nan") for k in a}
            print(f"| {p} | {length:.0f} | {b['reached']:.0f} / {a['reached']} of {a['runs']} | "
                  f"{b['median']:.1f} / {a['median']:.1f} | {b['pse']:.2f} / {a['pse']:.2f} | "
                  f"{b['changes']:.2f} / {a['changes']:.2f} | {b['robot']:.0f} / {a['robot']} | "
                  f"{b['person']:.0f} / {a['person']} |")


def speeds(title, rows, planners, length):
    print(f"\n{title}\n")
    vs = sorted({float(r["human_speed"]) for r in rows})
    print("| planner | " + " | ".join(f"{v:g} m/s" for v in vs) + " |")
    print("|---|" + "---:|" * len(vs))
    for p in planners:
        cells = []
        for v in vs:
            rs = [r for r in rows if r["planner"] == p and float(r["length_m"]) == length
                  and float(r["human_speed"]) == v]
            times = [float(r["time_to_goal_s"]) if r["reached"] == "true" else float("inf")
                     for r in rs]
            cells.append(f"{statistics.median(times):.1f}")
        print(f"| {p} | " + " | ".join(cells) + " |")


three = ["orca", "pgp+orca", "pnp-omni"]
after = here("results/hallway-layer-heldout/pnp-omni/runs.csv")
table("Held-out seeds 101–130, the layer on with its memory",
      committed("results/safety/memory/hallway-seeds-101-130-memory-1/runs.csv"), after, three)
table("Seeds 131–160, the layer on with its memory",
      committed("results/safety/memory/hallway-seeds-131-160-memory-1/runs.csv"),
      here("results/hallway-layer-heldout/seeds-131-160/runs.csv"), three)
for length in (50.0, 100.0):
    speeds(f"Closed ends, seeds 101–130, {length:.0f} m: median time to goal (s) by human speed",
           after, ["pnp-omni", "pnp-omni-nopeek", "orca", "pgp+orca"], length)
