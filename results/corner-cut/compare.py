#!/usr/bin/env python3
"""compare.py: every before/after pair of results/corner-cut, paired by (site, robots, seed):
mean per run before and after, the difference ± its standard error, and the seeds of the runs
with a gridlock or a deadlock. Only runs with the traffic policy and the safety layer on.
Run from the repository's root: python3 results/corner-cut/compare.py"""
import csv, statistics as st

HERE = "results/corner-cut"
PNP = "results/fleet-pnp-right"
# (label, after, before): comma-separated runs.csv lists.
PAIRS = [
    ("narrow 20, pnp-right, tuning 1-30",
     f"{HERE}/narrow-20-pnp-right-seeds-1-30",
     f"{PNP}/narrow-20-seeds-1-6,{PNP}/narrow-20-seeds-7-30"),
    ("narrow 20, pgp+orca, tuning 1-30",
     f"{HERE}/narrow-20-pgp+orca-seeds-1-30",
     "results/warning-graded/fleet-default"),
    ("narrow 40, pgp+orca, tuning 1-30",
     f"{HERE}/narrow-40-pgp+orca-seeds-1-10,{HERE}/narrow-40-pgp+orca-seeds-11-30",
     "results/swerve-allowance/study-warehouses-default-seeds-1-30"),
    ("narrow 20, pnp-right, held out 101-130",
     f"{HERE}/narrow-20-pnp-right-seeds-101-130",
     f"{PNP}/narrow-20-seeds-101-110,{PNP}/narrow-20-seeds-111-130"),
    ("narrow 20, pgp+orca, held out 101-130",
     f"{HERE}/narrow-20-40-pgp+orca-seeds-101-130",
     "results/swerve-allowance/study-warehouses-away-seeds-101-130"),
    ("narrow 40, pgp+orca, held out 101-130",
     f"{HERE}/narrow-20-40-pgp+orca-seeds-101-130",
     f"{HERE}/before-narrow-40-pgp+orca-seeds-101-130"),
    ("warehouse 8, pgp+orca, held out 101-103",
     f"{HERE}/warehouse-seeds-101-103",
     f"{HERE}/before-warehouse-and-narrow-20-seeds-101-103"),
]
COLUMNS = ("tasks", "efficiency", "robot_caused_contacts", "person_caused_contacts",
           "robot_robot_contacts", "wall_contacts", "min_human_distance_m", "human_delay_s",
           "stuck_robot_s", "gridlocked_robot_s")


def load(folders):
    runs = {}
    for folder in folders.split(","):
        for r in csv.DictReader(open(f"{folder}/runs.csv")):
            if (r["policy"], r["safety"]) == ("true", "true"):
                runs[(r["scenario"], int(r["robots"]), int(r["seed"]))] = r
    return runs


for label, after, before in PAIRS:
    try:
        new, old = load(after), load(before)
    except FileNotFoundError as e:
        print(f"## {label}: missing {e.filename}\n")
        continue
    site, robots = label.split(",")[0].split()
    site = {"narrow": "warehouse-narrow"}.get(site, site)
    keys = sorted(k for k in set(new) & set(old) if k[:2] == (site, int(robots)))
    print(f"## {label}: {len(keys)} paired runs\n")
    print("| measure (efficiency in %) | before | after | after − before |")
    print("|---|---:|---:|---:|")
    for c in COLUMNS:
        scale = 100.0 if c == "efficiency" else 1.0  # in per cent
        d = [scale * (float(new[k][c]) - float(old[k][c])) for k in keys]
        se = st.stdev(d) / len(d) ** 0.5 if len(d) > 1 else float("nan")
        b = scale * st.mean(float(old[k][c]) for k in keys)
        a = scale * st.mean(float(new[k][c]) for k in keys)
        print(f"| {c} | {b:.2f} | {a:.2f} | {st.mean(d):+.2f} ± {se:.2f} |")
    for what in ("gridlocks", "deadlocks"):
        seeds = lambda runs: [k[2] for k in keys if int(runs[k][what]) > 0]
        print(f"| runs with {what} (seeds) | {len(seeds(old))} {seeds(old)} "
              f"| {len(seeds(new))} {seeds(new)} | |")
    print()
