#!/usr/bin/env python3
"""The tables of results/safety/REPORT.md, "Memory": run from the repository's root (a git
checkout: the runs without memory are read from git history),
    python3 results/safety/memory/tables.py
"""
import csv
import io
import statistics
import subprocess

HERE = "results/safety/memory"


def load(path, planners=None, commit=None):
    """The rows of a runs.csv, or of the one committed at `commit` (the held-out hallway runs
    before the hallway was closed at its ends have since been re-run in its place)."""
    if commit is None:
        text = open(path).read()
    else:
        text = subprocess.run(["git", "show", f"{commit}:{path}"], check=True,
                              capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO(text)))
    return [r for r in rows if planners is None or r["planner"] in planners]


def hallway(title, rows):
    print(f"\n{title}\n")
    print("| planner | length (m) | runs | reached | median time to goal (s) | personal-space entries / run | robot-caused | person-caused |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for p in sorted({r["planner"] for r in rows}):
        for length in sorted({r["length_m"] for r in rows}, key=float):
            rs = [r for r in rows if r["planner"] == p and r["length_m"] == length]
            # A run that did not reach the end counts as never.
            t = statistics.median(
                float(r["time_to_goal_s"]) if r["reached"] == "true" else float("inf") for r in rs
            )
            reached = sum(r["reached"] == "true" for r in rs)
            pse = statistics.mean(int(r["personal_space_entries"]) for r in rs)
            rc = sum(int(r["robot_caused_contacts"]) for r in rs)
            pc = sum(int(r["person_caused_contacts"]) for r in rs)
            print(f"| {p} | {float(length):.0f} | {len(rs)} | {reached / len(rs):.0%} | {t:.1f} | {pse:.2f} | {rc} | {pc} |")


def fleets(title, path):
    rows = [r for r in csv.DictReader(open(path)) if r["safety"] == "true" and r["policy"] == "true"]
    print(f"\n{title}\n")
    print("| site | robots | efficiency | tasks/min | robot-caused | person-caused / run | robot–robot | walls | closest (m) | people's delay (person-s) | runs with a gridlock | stuck share |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    cells = {}
    for r in rows:
        cells.setdefault((r["scenario"], int(r["robots"])), []).append(r)
    for (site, robots), rs in sorted(cells.items()):
        if robots == 40:
            continue
        mean = lambda c: statistics.mean(float(r[c]) for r in rs)
        total = lambda c: sum(float(r[c]) for r in rs)
        stuck = total("stuck_robot_s") / (len(rs) * robots * 300.0)
        grid = sum(int(r["gridlocks"]) > 0 for r in rs)
        print(f"| {site} | {robots} | {mean('efficiency'):.1%} | {mean('tasks_per_min'):.2f} | {total('robot_caused_contacts'):.0f} | {mean('person_caused_contacts'):.2f} | {total('robot_robot_contacts'):.0f} | {total('wall_contacts'):.0f} | {mean('min_human_distance_m'):.2f} | {mean('human_delay_s'):.1f} | {grid} | {stuck:.1%} |")


for t in ["0", "0.5", "1"]:
    hallway(f"Hallway, tuning seeds 1–30, people at 2–3 m/s, memory {t} s",
            load(f"{HERE}/hallway-seeds-1-30-memory-{t}/runs.csv"))
# Open ends: the hallway before it was closed (2026-11-30).
OPEN = "6f272db"
base = load("results/hallway-layer-heldout/runs.csv", {"orca", "pgp+orca"}, OPEN) + load(
    "results/hallway-layer-heldout/pnp-omni/runs.csv", {"pnp-omni"}, OPEN)
hallway("Hallway, held-out seeds 101–130, no memory (results/hallway-layer-heldout)", base)
hallway("Hallway, held-out seeds 101–130, memory 1 s",
        load(f"{HERE}/hallway-seeds-101-130-memory-1/runs.csv"))
for t in ["0", "1"]:
    hallway(f"Hallway, seeds 131–160 (never looked at before the choice), memory {t} s",
            load(f"{HERE}/hallway-seeds-131-160-memory-{t}/runs.csv"))
fleets("Fleets, seeds 1–30, no memory (results/fleet-safety)", "results/fleet-safety/runs.csv")
fleets("Fleets, seeds 1–30, memory 1 s", f"{HERE}/fleets-seeds-1-30-memory-1/runs.csv")
fleets("Fleets, held-out seeds 101–130, no memory (results/fleet-safety-heldout)",
       "results/fleet-safety-heldout/runs.csv")
fleets("Fleets, held-out seeds 101–130, memory 1 s", f"{HERE}/fleets-seeds-101-130-memory-1/runs.csv")
