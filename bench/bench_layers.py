#!/usr/bin/env python3
"""Benchmark: boundary-layer growth, plaf vs Gmsh, in one run.

An ellipse (semi-axes 1 and 0.3) given by N points is meshed with 40 layers, first height h0,
growth 1.2, order Q = 3, on a front of about N/3 elements, i.e. ~N nodes (10k by default):
  - plaf:  `plaf run` with `layers: {max: 40}` on the ellipse as a spline body and the wall
           power-law metric sized so the front has ~N linear nodes; the time is plaf's "mesh"
           stage (surface mesh + layers, every layer certified);
  - gmsh:  the same ellipse as a closed spline through the N points, a BoundaryLayer field
           (hwall_n = h0, ratio 1.2, 40 layers, quads), 2D meshing to a small box plus
           setOrder(3) — Gmsh fills the rest of the box too, so its time is an upper bound of
           its layer cost; the cell count reported is its quadrilaterals.
Prints cells, seconds, cells/s and the ratio plaf/gmsh of cells/s. Run by hand after building:
    /usr/bin/python3 bench/bench_layers.py [--build build] [--points 10000]
"""
import argparse
import math
import os
import re
import subprocess
import tempfile
import time

import gmsh


def ellipse(n):
    # Clockwise, starting at the right end (a body loop); no repeated closing point.
    return [(math.cos(-2 * math.pi * i / n), 0.3 * math.sin(-2 * math.pi * i / n)) for i in range(n)]


def run_plaf(plaf, work, pts, h0):
    dat = os.path.join(work, "ellipse.dat")
    with open(dat, "w") as f:
        f.write("ellipse\n")
        for x, y in pts + [pts[0]]:
            f.write(f"{x:.15e} {y:.15e}\n")
    # Tangential size 3 point spacings: about N/3 order-3 elements, N front nodes.
    perimeter = sum(math.dist(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts)))
    h_wall = 3 * perimeter / len(pts)
    cfg = os.path.join(work, "ellipse.yaml")
    with open(cfg, "w") as f:
        f.write(f"""name: ellipse
order: 3
geometry:
  type: airfoils
  bodies: [{{file: {dat}}}]
  corner_angle_deg: 170
metric: {{type: wall_power_law, h0: {h0}, growth: 1.2, h_max: 100, h_wall_max: {h_wall}, curvature_factor: 100, h_corner: {h_wall}}}
layers: {{max: 40, corner_angle_deg: 170}}
output: {{formats: [report]}}
""")
    r = subprocess.run([plaf, "run", cfg, "--out", work], capture_output=True, text=True)
    t = float(re.search(r"\[plaf\] mesh: .*\(([0-9.e+-]+) s\)", r.stderr).group(1))
    cells = int(re.search(r": (\d+) cells", r.stdout).group(1))
    return cells, t


def run_gmsh(pts, h0):
    gmsh.initialize()
    gmsh.option.setNumber("General.Verbosity", 1)
    geo = gmsh.model.geo
    tags = [geo.addPoint(x, y, 0, 0.05) for x, y in pts]
    spline = geo.addSpline(tags + [tags[0]])
    inner = geo.addCurveLoop([spline])
    box = [geo.addPoint(x, y, 0, 0.5) for x, y in [(-3, -3), (3, -3), (3, 3), (-3, 3)]]
    lines = [geo.addLine(box[i], box[(i + 1) % 4]) for i in range(4)]
    outer = geo.addCurveLoop(lines)
    geo.addPlaneSurface([outer, inner])
    geo.synchronize()
    f = gmsh.model.mesh.field.add("BoundaryLayer")
    gmsh.model.mesh.field.setNumbers(f, "CurvesList", [spline])
    gmsh.model.mesh.field.setNumber(f, "Size", h0)
    gmsh.model.mesh.field.setNumber(f, "Ratio", 1.2)
    gmsh.model.mesh.field.setNumber(f, "Thickness", h0 * (1.2 ** 40 - 1) / 0.2)
    gmsh.model.mesh.field.setNumber(f, "Quads", 1)
    gmsh.model.mesh.field.setAsBoundaryLayer(f)
    gmsh.model.mesh.setTransfiniteCurve(spline, len(pts) // 3 + 1)
    t0 = time.perf_counter()
    gmsh.model.mesh.generate(2)
    gmsh.model.mesh.setOrder(3)
    t = time.perf_counter() - t0
    types, tags_, _ = gmsh.model.mesh.getElements(2)
    quads = sum(len(tg) for ty, tg in zip(types, tags_) if gmsh.model.mesh.getElementProperties(ty)[0].startswith("Quad"))
    gmsh.finalize()
    return quads, t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--points", type=int, default=10000)
    ap.add_argument("--h0", type=float, default=1e-4)
    a = ap.parse_args()
    plaf = os.path.join(a.build, "apps", "plaf")
    work = tempfile.mkdtemp(prefix="plaf_bench_layers_")
    pts = ellipse(a.points)
    pc, pt = run_plaf(plaf, work, pts, a.h0)
    gc, gt = run_gmsh(pts, a.h0)
    print(f"{'':6} {'cells':>9} {'seconds':>9} {'cells/s':>10}")
    print(f"{'plaf':6} {pc:>9} {pt:9.3f} {pc / pt:10.0f}")
    print(f"{'gmsh':6} {gc:>9} {gt:9.3f} {gc / gt:10.0f}")
    print(f"plaf/gmsh cells/s ratio: {(pc / pt) / (gc / gt):.2f}")


if __name__ == "__main__":
    main()
