"""Tallies fleet_contacts runs.

    python3 tally.py FILE...          runs, tasks per run, robot-caused, other contacts per run
    python3 tally.py --pair BASE NEW  NEW minus BASE per seed: mean ± standard error
"""
import math
import re
import sys


def runs(path):
    """seed -> (tasks, robot-caused, other contacts)"""
    out = {}
    for line in open(path):
        m = re.search(r"seed (\d+): (\d+) robot-caused, (\d+) other .* (\d+) tasks", line)
        if m:
            seed, caused, other, tasks = map(int, m.groups())
            out[seed] = (tasks, caused, other)
    return out


def mean_se(values):
    n = len(values)
    mean = sum(values) / n
    var = sum((v - mean) ** 2 for v in values) / (n - 1) if n > 1 else 0.0
    return mean, math.sqrt(var / n)


if sys.argv[1] == "--pair":
    base, new = runs(sys.argv[2]), runs(sys.argv[3])
    seeds = sorted(set(base) & set(new))
    for k, name in enumerate(["tasks", "robot-caused", "other contacts"]):
        m, se = mean_se([new[s][k] - base[s][k] for s in seeds])
        print(f"{name}: {m:+.2f} ± {se:.2f} per run over {len(seeds)} seeds")
else:
    for path in sys.argv[1:]:
        r = runs(path).values()
        n = len(r)
        tasks, caused, other = (sum(x[k] for x in r) for k in range(3))
        print(f"{path}: {n} runs | tasks per run {tasks / n:.2f} | robot-caused {caused}"
              f" | other contacts with people per run {other / n:.1f}")
