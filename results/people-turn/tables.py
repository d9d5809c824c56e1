"""The tables of results/people-turn/REPORT.md, from the runs.csv files beside this script.

    python3 results/people-turn/tables.py
"""
import csv
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def runs(folder, robots=None, scenario="warehouse-narrow"):
    path = os.path.join(HERE, folder, "runs.csv")
    if not os.path.exists(path):
        path = os.path.join(HERE, "..", folder, "runs.csv")
    rows = [
        r
        for r in csv.DictReader(open(path))
        if r["safety"] == "true" and r["scenario"] == scenario
    ]
    if robots is not None:
        rows = [r for r in rows if r["robots"] == str(robots)]
    return {int(r["seed"]): r for r in rows}


def mean(rows, col):
    return sum(float(r.get(col) or 0) for r in rows.values()) / len(rows)


def paired(a, b, col):
    seeds = sorted(set(a) & set(b))
    d = [float(b[s][col]) - float(a[s][col]) for s in seeds]
    m = sum(d) / len(d)
    sd = math.sqrt(sum((x - m) ** 2 for x in d) / (len(d) - 1))
    return m, sd / math.sqrt(len(d))


def row(name, r, base=None):
    n = len(r)
    robots = float(next(iter(r.values()))["robots"])
    hours = robots * 300.0 / 3600.0
    grid = sum(1 for x in r.values() if float(x["gridlocks"]) > 0)
    dl = sum(1 for x in r.values() if float(x["deadlocks"]) > 0)
    # The first development build wrote no people_turns column.
    has_turns = all("people_turns" in x for x in r.values())
    turns = f"{mean(r, 'people_turns'):.1f}" if has_turns else "–"
    pair = ""
    if base is not None:
        m, se = paired(base, r, "tasks")
        pair = f"{m:+.1f} ± {se:.1f}"
    return (
        f"| {name} | {n} | {mean(r, 'tasks'):.1f} | {pair} | {100 * mean(r, 'efficiency'):.1f} % "
        f"| {mean(r, 'robot_caused_contacts'):.2f} | {mean(r, 'person_caused_contacts'):.1f} "
        f"| {mean(r, 'person_caused_contacts') / hours:.1f} | {mean(r, 'robot_robot_contacts'):.2f} "
        f"| {mean(r, 'total_contacts'):.1f} | {mean(r, 'min_human_distance_m'):.2f} "
        f"| {mean(r, 'human_delay_s'):.1f} | {100 * mean(r, 'stuck_robot_s') / (robots * 300):.1f} % "
        f"| {grid} | {dl} | {turns} |"
    )


HEAD = (
    "| run | runs | tasks per run | against off, paired (± s.e.) | efficiency | robot-caused "
    "| person-caused | person-caused per robot-hour | robot–robot | total contacts | closest (m) "
    "| people's delay (person-s) | stuck share | runs with a gridlock | runs with a deadlock "
    "| turns per run |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
)


def stuck(name, r):
    robots = float(next(iter(r.values()))["robots"])
    parts = ["policy", "person", "robot", "layer", "planner"]
    return f"| {name} | " + " | ".join(
        f"{mean(r, f'stuck_by_{p}_s'):.0f}" for p in parts
    ) + f" | {mean(r, 'stuck_aisle_s'):.0f} | {mean(r, 'stuck_cross_aisle_s'):.0f} |"


STUCK_HEAD = (
    "| run | held by: policy | a person | a robot | the layer | nothing visible | in aisles | in cross-aisles |\n"
    "|---|---:|---:|---:|---:|---:|---:|---:|"
)


def main():
    cells = [
        ("tuning seeds 1–30", [
            ("`warehouse-narrow`, 20 robots", "seeds-1-30/narrow-20-off", "seeds-1-30/narrow-20-t5", "seeds-1-30/narrow-20-t10"),
            ("`warehouse-narrow`, 40 robots", "seeds-1-30/narrow-40-off", "seeds-1-30/narrow-40-t5", "seeds-1-30/narrow-40-t10"),
        ]),
    ]
    for title, group in cells:
        print(f"### {title}\n")
        print(HEAD)
        for site, off, t5, t10 in group:
            base = runs(off)
            print(row(f"{site}, off", base))
            for name, folder in ((f"{site}, 5 s", t5), (f"{site}, 10 s (the default)", t10)):
                if os.path.exists(os.path.join(HERE, folder, "runs.csv")):
                    print(row(name, runs(folder), base))
        print()
    print("### development builds, tuning seeds 1–30 (how the rule and its 10 s were arrived at)\n")
    print(HEAD)
    dev = [
        ("first build", "first-build", [(20, t) for t in (5, 10, 20)]),
        ("second build", "second-build", [(20, t) for t in (3, 5, 10)] + [(40, t) for t in (5, 10)]),
        ("third build", "third-build", [(n, t) for n in (20, 40) for t in (5, 10)]),
    ]
    for name, prefix, cells_ in dev:
        for n, t in cells_:
            base = runs(f"seeds-1-30/narrow-{n}-off")
            print(row(f"{name}, {n} robots, {t} s", runs(f"development/{prefix}-narrow-{n}-t{t}"), base))
    print()
    held = [
        ("`warehouse-narrow`, 20 robots", "halting/fleets-seeds-101-130", 20, "seeds-101-130", 20),
        ("`warehouse-narrow`, 40 robots", "halting/fleets-seeds-101-130", 40, "seeds-101-130", 40),
    ]
    if all(os.path.exists(os.path.join(HERE, f, "runs.csv")) for _, _, _, f, _ in held):
        print("### held-out seeds 101–130 (the rule at 10 s, the default)\n")
        print(HEAD)
        for site, off, n_off, on, n_on in held:
            base = runs(off, n_off)
            print(row(f"{site}, off", base))
            print(row(f"{site}, 10 s", runs(on, n_on), base))
        print()
        print("### where the stuck robot-seconds went (means per run)\n")
        print(STUCK_HEAD)
        for site, off, n_off, on, n_on in held:
            print(stuck(f"{site}, held out, off", runs(off, n_off)))
            print(stuck(f"{site}, held out, 10 s", runs(on, n_on)))
        print()


if __name__ == "__main__":
    main()
