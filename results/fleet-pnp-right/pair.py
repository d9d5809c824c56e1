#!/usr/bin/env python3
"""pair.py NEW.csv[,NEW.csv...] OLD.csv[,OLD.csv...]: the new runs against the old on the same
(site, robots, seed), mean difference per run ± its standard error, for the work and the
counter-measures. Only runs with the traffic policy and the safety layer on."""
import csv, sys, statistics as st

def load(arg):
    runs = {}
    for path in arg.split(","):
        for r in csv.DictReader(open(path)):
            if (r["policy"], r["safety"]) != ("true", "true"):
                continue
            runs[(r["scenario"], r["robots"], r["seed"])] = r
    return runs

new, old = load(sys.argv[1]), load(sys.argv[2])
keys = sorted(set(new) & set(old), key=lambda k: (k[0], int(k[1]), int(k[2])))
print(f"{len(keys)} paired runs")
for col in ("tasks", "robot_caused_contacts", "person_caused_contacts", "robot_robot_contacts",
            "total_contacts", "min_human_distance_m", "human_delay_s", "stuck_robot_s"):
    d = [float(new[k][col]) - float(old[k][col]) for k in keys]
    se = st.stdev(d) / len(d) ** 0.5 if len(d) > 1 else float("nan")
    base = st.mean(float(old[k][col]) for k in keys)
    print(f"  {col}: {st.mean(d):+.2f} ± {se:.2f} (old mean {base:.2f})")
