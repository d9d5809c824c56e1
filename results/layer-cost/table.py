"""The tables of results/layer-cost/REPORT.md from the runs beside this script.

    python3 results/layer-cost/table.py
"""

import csv
import statistics
from pathlib import Path

HERE = Path(__file__).parent
SETTINGS = [
    ("off", "no layer (`--safety off`)"),
    ("on", "the layer as shipped"),
    ("no-warning", "no warning-field slow-down (`warning_scale=1`)"),
    ("no-yield", "no yield (`yielding=false`)"),
    ("no-swerve", "no swerve allowance (`person_accel=0,person_accel_across=0`)"),
    ("protective-only", "none of the three (all the changes above)"),
]
SITES = [
    ("warehouse-8", "`warehouse`, 8 robots, 40 people"),
    ("hallway-20", "`hallway-fleet`, 20 robots, 30 people"),
]


def runs(site, setting):
    with open(HERE / f"{site}-{setting}" / "runs.csv") as f:
        return {r["seed"]: r for r in csv.DictReader(f)}


for site, label in SITES:
    print(f"\n**{label}** (seeds 1–30, 300 s, `pgp+orca`, the traffic policy on):\n")
    print(
        "| layer | tasks per run | against the layer as shipped, paired (± s.e.) | efficiency "
        "| robot-caused | person-caused | robot–robot | total contacts | closest (m) "
        "| people's delay (person-s) | stuck robot-s | runs with a gridlock |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    shipped = runs(site, "on")
    for setting, name in SETTINGS:
        r = runs(site, setting)
        rows = list(r.values())

        def mean(col):
            return statistics.mean(float(x[col]) for x in rows)

        diffs = [float(r[s]["tasks"]) - float(shipped[s]["tasks"]) for s in shipped]
        paired = (
            "–"
            if setting == "on"
            else f"{statistics.mean(diffs):+.1f} ± {statistics.stdev(diffs) / len(diffs) ** 0.5:.1f}"
        )
        gridlocked = sum(1 for x in rows if float(x["gridlocks"]) > 0)
        print(
            f"| {name} | {mean('tasks'):.1f} | {paired} | {100 * mean('efficiency'):.0f} % "
            f"| {mean('robot_caused_contacts'):.1f} | {mean('person_caused_contacts'):.1f} "
            f"| {mean('robot_robot_contacts'):.1f} | {mean('total_contacts'):.1f} "
            f"| {mean('min_human_distance_m'):.2f} | {mean('human_delay_s'):.0f} "
            f"| {mean('stuck_robot_s'):.0f} | {gridlocked} |"
        )
