#!/usr/bin/env python3
"""Tallies the person-caused contacts that `fleet_contacts` prints (lines starting `other t`),
per group of probe files: when in the run, where the robot stood, how fast it moved, and where
the person came from in the robot's motion.

    python3 tally.py probe/warehouse-*.txt
    python3 tally.py --group probe/warehouse-*.txt -- probe/narrow-*.txt -- probe/hallway-*.txt
"""
import re
import sys
from collections import Counter

LINE = re.compile(
    r"^other t\s+(\S+) robot \d+ person \d+: (\w+), robot speed ([\d.]+), person speed ([\d.]+), "
    r"the person (\w+), walking the robot's way (\w+), at a station (\w+), "
    r"the person walking to it \w+, the layer (\w+)"
)


def tally(files):
    runs, rows = 0, []
    for name in files:
        runs += 1
        with open(name) as f:
            for line in f:
                m = LINE.match(line)
                if m:
                    rows.append(m.groups())
    n = len(rows)
    if n == 0:
        return f"{runs} runs: no person-caused contact"
    times = [float(r[0]) for r in rows]
    rows = [r[1:] for r in rows]
    when = Counter(
        "first 5 s" if t < 5.0 else "5–60 s" if t < 60.0 else "after 60 s" for t in times
    )
    place = Counter(r[0] for r in rows)
    speed = Counter(
        "standing" if float(r[1]) < 0.05 else "slow" if float(r[1]) < 0.3 else "moving"
        for r in rows
    )
    side = Counter(
        "behind, walking its way" if (r[3] == "behind" and r[4] == "true") else
        "standing robot" if r[3] == "standing" else
        "ahead" if r[3] == "ahead" else
        "beside" if r[3] == "beside" else "behind, other way"
        for r in rows
    )
    behind = [r for r in rows if r[3] == "behind" and r[4] == "true"]
    zone = Counter(r[6] for r in rows)
    zone_behind = Counter(r[6] for r in behind)
    robot_v = sum(float(r[1]) for r in behind) / max(len(behind), 1)
    person_v = sum(float(r[2]) for r in behind) / max(len(behind), 1)

    def share(c):
        return ", ".join(f"{k} {v} ({100 * v / n:.0f} %)" for k, v in c.most_common())

    return (
        f"{runs} runs, {n} person-caused contacts ({n / runs:.1f} per run)\n"
        f"  when (s into the run): {share(when)}\n"
        f"  robot's place: {share(place)}\n"
        f"  robot's speed (standing < 0.05 m/s, slow < 0.3): {share(speed)}\n"
        f"  the person, in the robot's motion: {share(side)}\n"
        f"  behind and walking its way: robot {robot_v:.2f} m/s, person {person_v:.2f} m/s (means)\n"
        f"  at a station (within 1.5 m): {sum(r[5] == 'true' for r in rows)}\n"
        f"  the layer on the robot's command that step: {share(zone)}\n"
        f"  … of those behind and walking its way: "
        + ", ".join(f"{k} {v}" for k, v in zone_behind.most_common())
    )


def main(args):
    if args and args[0] == "--group":
        groups, current = [], []
        for a in args[1:]:
            if a == "--":
                groups.append(current)
                current = []
            else:
                current.append(a)
        groups.append(current)
    else:
        groups = [args]
    for g in groups:
        if g:
            print(f"{g[0]} …")
            print(tally(g))


if __name__ == "__main__":
    main(sys.argv[1:])
