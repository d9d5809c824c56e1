#!/usr/bin/env python3
"""The tables of results/safety/REPORT.md, from the committed study outputs (standard library
only): each study as published (no safety layer) beside the same study with the layer.

    python3 results/safety/tables.py
"""
import csv
import json
import os
import statistics

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
PLANNERS = ["dwa", "orca", "sf", "pgp+dwa", "pgp+orca", "pgp+sf"]


def rows(path):
    with open(os.path.join(ROOT, path), newline="") as f:
        return list(csv.DictReader(f))


def mean(xs):
    xs = list(xs)
    return statistics.fmean(xs) if xs else float("nan")


def open_space():
    off, on = rows("open-space/runs.csv"), rows("open-space-safety/runs.csv")
    print("### Open space: 6 planners × 11 densities × 100 seeds (6,600 runs each)\n")
    print("| planner | success | time to goal (s, successes) | robot-caused contacts | "
          "person-caused contacts | collision rate while moving | people's delay (s per run) |")
    print("|---|---|---|---|---|---|---|")
    total = [0, 0, 0, 0]
    for p in PLANNERS:
        cells = []
        for col in ("success", "time", "robot", "person", "collision", "delay"):
            pair = []
            for data in (off, on):
                r = [x for x in data if x["algorithm"] == p]
                if col == "success":
                    pair.append(f"{mean(x['success'] == 'true' for x in r):.1%}")
                elif col == "time":
                    pair.append(f"{mean(float(x['time_to_goal_s']) for x in r if x['success'] == 'true'):.1f}")
                elif col == "robot":
                    pair.append(str(sum(int(x["robot_caused_contacts"]) for x in r)))
                elif col == "person":
                    pair.append(str(sum(int(x["person_caused_contacts"]) for x in r)))
                elif col == "collision":
                    pair.append(f"{mean(float(x['collision_rate']) for x in r):.1%}")
                else:
                    pair.append(f"{mean(float(x['human_delay_s']) for x in r):.2f}")
            cells.append(" → ".join(pair))
        print(f"| {p} | " + " | ".join(cells) + " |")
    for data, k in ((off, 0), (on, 2)):
        total[k] = sum(int(x["robot_caused_contacts"]) for x in data)
        total[k + 1] = sum(int(x["person_caused_contacts"]) for x in data)
    print(f"| all | | | {total[0]} → {total[2]} | {total[1]} → {total[3]} | | |\n")
    print("Success by density (as published → with the layer):\n")
    densities = sorted({float(x["density"]) for x in off})
    print("| planner | " + " | ".join(f"{d:g}" for d in densities) + " |")
    print("|---|" + "---|" * len(densities))
    for p in PLANNERS:
        cells = []
        for d in densities:
            pair = []
            for data in (off, on):
                r = [x for x in data if x["algorithm"] == p and float(x["density"]) == d]
                pair.append(f"{mean(x['success'] == 'true' for x in r):.2f}")
            cells.append("→".join(pair))
        print(f"| {p} | " + " | ".join(cells) + " |")
    print()


def intent_sharing():
    path_off = os.path.join(ROOT, "intent-sharing/runs.json")
    path_on = os.path.join(ROOT, "safety/intent-sharing.json")
    if not (os.path.exists(path_off) and os.path.exists(path_on)):
        print("(intent-sharing runs missing)\n")
        return
    off, on = json.load(open(path_off)), json.load(open(path_on))
    print("### Intent sharing: warehouse, 12 robots, 40 people, pgp+orca, 300 s, seeds 1–100\n")
    print("Means per run (a run is one seed with sharing on or off); tasks per minute is the "
          "fleet's.\n")
    print("| sharing | layer | tasks / min | robot-caused | person-caused | robot–robot contacts "
          "| wall contacts | robot contact steps | collision rate | SVR | protective commands |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for sharing in (True, False):
        for label, data in (("off", off), ("on", on)):
            r = [x for x in data if x["sharing"] == sharing]
            print(f"| {'on' if sharing else 'off'} | {label} | {mean(x['tasks'] for x in r) / 5:.2f} "
                  f"| {mean(x['robot_caused_contacts'] for x in r):.2f} "
                  f"| {mean(x['person_caused_contacts'] for x in r):.2f} "
                  f"| {mean(x['robot_robot_contacts'] for x in r):.2f} "
                  f"| {mean(x['wall_contacts'] for x in r):.2f} "
                  f"| {mean(x['robot_contact_steps'] for x in r):.2f} "
                  f"| {mean(x['collision_rate'] for x in r):.3%} "
                  f"| {mean(x['svr'] for x in r):.3f} "
                  f"| {mean(x['protective_commands'] for x in r):.0f} |")
    for label, data in (("off", off), ("on", on)):
        print(f"\nLayer {label}: robot-caused contacts summed over all 200 runs: "
              f"{sum(x['robot_caused_contacts'] for x in data)}; person-caused: "
              f"{sum(x['person_caused_contacts'] for x in data)}; robot–robot: "
              f"{sum(x['robot_robot_contacts'] for x in data)}.")
    print()


def replay():
    for seq in ("seq_eth", "zara01"):
        off_dir, on_dir = f"eth/{seq}-partial", f"safety/{seq}-partial"
        if not os.path.exists(os.path.join(ROOT, on_dir, "runs.csv")):
            print(f"({seq} runs missing)\n")
            continue
        off, on = rows(f"{off_dir}/runs.csv"), rows(f"{on_dir}/runs.csv")
        print(f"### Replay, {seq}, partial runs (recorded people do not react)\n")
        print("| planner | runs | reached | robot-caused | person-caused | appeared too close "
              "| μ(s) (m) | μ(d_r) (m) | μ(duration) (s) |")
        print("|---|---|---|---|---|---|---|---|---|")
        planners = list(dict.fromkeys(x["planner"] for x in off))
        for p in planners:
            cells = []
            for col in ("runs", "reached", "robot", "person", "appeared", "s", "path", "duration"):
                pair = []
                for data in (off, on):
                    r = [x for x in data if x["planner"] == p]
                    if col == "runs":
                        pair.append(str(len(r)))
                    elif col == "reached":
                        pair.append(f"{mean(x['reached'] == 'true' for x in r):.0%}")
                    elif col == "robot":
                        pair.append(str(sum(int(x["robot_caused_contacts"]) for x in r)))
                    elif col == "person":
                        pair.append(str(sum(int(x["person_caused_contacts"]) for x in r)))
                    elif col == "appeared":
                        pair.append(str(sum(int(x["appeared_contacts"]) for x in r)))
                    elif col == "s":
                        pair.append(f"{mean(float(x['s_m']) for x in r if x['s_m'] not in ('', 'inf')):.2f}")
                    elif col == "path":
                        pair.append(f"{mean(float(x['path_m']) for x in r):.1f}")
                    else:
                        pair.append(f"{mean(float(x['duration_s']) for x in r):.1f}")
                cells.append(pair[0] if col == "runs" else " → ".join(pair))
            print(f"| {p} | " + " | ".join(cells) + " |")
        print()


if __name__ == "__main__":
    open_space()
    intent_sharing()
    replay()
