"""The tables of results/way-out/REPORT.md, from the runs.csv files beside this script and
results/people-turn's (the committed default before the change).

    python3 results/way-out/tables.py
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "people-turn"))
from tables import HEAD, STUCK_HEAD, mean, row, runs, stuck  # noqa: E402

HEAD = HEAD.replace("against off, paired", "against the build before, paired")


def here(folder, robots=None, scenario="warehouse-narrow"):
    return runs(os.path.join("..", "way-out", folder), robots, scenario)


def table(title, cells, base_name="the build before"):
    print(f"### {title}\n")
    print(HEAD.replace("the build before", base_name))
    for name, base, rows in cells:
        print(row(f"{name}, {base_name}", base))
        for label, r in rows:
            print(row(f"{name}, {label}", r, base))
    print()


def main():
    before = {n: runs(f"seeds-1-30/narrow-{n}-t10") for n in (20, 40)}
    table("tuning seeds 1–30: the choice", [
        (f"`warehouse-narrow`, {n} robots", before[n], [
            ("way out round, no exception", here(f"development/round-no-exception-narrow-{n}")),
            ("way out round, exception kept (8263ecd)", here(f"development/round-narrow-{n}")),
        ])
        for n in (20, 40)
    ])
    way_out = {n: here(f"development/round-narrow-{n}") for n in (20, 40)}
    table("tuning seeds 1–30: a robot alone in its segment leaves by either end", [
        ("`warehouse-narrow`, 20 robots", way_out[20], [
            ("either end", here("development/alone-either-end-narrow-20")),
            ("either end while nobody is near (committed)",
             here("development/alone-either-end-nobody-near-narrow-20")),
        ]),
        ("`warehouse-narrow`, 40 robots", way_out[40], [
            ("either end", here("development/alone-either-end-narrow-40")),
            ("either end while nobody is near (committed)",
             here("development/alone-either-end-nobody-near-narrow-40")),
        ]),
    ], "way out round")
    table("probe, tuning seeds 1–30: a robot turned round from people at most once a visit", [
        ("`warehouse-narrow`, 20 robots", here("development/round-narrow-20"), [
            ("at most once a visit", here("development/turn-once-narrow-20")),
        ]),
    ], "committed")
    empty = "warehouse-narrow-empty"
    far = here("development/no-people-far-end", 20, empty)
    table("probe, tuning seeds 1–30, no people: a robot alone in its segment leaves by either end", [
        ("`warehouse-narrow` without people, 20 robots", far, [
            ("either end", here("development/no-people-either-end", 20, empty)),
        ]),
    ], "by the far end (committed)")
    alone = os.path.join(HERE, "seeds-101-130-alone-exit", "narrow-40", "runs.csv")
    if os.path.exists(alone):
        table("held-out seeds 101–130: a robot alone in its segment with nobody near leaves by either end", [
            (f"`warehouse-narrow`, {n} robots", here(f"seeds-101-130/narrow-{n}"),
             [("alone, either end (committed)", here(f"seeds-101-130-alone-exit/narrow-{n}"))])
            for n in (20, 40)
        ], "way out round")
        print("### one robot alone, no people (the free flow efficiency divides by): tasks in 300 s, mean over seeds\n")
        print("| seeds | way out round | alone, either end |\n|---|---:|---:|")
        for name, a, b in [
            ("1–30", way_out[20], here("development/alone-either-end-nobody-near-narrow-20")),
            ("101–130", here("seeds-101-130/narrow-20"), here("seeds-101-130-alone-exit/narrow-20")),
        ]:
            print(f"| {name} | {mean(a, 'free_flow_tasks'):.2f} | {mean(b, 'free_flow_tasks'):.2f} |")
        print()
    if os.path.exists(os.path.join(HERE, "seeds-101-130-no-people", "either-end", "runs.csv")):
        table("held-out seeds 101–130, no people: a robot alone in its segment leaves by either end", [
            ("`warehouse-narrow` without people, 20 robots",
             here("seeds-101-130-no-people/far-end", 20, empty), [
                 ("either end (committed)", here("seeds-101-130-no-people/either-end", 20, empty)),
             ]),
        ], "by the far end (`alone_exit_clear_m=0`)")
    held = os.path.join(HERE, "seeds-101-130", "narrow-40", "runs.csv")
    if os.path.exists(held):
        table("held-out seeds 101–130", [
            (f"`warehouse-narrow`, {n} robots", runs("people-turn/seeds-101-130", n),
             [("way out round (8263ecd)", here(f"seeds-101-130/narrow-{n}"))])
            for n in (20, 40)
        ])
        print("### where the stuck robot-seconds went, held out (means per run)\n")
        print(STUCK_HEAD)
        for n in (20, 40):
            print(stuck(f"{n} robots, the build before", runs("people-turn/seeds-101-130", n)))
            print(stuck(f"{n} robots, way out round", here(f"seeds-101-130/narrow-{n}")))
        print()


if __name__ == "__main__":
    main()
