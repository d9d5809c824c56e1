"""The tables of results/halting/REPORT.md, from the runs.csv files beside this script.

    python3 results/halting/tables.py

Each pair compares people who may stop dead (the layer before, `people_stop_dead=true`) with
people who halt no harder than a_h (the default now), run for run on the same seeds.
"""

import csv
import math
import os
import statistics
from collections import defaultdict

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")


def rows(path):
    with open(os.path.join(HERE, path, "runs.csv")) as f:
        return list(csv.DictReader(f))


def fleet_cells(path, committed=False):
    base = ROOT if committed else HERE
    with open(os.path.join(base, path, "runs.csv")) as f:
        cells = defaultdict(dict)
        for r in csv.DictReader(f):
            if r["safety"] == "true":
                cells[(r["scenario"], r["robots"])][int(r["seed"])] = r
        return cells


def paired(a, b, column):
    d = [float(b[s][column]) - float(a[s][column]) for s in a]
    se = statistics.stdev(d) / math.sqrt(len(d)) if len(d) > 1 else 0.0
    return statistics.mean(d), se


def fleet_table(title, before, after):
    print(f"\n{title}\n")
    print("| cell | runs | tasks per run | paired (± s.e.) | efficiency | robot-caused | "
          "person-caused per run | paired (± s.e.) | closest (m) | people's delay (person-s) | "
          "stuck share | runs with a gridlock |")
    print("|---|---:|---|---|---|---|---|---|---|---|---|---|")
    for cell in [("warehouse", "8"), ("warehouse-narrow", "20"), ("warehouse-narrow", "40"),
                 ("hallway-fleet", "20")]:
        if cell not in before or cell not in after:
            continue
        a, b = before[cell], after[cell]
        a = {s: a[s] for s in b if s in a}
        b = {s: b[s] for s in a}
        m = lambda d, c: statistics.mean(float(x[c]) for x in d.values())
        robots = float(cell[1])
        stuck = lambda d: 100 * m(d, "stuck_robot_s") / (robots * 300)
        grid = lambda d: sum(1 for x in d.values() if float(x["gridlocks"]) > 0)
        dt, st = paired(a, b, "tasks")
        dp, sp = paired(a, b, "person_caused_contacts")
        print(f"| `{cell[0]}`, {cell[1]} | {len(a)} | {m(a, 'tasks'):.1f} → {m(b, 'tasks'):.1f} | "
              f"{dt:+.1f} ± {st:.1f} | {100 * m(a, 'efficiency'):.1f} → {100 * m(b, 'efficiency'):.1f} % | "
              f"{m(a, 'robot_caused_contacts'):.0f} → {m(b, 'robot_caused_contacts'):.0f} | "
              f"{m(a, 'person_caused_contacts'):.1f} → {m(b, 'person_caused_contacts'):.1f} | "
              f"{dp:+.1f} ± {sp:.1f} | {m(a, 'min_human_distance_m'):.2f} → {m(b, 'min_human_distance_m'):.2f} | "
              f"{m(a, 'human_delay_s'):.1f} → {m(b, 'human_delay_s'):.1f} | "
              f"{stuck(a):.1f} → {stuck(b):.1f} % | {grid(a)} → {grid(b)} |")


def hallway_table(title, arms):
    print(f"\n{title}\n")
    names = list(arms)
    print("| planner | length (m) | " + " | ".join(
        f"{n}: median (s) / entries per run / robot-caused / person-caused" for n in names) + " |")
    print("|---|---:|" + "---|" * len(names))
    cells = defaultdict(dict)
    for n, (path, committed_planners) in arms.items():
        for p in path:
            base = ROOT if p.startswith("results/") else HERE
            with open(os.path.join(base, p, "runs.csv")) as f:
                for r in csv.DictReader(f):
                    if committed_planners and r["planner"] not in committed_planners:
                        continue
                    cells[(r["planner"], float(r["length_m"]))].setdefault(n, []).append(r)
    for key in sorted(cells):
        parts = []
        for n in names:
            rs = cells[key].get(n)
            if not rs:
                parts.append("–")
                continue
            t = [float(r["time_to_goal_s"]) if r["reached"] == "true" else math.inf for r in rs]
            e = statistics.mean(float(r["personal_space_entries"]) for r in rs)
            rc = sum(int(r["robot_caused_contacts"]) for r in rs)
            pc = sum(int(r["person_caused_contacts"]) for r in rs)
            parts.append(f"{statistics.median(t):.1f} / {e:.2f} / {rc} / {pc}")
        print(f"| {key[0]} | {key[1]:.0f} | " + " | ".join(parts) + " |")


