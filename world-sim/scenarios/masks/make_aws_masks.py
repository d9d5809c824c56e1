#!/usr/bin/env python3
"""Writes the sample Nav2 filter masks for the built-in aws-small-warehouse map, each a
map.yaml and a PGM (trinary: black is in a zone, white is not) covering the map's extent at
0.1 m per pixel, a coarser grid than the map's 0.05 m:

- aws-small-warehouse-keepout.{yaml,pgm}, a keep-out mask: one packing area on the open floor
  of the south half, between the west docks and the south-east aisles, x -1.5 to 1.5 m,
  y -5.0 to -3.0 m in the map's frame, which robots must not cross and people may;
- aws-small-warehouse-slow-docks.{yaml,pgm}, a speed mask: the strip along the west wall's
  dock bays, x -7.0 to -4.5 m over the map's height, where robots drive slowly (the limit is
  the scenario's).

    python3 world-sim/scenarios/masks/make_aws_masks.py
"""

from pathlib import Path

ORIGIN = (-7.0, -10.5)  # the map's (map.yaml)
RESOLUTION = 0.1
WIDTH, HEIGHT = 143, 212  # 14.3 x 21.2 m, the map's 14.3 x 21.15 m and a little more
MASKS = {
    "aws-small-warehouse-keepout": [((-1.5, -5.0), (1.5, -3.0))],  # (x0, y0), (x1, y1)
    "aws-small-warehouse-slow-docks": [((-7.0, -10.5), (-4.5, 10.7))],
}


def in_zone(zones, x, y):
    """Whether pixel column x, row y from the bottom has its centre in a zone."""
    cx = ORIGIN[0] + (x + 0.5) * RESOLUTION
    cy = ORIGIN[1] + (y + 0.5) * RESOLUTION
    return any(x0 <= cx <= x1 and y0 <= cy <= y1 for (x0, y0), (x1, y1) in zones)


def main():
    here = Path(__file__).resolve().parent
    for name, zones in MASKS.items():
        # A PGM's first row is the map's top (largest y).
        rows = [
            bytes(0 if in_zone(zones, x, y) else 255 for x in range(WIDTH))
            for y in reversed(range(HEIGHT))
        ]
        pgm = f"P5\n{WIDTH} {HEIGHT}\n255\n".encode() + b"".join(rows)
        (here / f"{name}.pgm").write_bytes(pgm)
        (here / f"{name}.yaml").write_text(
            f"image: {name}.pgm\n"
            "mode: trinary\n"
            f"resolution: {RESOLUTION}\n"
            f"origin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
            "negate: 0\n"
            "occupied_thresh: 0.65\n"
            "free_thresh: 0.196\n"
        )


if __name__ == "__main__":
    main()
