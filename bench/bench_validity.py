#!/usr/bin/env python3
"""Benchmark: certified Jacobian bounds of curved meshes, plaf vs Gmsh, in one run.

Both tools compute Bezier bounds of det J (Gmsh's Plugin(AnalyseMeshQuality) is Johnen,
Remacle and Geuzaine's own implementation). For annulus meshes of growing size and orders
Q = 2..4, this script writes the mesh with `plaf run`, then times
  - plaf:  `plaf check MESH.msh`, its "quality" stage (certification of every cell), and
  - gmsh:  the AnalyseMeshQuality plugin with JacobianDeterminant on the same file,
and prints cells, seconds, cells/s, the worst scaled Jacobian each reports and the time ratio.
Run by hand after building (needs Debian's gmsh and python3-gmsh):
    /usr/bin/python3 bench/bench_validity.py [--build build] [--sizes 0.05,0.02,0.01]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import gmsh


def plaf_check(plaf, msh):
    r = subprocess.run([plaf, "check", msh], capture_output=True, text=True)
    t = float(re.search(r"\[plaf\] quality: .*\(([0-9.e+-]+) s\)", r.stderr).group(1))
    sj = float(re.search(r"min scaled Jacobian: ([0-9.e+-]+)", r.stdout).group(1))
    inv = int(re.search(r"invalid cells: (\d+)", r.stdout).group(1))
    return t, sj, inv


def gmsh_check(msh):
    gmsh.initialize()
    gmsh.option.setNumber("General.Verbosity", 2)
    gmsh.open(msh)
    for k, v in {"JacobianDeterminant": 1, "IGEMeasure": 0, "ICNMeasure": 0, "CreateView": 1,
                 "DimensionOfElements": 2}.items():
        gmsh.plugin.setNumber("AnalyseMeshQuality", k, v)
    t0 = time.perf_counter()
    gmsh.plugin.run("AnalyseMeshQuality")
    t = time.perf_counter() - t0
    # The view holds min J/max J per element (second component of the 'minJ/maxJ' data).
    tags = gmsh.view.getTags()
    worst = None
    for tag in tags:
        name = gmsh.option.getString(f"View[{gmsh.view.getIndex(tag)}].Name")
        if "minJ/maxJ" in name or "scaled" in name.lower():
            _, _, data, _, _ = gmsh.view.getModelData(tag, 0)
            worst = min(d[0] for d in data)
    gmsh.finalize()
    return t, worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--sizes", default="0.05,0.02,0.01")
    ap.add_argument("--orders", default="2,3,4")
    a = ap.parse_args()
    plaf = os.path.join(a.build, "apps", "plaf")
    work = tempfile.mkdtemp(prefix="plaf_bench_")
    print(f"{'Q':>2} {'cells':>9} | {'plaf s':>8} {'cells/s':>10} {'min sJ':>7} | "
          f"{'gmsh s':>8} {'cells/s':>10} {'min sJ':>7} | {'plaf/gmsh':>9}")
    for q in map(int, a.orders.split(",")):
        for h in map(float, a.sizes.split(",")):
            name = f"annulus_q{q}_h{h}"
            cfg = os.path.join(work, name + ".yaml")
            with open(cfg, "w") as f:
                f.write(f"name: {name}\norder: {q}\ngeometry: {{type: annulus}}\n"
                        f"metric: {{type: uniform, h: {h}}}\noutput: {{formats: [msh]}}\n")
            subprocess.run([plaf, "run", cfg, "--out", work], check=True, capture_output=True)
            msh = os.path.join(work, name + ".msh")
            tp, sjp, inv = plaf_check(plaf, msh)
            tg, sjg = gmsh_check(msh)
            out = subprocess.run([plaf, "check", msh], capture_output=True, text=True).stdout
            cells = int(re.search(r": (\d+) cells", out).group(1))
            sjg_s = f"{sjg:7.4f}" if sjg is not None else "    n/a"
            print(f"{q:>2} {cells:>9} | {tp:8.3f} {cells / tp:10.0f} {sjp:7.4f} | "
                  f"{tg:8.3f} {cells / tg:10.0f} {sjg_s} | {tp / tg:9.2f}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
