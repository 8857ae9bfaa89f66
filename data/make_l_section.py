#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes sections/l_section.dat: an L-shaped section (five convex corners, one concave corner)
for the concave-ridge case of the 3D prism layers (configs/l_wing_layers.yaml): extruded by the
wing builder between two symmetry planes, its concave corner becomes a concave ridge along the span.

The L is the unit square minus the square [0.3, 1] x [0.3, 1], scaled to x in [0, 1]: corners
(0, 0), (1, 0), (1, 0.3), (0.3, 0.3) (concave), (0.3, 1), (0, 1). Ten points per unit length on
every side, counter-clockwise from (1, 0.15) (the middle of the right side, a smooth point), one
"%.15e %.15e" pair per line, no header (as the Selig files). Generated, no source: MIT like the code.

Usage: python3 data/make_l_section.py [output]  (default: sections/l_section.dat beside this script).
"""
import os
import sys

CORNERS = [(1.0, 0.3), (0.3, 0.3), (0.3, 1.0), (0.0, 1.0), (0.0, 0.0), (1.0, 0.0)]
PER_UNIT = 10


def points():
    start = (1.0, 0.15)
    path = [start] + CORNERS + [start]
    out = []
    for (x0, y0), (x1, y1) in zip(path, path[1:]):
        n = max(1, round(PER_UNIT * (abs(x1 - x0) + abs(y1 - y0))))
        for k in range(n):
            t = k / n
            out.append((x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "sections", "l_section.dat")
    with open(path, "w") as f:
        for x, y in points():
            f.write("%.15e %.15e\n" % (x, y))


if __name__ == "__main__":
    main()
