#!/usr/bin/env python3
"""Writes aws-small-warehouse-keepout.{pgm,yaml}: a Nav2 keep-out filter mask for the
built-in aws-small-warehouse map (nav2_map_server's filter_mask, trinary: black is a keep-out
zone, white is allowed). It covers the map's extent at 0.1 m per pixel, a coarser grid than
the map's 0.05 m, with one zone: a packing area on the open floor of the south half, between
the west docks and the south-east aisles, x -1.5 to 1.5 m, y -5.0 to -3.0 m in the map's
frame, which robots must not cross and people may.

    python3 world-sim/scenarios/masks/make_aws_keepout.py
"""

from pathlib import Path

ORIGIN = (-7.0, -10.5)  # the map's (map.yaml)
RESOLUTION = 0.1
WIDTH, HEIGHT = 143, 212  # 14.3 x 21.2 m, the map's 14.3 x 21.15 m and a little more
ZONES = [((-1.5, -5.0), (1.5, -3.0))]  # (x0, y0), (x1, y1)


def kept_out(x, y):
    """Whether pixel column x, row y from the bottom has its centre in a zone."""
    cx = ORIGIN[0] + (x + 0.5) * RESOLUTION
    cy = ORIGIN[1] + (y + 0.5) * RESOLUTION
    return any(x0 <= cx <= x1 and y0 <= cy <= y1 for (x0, y0), (x1, y1) in ZONES)


def main():
    here = Path(__file__).resolve().parent
    rows = []
    # A PGM's first row is the map's top (largest y).
    for y in reversed(range(HEIGHT)):
        rows.append(bytes(0 if kept_out(x, y) else 255 for x in range(WIDTH)))
    pgm = f"P5\n{WIDTH} {HEIGHT}\n255\n".encode() + b"".join(rows)
    (here / "aws-small-warehouse-keepout.pgm").write_bytes(pgm)
    (here / "aws-small-warehouse-keepout.yaml").write_text(
        "image: aws-small-warehouse-keepout.pgm\n"
        "mode: trinary\n"
        f"resolution: {RESOLUTION}\n"
        f"origin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.196\n"
    )


if __name__ == "__main__":
    main()
