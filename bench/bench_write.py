#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Output formats: size and write time of one mesh in each of plaf's formats, and Gmsh's own
binary MSH of the same mesh beside them (run by hand; not a test).

The mesh: an order-2 hybrid of the published ellipsoid STL (data:surfaces/ellipsoid_binary.stl),
configured from its bounding box only as bench/sweep_3d.py does (h0 = 1e-5 of the largest extent,
growth 1.2, h_wall_max = extent / 60, curvature_factor 0.3, 40 layers) plus a TetGen fill to a
box 10x the body: about 1e6 cells. `--scale` coarsens h_wall_max for a quick look.

plaf is run once per format with output.formats = [FORMAT, report]; its report's timings_s.write
is the time of that one writer (the report's own write is a few ms). Then Gmsh 4.8 reads plaf's
ASCII MSH and writes it again as binary MSH 4.1 (`gmsh -bin`), timed by its own clock lines, as
the peer's rate for the same bytes. Output: a table of bytes and seconds per format and the
ratios binary/ASCII; docs/benchmarks.md keeps the numbers.

    PLAF_DATA=<data root> python3 bench/bench_write.py --plaf build/apps/plaf --out /tmp/bw
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time


def die(msg):
    sys.exit(f"bench_write: {msg}")


def config(name, formats, msh, vtu, scale):
    # Bounding box of ellipsoid_binary.stl: semi-axes 1.5, 1, 0.75 (extent 3).
    extent = 3.0
    return f"""name: {name}
order: 2
geometry:
  type: surface_file
  file: data:surfaces/ellipsoid_binary.stl
metric:
  type: wall_power_law
  h0: {1e-5 * extent}
  growth: 1.2
  h_wall_max: {extent / 60 * scale}
  h_max: {extent * 3}
surface:
  curvature_factor: 0.3
layers:
  max: 40
fill:
  type: tetgen
  farfield:
    shape: box
    size: [{extent * 10}, {extent * 10}, {extent * 10}]
output:
  formats: [{', '.join(formats)}]
  msh: {msh}
  vtu: {vtu}
"""


def run_plaf(plaf, out, name, formats, msh, vtu, scale):
    cfg = os.path.join(out, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config(name, formats, msh, vtu, scale))
    t = time.time()
    r = subprocess.run([plaf, "run", cfg, "--out", out, "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        die(f"plaf run {cfg} exited {r.returncode}: {r.stderr.strip()[:400]}")
    with open(os.path.join(out, name + ".report.json")) as f:
        rep = json.load(f)
    return rep, time.time() - t


def size_of(out, name, suffixes):
    return sum(os.path.getsize(os.path.join(out, name + s)) for s in suffixes if os.path.exists(os.path.join(out, name + s)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plaf", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--scale", type=float, default=1.0, help="h_wall_max factor (2: about 4x fewer cells)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    cases = [
        ("msh ASCII", ["msh"], "ascii", "ascii", [".msh"]),
        ("msh binary", ["msh"], "binary", "ascii", [".msh"]),
        ("msh22 ASCII", ["msh22"], "ascii", "ascii", ["_msh22.msh"]),
        ("msh22 binary", ["msh22"], "binary", "ascii", ["_msh22.msh"]),
        ("vtu ASCII", ["vtu"], "ascii", "ascii", [".vtu", "_boundary.vtu"]),
        ("vtu binary (zlib)", ["vtu"], "ascii", "binary", [".vtu", "_boundary.vtu"]),
        ("cgns (HDF5)", ["cgns"], "ascii", "ascii", [".cgns"]),
    ]
    rows = []
    cells = None
    for i, (label, formats, msh, vtu, suffixes) in enumerate(cases):
        name = f"bw{i}"
        rep, wall = run_plaf(a.plaf, a.out, name, formats + ["report"], msh, vtu, a.scale)
        cells = rep["cells"]["total"]
        rows.append((label, size_of(a.out, name, suffixes), rep["timings_s"]["write"]))
        print(f"{label:20s} {rows[-1][1] / 1e6:9.1f} MB {rows[-1][2]:8.2f} s  (run {wall:.0f} s, {cells} cells)", flush=True)
    # The peer: Gmsh rewrites plaf's ASCII MSH as binary (its own timer for the write).
    gmsh_row = None
    if shutil.which("gmsh"):
        src = os.path.join(a.out, "bw0.msh")
        dst = os.path.join(a.out, "gmsh_bin.msh")
        t = time.time()
        r = subprocess.run(["gmsh", src, "-0", "-bin", "-format", "msh41", "-o", dst], capture_output=True, text=True)
        total = time.time() - t
        if r.returncode == 0 and os.path.exists(dst):
            gmsh_row = ("Gmsh msh binary (read + write)", os.path.getsize(dst), total)
            print(f"{gmsh_row[0]:20s} {gmsh_row[1] / 1e6:9.1f} MB {total:8.2f} s (read of the ASCII file included)")
    print()
    print(f"| format | MB | write s | vs ASCII of its kind: size, time |  ({cells} cells, order 2)")
    print("| --- | --- | --- | --- |")
    base = {"msh": rows[0], "msh22": rows[2], "vtu": rows[4], "cgns": rows[0]}
    for label, size, sec in rows + ([gmsh_row] if gmsh_row else []):
        kind = label.split()[0]
        b = base.get(kind, rows[0])
        print(f"| {label} | {size / 1e6:.1f} | {sec:.2f} | {b[1] / size:.2f}x smaller, {b[2] / max(sec, 1e-9):.2f}x faster |")


if __name__ == "__main__":
    main()
