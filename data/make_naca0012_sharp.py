#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes airfoils/naca0012_sharp.dat: the NACA 0012 with a closed (sharp) trailing edge.

Thickness from the NACA 4-digit formula with the closed-TE last coefficient (-0.1036):
    y = +-0.6 (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 - 0.1036 x^4),
so y(1) = 0 (written as exactly 0 at both ends). Cosine spacing with 100 intervals per surface,
theta = pi k / 100: the upper surface from the TE, x = (1 + cos(theta)) / 2 for k = 0..99, then
the lower surface to the TE, x = (1 - cos(theta)) / 2 for k = 1..100. The two forms are equal in
exact arithmetic; they are kept as written because they reproduce, to the last bit, the 200
points the project's meshes were made from before it generated this file. Selig order,
counter-clockwise: TE -> upper surface -> LE -> lower surface -> TE. The LE point x = 0 is left
out, so the two points nearest the LE are (x_1, +-y(x_1)) with x_1 = 2.467e-4. No header;
"%.15e %.15e" per line.

Usage: python3 data/make_naca0012_sharp.py [output]  (default: airfoils/naca0012_sharp.dat beside
this script). The repository ships this script, not its output: the reference shelf holds the
same bytes (docs/data.md), configs generate the section in-process (`naca: "0012"`), and
bench/bench_fill.py and bench/sweep_2d.py write the file where they need it.
"""
import math
import os
import sys

INTERVALS = 100


def half_thickness(x):
    t = 0.2969 * math.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4
    return max(0.6 * t, 0.0)  # y(1) is 0 up to rounding: never negative


def points():
    upper = [(1 + math.cos(math.pi * k / INTERVALS)) / 2 for k in range(0, INTERVALS)]
    lower = [(1 - math.cos(math.pi * k / INTERVALS)) / 2 for k in range(1, INTERVALS + 1)]
    return [(x, half_thickness(x)) for x in upper] + [(x, -half_thickness(x)) for x in lower]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "airfoils", "naca0012_sharp.dat")
    with open(out, "w", newline="\n") as f:
        for x, y in points():
            f.write("%.15e %.15e\n" % (x, y + 0.0))  # + 0.0 turns -0.0 into 0.0
    print(out)


if __name__ == "__main__":
    main()
