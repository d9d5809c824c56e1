#!/usr/bin/env python3
"""tables.py RUNS.csv...: one row per runs.csv and cell (site, robots, planner): the work and,
beside it, every counter-measure (means per run): tasks, efficiency, contacts of every cause,
closeness, people's delay, deadlocks and gridlocks, stuck share. Only runs with the traffic policy
and the safety layer on."""
import csv, sys, statistics as st

print("| runs | planner | site | robots | runs | tasks per run | efficiency | robot-caused | person-caused | robot–robot | walls | total contacts | closest, mean of runs (m) | people's delay (person-s) | runs with a deadlock | runs with a gridlock | stuck share |")
print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for path in sys.argv[1:]:
    cells = {}
    for r in csv.DictReader(open(path)):
        if (r["policy"], r["safety"]) != ("true", "true"):
            continue
        cells.setdefault((r["scenario"], int(r["robots"]), r.get("planner", "")), []).append(r)
    for (site, robots, planner), v in sorted(cells.items()):
        m = lambda c: st.mean(float(x[c]) for x in v)
        share = m("stuck_robot_s") / (robots * 300.0)
        print(f"| {'/'.join(path.rsplit('/', 3)[-3:-1])} | {planner} | {site} | {robots} | {len(v)} | {m('tasks'):.1f} "
              f"| {100 * m('efficiency'):.1f} % | {m('robot_caused_contacts'):.2f} | {m('person_caused_contacts'):.1f} "
              f"| {m('robot_robot_contacts'):.2f} | {m('wall_contacts'):.2f} | {m('total_contacts'):.1f} "
              f"| {m('min_human_distance_m'):.2f} | {m('human_delay_s'):.0f} "
              f"| {sum(int(x['deadlocks']) > 0 for x in v)} | {sum(int(x['gridlocks']) > 0 for x in v)} | {100 * share:.1f} % |")
