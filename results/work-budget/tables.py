#!/usr/bin/env python3
"""tables.py FILE...: sums budget.sh outputs over seeds: tasks, metres driven, metres of progress along the route, and the metres that were not, by whether the layer held the command back and whether a person was within 2 m."""
import re, sys
for f in sys.argv[1:]:
    t = dict(tasks=0, driven=0, prog=0, rer=0, seeds=0)
    cells = {}
    for line in open(f):
        if m := re.match(r"tasks (\d+)", line): t["tasks"] += int(m[1]); t["seeds"] += 1
        if m := re.match(r"with a task: (\d+) m driven", line): t["driven"] += int(m[1])
        if m := re.match(r"of it (\d+) m along the route, (-?\d+) m not .*added (\d+) m", line):
            t["prog"] += int(m[1]); t["rer"] += int(m[3])
        if m := re.match(r"  (layer [a-z ]+), (.*): driven (\d+) m, progress (-?\d+) m", line):
            k = (m[1], m[2]); d, p = cells.get(k, (0, 0)); cells[k] = (d + int(m[3]), p + int(m[4]))
    n = t["seeds"]
    print(f"{f}: {n} seeds, tasks/run {t['tasks']/n:.1f}, driven/run {t['driven']/n:.0f} m, progress/run {t['prog']/n:.0f} m, not {100*(t['driven']-t['prog'])/t['driven']:.1f} %, rerouted/run {t['rer']/n:.0f} m")
    for k, (d, p) in cells.items():
        print(f"   {k[0]:16s} {k[1]:20s} driven {d/n:6.0f} m  progress {p/n:6.0f} m  not {(d-p)/n:5.0f} m")
