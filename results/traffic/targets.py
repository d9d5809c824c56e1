#!/usr/bin/env python3
"""Issue 45's targets against the fleets as they ship today, from committed runs.

Usage (from the repository's root): python3 results/traffic/targets.py

Every cell is 300 s with the safety layer and the traffic policy on, `pnp-right` (the fleet's
planner), each site's scenario as built in. The runs are those of the studies named in
CELLS; "before" is results/fleet-efficiency-before (the issue's "today's figures", seeds
1-30, measured with the code of the day the issue was filed).
"""
import csv
import statistics as st

R = "results/"
SECONDS = 300.0
CELLS = [  # cell, robots, seed set, run folders
    ("warehouse", 8, "1–30", [R + "warning-time/warehouse-8-seeds-1-30"]),
    ("warehouse", 8, "101–130 (held out)", [R + "warning-time/warehouse-8-seeds-101-130"]),
    ("warehouse-narrow", 20, "1–30", [R + "corner-cut/narrow-20-pnp-right-seeds-1-30"]),
    ("warehouse-narrow", 20, "101–130 (held out)", [R + "corner-cut/narrow-20-pnp-right-seeds-101-130"]),
    ("warehouse-narrow", 40, "1–30", [R + "fleet-pnp-right/narrow-40-seeds-1-30"]),
    ("warehouse-narrow", 40, "101–130 (held out)", [R + "fleet-pnp-right/narrow-40-seeds-101-130"]),
    ("hallway-fleet", 20, "1–10", [R + "warning-time/hallway-20-seeds-1-10"]),
    ("hallway-fleet", 20, "101–130 (held out)",
     [R + "warning-time/hallway-20-seeds-101-110", R + "warning-time/hallway-20-seeds-111-130"]),
]
BEFORE = R + "fleet-efficiency-before"
TARGET = {("warehouse", 8): "80 %", ("warehouse-narrow", 20): "50 %",
          ("warehouse-narrow", 40): "tasks/min ≥ 20 robots'", ("hallway-fleet", 20): "40 %"}


def runs(dirs, scenario, robots):
    out = []
    for d in dirs:
        try:
            rows = list(csv.DictReader(open(d + "/runs.csv")))
        except FileNotFoundError:
            return None
        out += [r for r in rows if r["scenario"] == scenario and int(r["robots"]) == robots
                and r["safety"] == "true" and r["policy"] == "true"]
    return out or None


def per_robot_hour(rows, column, robots):
    return st.mean(float(r[column]) for r in rows) / (robots * SECONDS / 3600.0)


def main():
    print("| cell | seeds | runs | efficiency (target) | tasks/min | stuck share | runs with a gridlock "
          "| deadlocks (all runs) | robot-caused | person-caused per robot-hour (before; half of it) "
          "| total contacts per robot-hour | closest (m) | people's delay (person-s) |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|---|---:|---:|---:|")
    for scenario, robots, seeds, dirs in CELLS:
        rows = runs(dirs, scenario, robots)
        if rows is None:
            print(f"| `{scenario}`, {robots} | {seeds} | not run | | | | | | | | | | |")
            continue
        before = runs([BEFORE], scenario, robots)
        mean = lambda c: st.mean(float(r[c]) for r in rows)
        eff = st.mean(float(r["efficiency"]) for r in rows if int(r["free_flow_tasks"]) > 0)
        stuck = mean("stuck_robot_s") / (robots * SECONDS)
        gridlock_runs = sum(1 for r in rows if int(r["gridlocks"]) > 0)
        person = per_robot_hour(rows, "person_caused_contacts", robots)
        was = per_robot_hour(before, "person_caused_contacts", robots) if before else None
        was_text = f"{was:.1f}; {was / 2:.1f}" if was is not None else "–"
        print(f"| `{scenario}`, {robots} | {seeds} | {len(rows)} | {100 * eff:.1f} % "
              f"({TARGET[(scenario, robots)]}) | {mean('tasks_per_min'):.2f} | {100 * stuck:.1f} % "
              f"| {gridlock_runs} | {sum(int(r['deadlocks']) for r in rows)} | {mean('robot_caused_contacts'):.2f} "
              f"| {person:.1f} ({was_text}) | {per_robot_hour(rows, 'total_contacts', robots):.1f} "
              f"| {mean('min_human_distance_m'):.3f} | {mean('human_delay_s'):.0f} |")


if __name__ == "__main__":
    main()
