#!/usr/bin/env python3
"""tables.py RUNS.csv...: per cell (site, robots, planner folder), means over runs of a traffic
study's runs.csv: tasks, efficiency, deadlocks, gridlocks, stuck share and where the stuck time
was, robot-robot contacts."""
import csv, sys, statistics as st

print("| runs | site | robots | runs | tasks per run (fewest) | efficiency | runs with a deadlock (deadlocks) | runs with a gridlock | stuck share | stuck: corridor / cross-aisle / aisle / near a station | held by: policy / robot / layer / nothing visible | robot–robot contacts |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|---:|")
for path in sys.argv[1:]:
    cells = {}
    for r in csv.DictReader(open(path)):
        cells.setdefault((r["scenario"], int(r["robots"])), []).append(r)
    for (site, robots), v in sorted(cells.items()):
        m = lambda c: st.mean(float(x[c]) for x in v)
        stuck = m("stuck_robot_s")
        share = stuck / (robots * 300.0)
        where = [m(c) for c in ("stuck_corridor_s", "stuck_cross_aisle_s", "stuck_aisle_s", "stuck_station_s")]
        held = [m(c) for c in ("stuck_by_policy_s", "stuck_by_robot_s", "stuck_by_layer_s", "stuck_by_planner_s")]
        pct = lambda xs: " / ".join(f"{100 * x / stuck:.0f} %" if stuck > 0 else "–" for x in xs)
        print(f"| {path.rsplit('/', 2)[-2]} | {site} | {robots} | {len(v)} | {m('tasks'):.1f} ({min(int(x['tasks']) for x in v)}) "
              f"| {100 * m('efficiency'):.1f} % | {sum(int(x['deadlocks']) > 0 for x in v)} ({sum(int(x['deadlocks']) for x in v)}) "
              f"| {sum(int(x['gridlocks']) > 0 for x in v)} | {100 * share:.1f} % | {pct(where)} | {pct(held)} | {m('robot_robot_contacts'):.2f} |")
