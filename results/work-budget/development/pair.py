#!/usr/bin/env python3
"""pair.py BASE NEW [ROBOTS]: paired per-seed comparison of two traffic studies (each a study's
folder or its runs.csv), layer-on runs only: mean ± standard error of the per-seed differences."""
import csv, sys, math
def load(d, robots):
    out = {}
    for r in csv.DictReader(open(d if d.endswith(".csv") else f"{d}/runs.csv")):
        if r["safety"] != "true": continue
        if robots and r["robots"] != robots: continue
        out[(r["scenario"], r["robots"], int(r["seed"]))] = r
    return out
a, b = load(sys.argv[1], sys.argv[3] if len(sys.argv) > 3 else None), load(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else None)
keys = sorted(set(a) & set(b))
cells = sorted(set((k[0], k[1]) for k in keys))
for cell in cells:
    ks = [k for k in keys if (k[0], k[1]) == cell]
    print(f"{cell[0]} {cell[1]} robots, {len(ks)} seeds")
    for col in ["tasks", "efficiency", "robot_caused_contacts", "person_caused_contacts", "total_contacts", "min_human_distance_m", "human_delay_s", "stuck_robot_s", "gridlocks"]:
        xa = [float(a[k][col]) for k in ks]; xb = [float(b[k][col]) for k in ks]
        d = [y - x for x, y in zip(xa, xb)]
        m = sum(d) / len(d)
        se = math.sqrt(sum((x - m) ** 2 for x in d) / (len(d) - 1) / len(d)) if len(d) > 1 else 0
        if col == "gridlocks":
            print(f"  runs with a gridlock: {sum(1 for x in xa if x > 0)} -> {sum(1 for x in xb if x > 0)}")
        else:
            print(f"  {col:24s} {sum(xa)/len(xa):8.3f} -> {sum(xb)/len(xb):8.3f}   paired {m:+.3f} ± {se:.3f}")
