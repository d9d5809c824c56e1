#!/usr/bin/env python3
"""Where do the planners come closer than 0.3 m to a recorded pedestrian?

Reads a `gapfleet study replay` (formerly `eth`) output folder (runs.csv) and the sequence it ran on, and
classifies every run with s < 0.3 m by the geometry at the closest moment: the pedestrian's
recorded velocity against the run's direction (start -> goal): "same way" (cos > 0.5: walking
the robot's way, i.e. overtaking or being overtaken), "head-on" (cos < -0.5) or "crossing";
"standing" if slower than 0.2 m/s; and whether the pedestrian belongs to the removed person's
group (groups.txt).

    python3 results/eth/closest_approaches.py results/eth/seq_eth-partial world-sim/datasets/ETH/seq_eth
"""

import csv
import math
import sys
from collections import Counter, defaultdict
from pathlib import Path


def load_obsmat(path):
    tracks = defaultdict(list)
    frames = []
    for line in open(path):
        f = line.split()
        if len(f) != 8:
            continue
        frame, pid = int(float(f[0])), int(float(f[1]))
        tracks[pid].append((frame, float(f[2]), float(f[4]), float(f[5]), float(f[7])))
        frames.append(frame)
    gaps = Counter()
    for t in tracks.values():
        t.sort()
        gaps.update(b[0] - a[0] for a, b in zip(t, t[1:]))
    step = min(g for g, c in gaps.items() if c == max(gaps.values()))
    first = min(frames)
    return {
        pid: [((fr - first) / step * 0.4, x, y, vx, vy) for fr, x, y, vx, vy in t]
        for pid, t in tracks.items()
    }


def state_at(track, t):
    # runs.csv rounds times to 0.1 s: clamp to the track's ends within that rounding.
    if track[0][0] - 0.06 <= t < track[0][0]:
        t = track[0][0]
    if track[-1][0] < t <= track[-1][0] + 0.06:
        t = track[-1][0]
    if len(track) == 1 and t == track[0][0]:
        return list(track[0][1:])
    for a, b in zip(track, track[1:]):
        if a[0] <= t <= b[0]:
            w = (t - a[0]) / (b[0] - a[0])
            return [a[i] + (b[i] - a[i]) * w for i in range(1, 5)]
    return None


def main(out_dir, dataset_dir):
    tracks = load_obsmat(Path(dataset_dir) / "obsmat.txt")
    group_of = {}
    groups = Path(dataset_dir) / "groups.txt"
    if groups.exists():
        for line in open(groups):
            ids = [int(float(v)) for v in line.split()]
            for i in ids:
                group_of[i] = set(ids)
    rows = list(csv.DictReader(open(Path(out_dir) / "runs.csv")))
    table = defaultdict(Counter)
    for r in rows:
        if not r["s_m"] or float(r["s_m"]) >= 0.3 or not r["closest_pedestrian"]:
            continue
        me, other = int(r["pedestrian"]), int(r["closest_pedestrian"])
        t = float(r["closest_t_s"])
        start = state_at(tracks[me], float(r["t_start_s"]))
        goal = state_at(tracks[me], float(r["t_end_s"]))
        ped = state_at(tracks[other], t)
        if start is None or goal is None or ped is None:
            kind = "unknown"
        else:
            dx, dy = goal[0] - start[0], goal[1] - start[1]
            speed = math.hypot(ped[2], ped[3])
            if speed < 0.2:
                kind = "standing"
            else:
                cos = (dx * ped[2] + dy * ped[3]) / (math.hypot(dx, dy) * speed + 1e-12)
                kind = "same way" if cos > 0.5 else "head-on" if cos < -0.5 else "crossing"
        if other in group_of.get(me, ()):
            kind += " (own group)"
        table[r["planner"]][kind] += 1
    kinds = sorted({k for c in table.values() for k in c})
    print(f"runs with s < 0.3 m in {out_dir}, by the closest pedestrian's motion\n")
    print("| planner | " + " | ".join(kinds) + " | total |")
    print("|---|" + "---|" * (len(kinds) + 1))
    for planner, c in table.items():
        print(f"| {planner} | " + " | ".join(str(c[k]) for k in kinds) + f" | {sum(c.values())} |")


if __name__ == "__main__":
    main(*sys.argv[1:3])
