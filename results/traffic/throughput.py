"""Throughput against fleet size in the narrow warehouse, development and held-out seeds.

Issue 45 asks for a plot of throughput against fleet size for both seed sets. Each traffic
study draws its own `throughput.png` for the seeds it ran; this script draws the committed
`pnp-right` runs of both sets in one figure, from their `runs.csv`, with the standard error
of the mean as bars. It writes `throughput-pnp-right.svg` beside itself (plain SVG: no
plotting library needed) and prints the points.

    python3 results/traffic/throughput.py
"""
import os
import statistics as st

from targets import CELLS, runs  # the committed runs, as the targets table reads them

SCENARIO = "warehouse-narrow"
SERIES = [  # label, colour, the seed set's name in `targets.CELLS`
    ("development seeds 1–30", "#1f77b4", "1–30"),
    ("held-out seeds 101–130", "#d62728", "101–130 (held out)"),
]
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "throughput-pnp-right.svg")


def points():
    """(label, colour, [(robots, mean, standard error, runs)]) per series."""
    out = []
    for label, colour, seeds in SERIES:
        pts = []
        for scenario, robots, cell_seeds, dirs in CELLS:
            if (scenario, cell_seeds) != (SCENARIO, seeds):
                continue
            rows = runs(dirs, scenario, robots)
            if rows is None:
                continue
            v = [float(r["tasks_per_min"]) for r in rows]
            se = st.stdev(v) / len(v) ** 0.5 if len(v) > 1 else 0.0
            pts.append((robots, st.mean(v), se, len(v)))
        out.append((label, colour, sorted(pts)))
    return out


def svg(series):
    w, h, left, right, top, bottom = 680, 440, 70, 30, 70, 60
    x_max = 50.0
    y_max = max((m + s for _, _, pts in series for _, m, s, _ in pts), default=1.0)
    y_max = 2.0 * int(y_max / 2.0 + 1.0)
    px = lambda x: left + (w - left - right) * x / x_max
    py = lambda y: h - bottom - (h - top - bottom) * y / y_max
    e = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
         f'font-family="sans-serif" font-size="12">',
         f'<rect width="{w}" height="{h}" fill="white"/>',
         f'<text x="{w / 2}" y="22" text-anchor="middle" font-size="15">Throughput against '
         f'fleet size, narrow warehouse</text>',
         f'<text x="{w / 2}" y="42" text-anchor="middle">40 people, 300 s, safety layer and '
         f'traffic policy on, pnp-right</text>']
    for x in range(0, int(x_max) + 1, 10):
        e.append(f'<line x1="{px(x)}" y1="{py(0)}" x2="{px(x)}" y2="{py(0) + 5}" stroke="black"/>')
        e.append(f'<text x="{px(x)}" y="{py(0) + 18}" text-anchor="middle">{x}</text>')
    for y in range(0, int(y_max) + 1, 2):
        e.append(f'<line x1="{px(0)}" y1="{py(y)}" x2="{px(x_max)}" y2="{py(y)}" stroke="#ddd"/>')
        e.append(f'<text x="{px(0) - 8}" y="{py(y) + 4}" text-anchor="end">{y}</text>')
    e.append(f'<line x1="{px(0)}" y1="{py(0)}" x2="{px(x_max)}" y2="{py(0)}" stroke="black"/>')
    e.append(f'<line x1="{px(0)}" y1="{py(0)}" x2="{px(0)}" y2="{py(y_max)}" stroke="black"/>')
    e.append(f'<text x="{(px(0) + px(x_max)) / 2}" y="{h - 15}" text-anchor="middle">robots</text>')
    e.append(f'<text x="18" y="{(py(0) + py(y_max)) / 2}" text-anchor="middle" '
             f'transform="rotate(-90 18 {(py(0) + py(y_max)) / 2})">tasks per minute '
             f'(mean ± s.e. over runs)</text>')
    for k, (label, colour, pts) in enumerate(series):
        shift = 0.4 * (k - 0.5)  # keep the two sets' bars apart
        path = " ".join(f"{px(r + shift):.1f},{py(m):.1f}" for r, m, _, _ in pts)
        if len(pts) > 1:
            e.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="2"/>')
        for r, m, s, n in pts:
            x = px(r + shift)
            e.append(f'<line x1="{x:.1f}" y1="{py(m - s):.1f}" x2="{x:.1f}" y2="{py(m + s):.1f}" '
                     f'stroke="{colour}" stroke-width="2"/>')
            e.append(f'<circle cx="{x:.1f}" cy="{py(m):.1f}" r="4" fill="{colour}"/>')
            # The first set's labels go left of its points, the second's right.
            dx, anchor = (-8, "end") if k == 0 else (8, "start")
            e.append(f'<text x="{x + dx:.1f}" y="{py(m) + 4:.1f}" fill="{colour}" '
                     f'text-anchor="{anchor}">{m:.2f} ({n} runs)</text>')
        ly = top + 10 + 18 * k
        e.append(f'<line x1="{px(1)}" y1="{ly}" x2="{px(4)}" y2="{ly}" stroke="{colour}" stroke-width="2"/>')
        e.append(f'<text x="{px(4) + 6}" y="{ly + 4}">{label}</text>')
    e.append("</svg>")
    return "\n".join(e) + "\n"


def main():
    series = points()
    for label, _, pts in series:
        for r, m, s, n in pts:
            print(f"{label}: {r} robots, {m:.2f} ± {s:.2f} tasks/min over {n} runs")
    with open(OUT, "w") as f:
        f.write(svg(series))
    print(f"wrote {os.path.relpath(OUT)}")


if __name__ == "__main__":
    main()
