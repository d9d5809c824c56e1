#!/usr/bin/env python3
"""The tables of results/safety/REPORT.md, from the committed study outputs (standard library
and git only): each study without the safety layer (as the papers ran it), with the layer that
only slowed and stopped (as committed at STOPPING, before issue 43), and with the layer as it
is now (it yields, and the planners plan inside its safe set); in open space also with the
layer's default yield (as committed at DEFAULT_YIELD), before the open-space scenario had a
yield of its own.

    python3 results/safety/tables.py

Run it inside the repository: the stopping layer's outputs are read from git history.
"""
import csv
import io
import os
import statistics
import subprocess

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
# The last commit with the layer that only slowed and stopped.
STOPPING = "e9ded2f"
# The last commit whose open-space study ran the layer's default yield (2 s, 0.2 m).
DEFAULT_YIELD = "d0cf286"
OPEN_SPACE = ["dwa", "orca", "sf", "pgp+dwa", "pgp+orca", "pgp+sf"]
REPLAY = ["foigp", "foigp-1", "igp-diag", "igp-lin", "mc", "dwa", "pgp+orca"]


def rows(path):
    with open(os.path.join(ROOT, path), newline="") as f:
        return list(csv.DictReader(f))


def rows_at(rev, path):
    text = subprocess.run(
        ["git", "show", f"{rev}:results/{path}"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    return list(csv.DictReader(io.StringIO(text)))


def mean(xs):
    xs = list(xs)
    return statistics.fmean(xs) if xs else float("nan")


def three(values):
    return " / ".join(values)


def replays():
    for scene in ("seq_eth", "zara01"):
        runs = {
            "no layer": rows(f"eth/{scene}-partial/runs.csv"),
            "stopping": rows_at(STOPPING, f"safety/{scene}-partial/runs.csv"),
            "yielding": rows(f"safety/{scene}-partial/runs.csv"),
        }
        print(f"### {scene}, partial runs: no layer / stopping layer / yielding layer\n")
        print("| planner | runs | reached | %s<0.21 | robot-caused | person-caused | "
              "appeared too close | total contacts |")
        print("|---|---|---|---|---|---|---|---|")
        for p in ["human"] + REPLAY:
            cells = {k: [x for x in v if x["planner"] == p] for k, v in runs.items()}
            n = len(cells["yielding"])
            col = []
            col.append(three(f"{mean(x['reached'] == 'true' for x in c):.0%}" for c in cells.values()))
            col.append(three(f"{mean(float(x['s_m']) < 0.21 for x in c):.0%}" for c in cells.values()))
            for key in ("robot_caused_contacts", "person_caused_contacts", "appeared_contacts"):
                col.append(three(str(sum(int(x[key]) for x in c)) for c in cells.values()))
            col.append(three(str(sum(int(x["robot_caused_contacts"]) + int(x["person_caused_contacts"])
                                     + int(x["appeared_contacts"]) for x in c))
                             for c in cells.values()))
            print(f"| {p} | {n} | " + " | ".join(col) + " |")
        print()


def open_space(held_out=False):
    if held_out:
        runs = {
            "no layer": rows("open-space-heldout/runs.csv"),
            "yielding": rows("open-space-safety-heldout/runs.csv"),
        }
        print("### Open space, held-out seeds 101–200: no layer / yielding layer (open ground)\n")
    else:
        runs = {
            "no layer": rows("open-space/runs.csv"),
            "stopping": rows_at(STOPPING, "open-space-safety/runs.csv"),
            "default yield": rows_at(DEFAULT_YIELD, "open-space-safety/runs.csv"),
            "yielding": rows("open-space-safety/runs.csv"),
        }
        print("### Open space: 6 planners × 11 densities × 100 seeds: no layer / stopping layer / "
              "default yield (2 s, 0.2 m) / open-ground yield (3 s, 0.6 m)\n")
    print("| planner | success | time to goal (s, successes) | robot-caused | person-caused | "
          "total contacts | min distance to a person (m) | people's delay (s per run) |")
    print("|---|---|---|---|---|---|---|---|")
    total = lambda x: (int(x["robot_caused_contacts"]) + int(x["person_caused_contacts"])
                       + int(x["wall_contacts"]))
    for p in OPEN_SPACE:
        cells = [[x for x in v if x["algorithm"] == p] for v in runs.values()]
        col = [
            three(f"{mean(x['success'] == 'true' for x in c):.1%}" for c in cells),
            three(f"{mean(float(x['time_to_goal_s']) for x in c if x['success'] == 'true'):.1f}"
                  for c in cells),
            three(str(sum(int(x["robot_caused_contacts"]) for x in c)) for c in cells),
            three(str(sum(int(x["person_caused_contacts"]) for x in c)) for c in cells),
            three(str(sum(total(x) for x in c)) for c in cells),
            three(f"{mean(float(x['min_human_distance_m']) for x in c):.2f}" for c in cells),
            three(f"{mean(float(x['human_delay_s']) for x in c):.2f}" for c in cells),
        ]
        print(f"| {p} | " + " | ".join(col) + " |")
    sums = [sum(total(x) for x in v) for v in runs.values()]
    robot = [sum(int(x["robot_caused_contacts"]) for x in v) for v in runs.values()]
    print(f"| all | | | {three(map(str, robot))} | | {three(map(str, sums))} | | |\n")
    print("Success by density (" + " / ".join(runs) + "):\n")
    densities = sorted({float(x["density"]) for x in runs["no layer"]})
    print("| planner | " + " | ".join(f"{d:g}" for d in densities) + " |")
    print("|---|" + "---|" * len(densities))
    for p in OPEN_SPACE:
        out = []
        for d in densities:
            out.append("/".join(
                f"{mean(x['success'] == 'true' for x in v if x['algorithm'] == p and float(x['density']) == d):.2f}"
                for v in runs.values()))
        print(f"| {p} | " + " | ".join(out) + " |")
    print()


def fleets():
    for folder, seeds in (("fleet-safety", "1–30"), ("fleet-safety-heldout", "101–130")):
        path = os.path.join(ROOT, folder, "runs.csv")
        if not os.path.exists(path):
            print(f"({folder} missing)\n")
            continue
        data = rows(f"{folder}/runs.csv")
        print(f"### Fleets in-process, seeds {seeds}, 300 s, traffic policy on: layer off / on\n")
        print("| site | robots | tasks (mean per run) | robot-caused | person-caused | robot–robot | "
              "walls | total | total per robot-hour | closest (m) | people's delay (person-s) | "
              "stuck share | commands changed | of which yields |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        sites = []
        for r in data:
            if (r["scenario"], r["robots"]) not in sites:
                sites.append((r["scenario"], r["robots"]))
        for site, robots in sites:
            cells = [[x for x in data if (x["scenario"], x["robots"]) == (site, robots)
                      and x["safety"] == on] for on in ("false", "true")]
            hours = int(robots) * 300 / 3600

            def m(key, fmt="{:.1f}", scale=1.0):
                return " / ".join(fmt.format(scale * mean(float(x[key]) for x in c)) for c in cells)

            def share(key):
                out = []
                for c in cells:
                    checked = sum(int(x["layer_checked"]) for x in c)
                    n = sum(int(x[k]) for x in c for k in key)
                    out.append(f"{n / checked:.1%}" if checked else "–")
                return " / ".join(out)
            stuck = " / ".join(f"{mean(float(x['stuck_robot_s']) for x in c) / (int(robots) * 300):.0%}"
                               for c in cells)
            print(f"| {site} | {robots} | {m('tasks')} | {m('robot_caused_contacts')} | "
                  f"{m('person_caused_contacts')} | {m('robot_robot_contacts')} | {m('wall_contacts')} | "
                  f"{m('total_contacts')} | {m('total_contacts', scale=1 / hours)} | "
                  f"{m('min_human_distance_m', '{:.2f}')} | {m('human_delay_s')} | {stuck} | "
                  f"{share(('layer_warned', 'layer_protective', 'yielded'))} | {share(('yielded',))} |")
        print()


if __name__ == "__main__":
    replays()
    open_space()
    open_space(held_out=True)
    fleets()
