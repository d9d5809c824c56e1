"""Issue 45's tables from the committed fleet studies' summary.json files: fleet efficiency,
stuck time by what held the robots, gridlocks and contacts, for the development seeds (1-30),
the held-out seeds (101-130), the world before people gave up stalled goals (same seeds 1-30)
and one robot on each site among the same people.

    python3 results/traffic/efficiency.py
"""
import json
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
TARGET = {"warehouse": 0.80, "warehouse-narrow": 0.50, "hallway-fleet": 0.40}


def cells(study):
    path = ROOT / study / "summary.json"
    return json.loads(path.read_text()) if path.exists() else []


def find(rows, site, robots, layer=True):
    for c in rows:
        if (c["scenario"], c["robots"], c["policy"], c["safety"]) == (site, robots, True, layer):
            return c
    return None


def pct(x):
    return "–" if x is None else f"{100 * x:.0f} %"


def main():
    dev, held = cells("fleet-safety"), cells("fleet-safety-heldout")
    before, alone = cells("fleet-efficiency-before"), cells("fleet-one-robot")
    sites = [("warehouse", 8), ("warehouse-narrow", 20), ("warehouse-narrow", 40), ("hallway-fleet", 20)]

    print("### Efficiency, layer and policy on (target on held-out seeds)\n")
    print("| cell | target | held out 101–130 | development 1–30 | people kept stalled goals (1–30) "
          "| no layer (1–30) | one robot among the people (1–30) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for site, n in sites:
        h, d, b, o = find(held, site, n), find(dev, site, n), find(before, site, n), find(dev, site, n, False)
        one = find(alone, site, 1)
        target = f"≥ {pct(TARGET[site])}" if n != 40 else "throughput ≥ 20's"
        print(f"| `{site}`, {n} | {target} | {pct(h and h['efficiency'])} | {pct(d and d['efficiency'])} "
              f"| {pct(b and b['efficiency'])} | {pct(o and o['efficiency'])} | {pct(one and one['efficiency'])} |")

    print("\n### Throughput, stuck time, gridlocks, deadlocks (layer and policy on)\n")
    print("| cell | seeds | tasks/min | stuck share | runs with a gridlock | gridlocks | deadlocks "
          "| held by: policy | a person | a robot | the layer | nothing visible | people stalled |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for label, rows in [("101–130", held), ("1–30", dev), ("1–30, before", before)]:
        for site, n in sites:
            c = find(rows, site, n)
            if c is None:
                continue
            h, s = c["stuck_causes"], max(c["stuck_robot_s"], 1e-9)
            share = lambda x: f"{100 * x / s:.0f} %"
            print(f"| `{site}`, {n} | {label} | {c['tasks_per_min']:.2f} | {pct(c['stuck_share'])} "
                  f"| {c['runs_with_gridlock']} of {c['runs']} | {c['gridlocks']} | {c['deadlocks']} "
                  f"| {share(h['policy_s'])} | {share(h['person_s'])} | {share(h['robot_s'])} "
                  f"| {share(h['layer_s'])} | {share(h['planner_s'])} | {pct(c['people_stalled_share'])} |")

    print("\n### Contacts per robot-hour (layer and policy on; the issue's \"today\" is the world before)\n")
    print("| cell | seeds | robot-caused | person-caused | total | person-caused, before (1–30) "
          "| total, no layer | closest (m) | people's delay (person-s) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for label, rows, off_rows in [("101–130", held, held), ("1–30", dev, dev)]:
        for site, n in sites:
            c, b, o = find(rows, site, n), find(before, site, n), find(off_rows, site, n, False)
            if c is None:
                continue
            hours = n * 300 / 3600
            print(f"| `{site}`, {n} | {label} | {c['robot_caused_contacts'] / hours:.1f} "
                  f"| {c['person_caused_per_robot_hour']:.1f} | {c['total_per_robot_hour']:.1f} "
                  f"| {b['person_caused_per_robot_hour']:.1f} | {o['total_per_robot_hour']:.1f} "
                  f"| {c['min_human_distance_m']:.2f} | {c['human_delay_s']:.0f} |" if b and o else "")


if __name__ == "__main__":
    main()
