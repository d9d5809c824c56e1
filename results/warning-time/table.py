"""The report's tables: each cell's runs with the 0.5 s warning field paired by seed against the
same seeds with the layer's 1 s, from the repository's root:

    python3 results/warning-time/table.py

Means per run; the difference is paired by seed (new - old, mean ± standard error).
"""
import csv, statistics as st

R = "results/"
W = R + "warning-time/"
B = R + "fleet-pnp-right/"
CELLS = [  # cell, seeds, new runs, old (1 s) runs
    ("`warehouse`, 8", "1–30", [W + "warehouse-8-seeds-1-30"], [B + "warehouse-8-seeds-1-30"]),
    ("`warehouse`, 8, held out", "101–130", [W + "warehouse-8-seeds-101-130"], [B + "warehouse-8-seeds-101-130"]),
    ("`warehouse`, 8, T_w 0.25 s", "1–30", [W + "warehouse-8-wt025-seeds-1-30"], [B + "warehouse-8-seeds-1-30"]),
    ("`hallway-fleet`, 20", "1–10", [W + "hallway-20-seeds-1-10"],
     [B + "hallway-20-seeds-1-6", R + "pnp-right-layer/hallway-20-default-seeds-7-10"]),
    ("`hallway-fleet`, 20, held out", "101–110", [W + "hallway-20-seeds-101-110"], [B + "hallway-20-seeds-101-130"]),
    ("`hallway-fleet`, 20, held out", "101–130",
     [W + "hallway-20-seeds-101-110", W + "hallway-20-seeds-111-130"], [B + "hallway-20-seeds-101-130"]),
    ("`warehouse-narrow`, 20", "1–10", [W + "narrow-20-seeds-1-10"], [B + "narrow-20-seeds-1-6", B + "narrow-20-seeds-7-30"]),
    ("`warehouse-narrow`, 20, held out", "101–110", [W + "narrow-20-seeds-101-110"], [B + "narrow-20-seeds-101-110"]),
]
COLS = [("tasks", 1, "{:.1f}"), ("efficiency", 100, "{:.1f} %"), ("robot_caused_contacts", 1, "{:.2f}"),
        ("person_caused_contacts", 1, "{:.1f}"), ("total_contacts", 1, "{:.1f}"),
        ("min_human_distance_m", 1, "{:.3f}"), ("human_delay_s", 1, "{:.0f}"),
        ("stuck_robot_s", 1, "{:.0f}"), ("gridlocks", 1, "{:.1f}")]


def load(dirs):
    runs = {}
    for d in dirs:
        try:
            for r in csv.DictReader(open(d + "/runs.csv")):
                runs[r["seed"]] = r
        except FileNotFoundError:
            return None
    return runs


print("| cell | seeds | | tasks | efficiency | robot-caused | person-caused | total contacts | closest (m) | people's delay (person-s) | stuck robot-s | gridlock runs |")
print("|---|---|---|" + "---:|" * len(COLS))
for cell, seeds, new, old in CELLS:
    a, b = load(new), load(old)
    if a is None:
        continue
    ks = sorted(set(a) & set(b), key=int)
    val = lambda runs, c, s: [float(runs[k][c]) * s for k in ks]
    for label, runs in (("1 s", b), ("0.5 s" if "0.25" not in cell else "0.25 s", a)):
        cells = [f.format(st.mean(val(runs, c, s))) for c, s, f in COLS]
        print(f"| {cell if label == '1 s' else ''} | {seeds if label == '1 s' else ''} | {label} | " + " | ".join(cells) + " |")
    diffs = []
    for c, s, f in COLS:
        d = [x - y for x, y in zip(val(a, c, s), val(b, c, s))]
        diffs.append(f"{st.mean(d):+.2f} ± {st.stdev(d) / len(d) ** .5:.2f}")
    print("| | | paired | " + " | ".join(diffs) + " |")