def open_space_table(title, before, after):
    print(f"\n{title}\n")
    print("| planner | success | robot-caused | person-caused | people's delay (person-s per run) |")
    print("|---|---|---|---|---|")
    tally = {}
    for arm, path in (("before", before), ("after", after)):
        d = defaultdict(lambda: [0, 0, 0, 0, 0.0])
        for r in rows(path):
            x = d[r["algorithm"]]
            x[0] += 1
            x[1] += r["success"] == "true"
            x[2] += int(r["robot_caused_contacts"])
            x[3] += int(r["person_caused_contacts"])
            x[4] += float(r["human_delay_s"])
        tally[arm] = d
    for p in tally["before"]:
        a, b = tally["before"][p], tally["after"][p]
        print(f"| {p} | {100 * a[1] / a[0]:.1f} → {100 * b[1] / b[0]:.1f} % | {a[2]} → {b[2]} | "
              f"{a[3]} → {b[3]} | {a[4] / a[0]:.2f} → {b[4] / b[0]:.2f} |")


def replay_table(title, before, after):
    print(f"\n{title}\n")
    print("| planner | reached | %s<0.21 | contacts caused / suffered / appeared / total |")
    print("|---|---|---|---|")
    read = lambda path: {
        line.split("|")[1].strip(): [c.strip() for c in line.split("|")]
        for line in open(os.path.join(HERE, path, "table.md")) if line.startswith("| ")
        and not line.startswith("| |")
    }
    a, b = read(before), read(after)
    for p in a:
        print(f"| {p} | {a[p][4]} → {b[p][4]} | {a[p][7]} → {b[p][7]} | {a[p][14]} → {b[p][14]} |")


fleet_table("Fleets, tuning seeds 1–10 (stop dead → halt within a_h)",
            fleet_cells("fleets-seeds-1-10-stop-dead"), fleet_cells("fleets-seeds-1-10"))
held_before = fleet_cells("results/safety/memory/fleets-seeds-101-130-memory-1", committed=True)
held_before.update(fleet_cells("narrow-40-seeds-101-130-stop-dead"))
fleet_table("Fleets, held-out seeds 101–130", held_before, fleet_cells("fleets-seeds-101-130"))
hallway_table("Hallway study, tuning seeds 1–12", {
    "stop dead": (["hallway-seeds-1-12-stop-dead"], None),
    "halt within a_h, every speed": (["hallway-seeds-1-12-every-speed"], None),
    "halt within a_h up to 1.5 m/s": (["hallway-seeds-1-12"], None),
})
hallway_table("Hallway study, held-out seeds 101–130", {
    "stop dead": (["results/hallway-layer-heldout/pnp-omni",
                   "results/hallway-layer-heldout/pnp-side-brake"],
                  {"orca", "pgp+orca", "pnp-side-brake"}),
    "halt within a_h up to 1.5 m/s": (["hallway-seeds-101-130"], None),
})
open_space_table("Open space, tuning seeds 1–20 (6 planners × 11 densities)",
                 "open-space-seeds-1-20-stop-dead", "open-space-seeds-1-20")
if os.path.exists(os.path.join(HERE, "open-space-seeds-101-150", "runs.csv")):
    open_space_table("Open space, held-out seeds 101–150",
                     "open-space-seeds-101-150-stop-dead", "open-space-seeds-101-150")
replay_table("seq_eth, partial runs", "seq_eth-partial-stop-dead", "seq_eth-partial")
replay_table("zara01, partial runs", "zara01-partial-stop-dead", "zara01-partial")
