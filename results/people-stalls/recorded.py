"""How often recorded people stand still: the share of person-time slower than 0.1 m/s and the
share of 10 s windows in which a person moved less than 1 m, in every obsmat.txt under
../shared/datasets (2.5 fps: 0.4 s between a person's samples). The simulated figures to
compare with: `cargo run --release -p world-sim --example crowd_stalls`.

    python3 results/people-stalls/recorded.py [DATASETS_DIR]
"""
import collections
import math
import pathlib
import sys

STEP_S = 0.4
WINDOW = 25  # samples: 10 s


def stalls(path):
    tracks = collections.defaultdict(list)
    for line in path.read_text().splitlines():
        f = line.split()
        if len(f) < 8:
            continue
        tracks[int(float(f[1]))].append((float(f[0]), float(f[2]), float(f[4])))
    slow = steps = stalled = windows = 0
    speed = 0.0
    for t in tracks.values():
        t.sort()
        for a, b in zip(t, t[1:]):
            v = math.hypot(b[1] - a[1], b[2] - a[2]) / STEP_S
            steps += 1
            slow += v < 0.1
            speed += v
        for i in range(0, len(t) - WINDOW, WINDOW):
            windows += 1
            stalled += math.hypot(t[i + WINDOW][1] - t[i][1], t[i + WINDOW][2] - t[i][2]) < 1.0
    return len(tracks), slow / steps, stalled / max(windows, 1), windows, speed / steps


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/datasets")
    print("| scene | people | person-time < 0.1 m/s | 10 s windows moved < 1 m | mean speed (m/s) |")
    print("|---|---:|---:|---:|---:|")
    for path in sorted(root.glob("*/*/obsmat.txt")):
        n, slow, stalled, windows, speed = stalls(path)
        print(f"| {path.parent.name} | {n} | {100 * slow:.1f} % | {100 * stalled:.1f} % (of {windows}) | {speed:.2f} |")


if __name__ == "__main__":
    main()
