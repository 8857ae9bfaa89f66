#!/usr/bin/env python3
"""Benchmark: plaf's whole 3D pipeline (surface, layers, TetGen fill) against Gmsh's on one sphere.

The complete hybrid mesh around the unit sphere of configs/sphere_hybrid.yaml, stage by stage,
in one run of each tool: a wall triangulation, N layers of prisms (default 30, layer k of height
h0 g^k, h0 = 1e-5, g = 1.25: 0.0323 in all) and tetrahedra from the layers' top to a farfield
sphere of radius 20.

  - plaf:  `plaf run` of a temporary config that is configs/sphere_hybrid.yaml with a finer wall:
           order 2, geometry sphere (unit, at the origin), metric wall_power_law {h0, growth,
           h_max: 5, h_wall_max: H} (H = 0.039, as bench_prisms, gives 19,770 triangles),
           layers {type: extrude, max: N, f_atten: 0.2}, fill {type: tetgen, farfield: sphere of
           radius 20}, output: report only. Its report gives the cells (cells.by_type: prism_Q2
           and tetrahedron_Q2) and every stage's time (timings_s): surface (remeshed, curved
           wall), layers (grown and certified), fill (farfield sphere + TetGen), mesh (the
           order-2 assembly of prisms and tets). Their sum with geometry and metric is the
           compared "total"; the quality stage (every cell certified again, with tight bounds,
           plus metric and conformity measures) is printed separately, with the process's wall
           time and peak RSS (wait4). plaf uses its worker threads (2 on this machine;
           PLAF_THREADS overrides).
  - Gmsh (python3-gmsh 4.8.4, in this process, --gmsh-threads, default 1, order 1): the same
           sphere in the built-in kernel (8 octant patches, addSurfaceFilling with the sphere's
           centre), mesh size h at its points, h corrected (N ~ 1/h^2, up to 4 untimed
           meshings of the sphere alone) until its triangle count is within 2 % of plaf's;
           geo.extrudeBoundaryLayer(the 8 patches, [1] * N, cumulative heights, recombine) as
           in bench_prisms (one straight prism per triangle and layer, along the mesh normals);
           the farfield sphere (radius 20, the same 8 patches, size plaf's fill.farfield.h) and
           one volume between it and the layers' top surfaces, meshed by Mesh.Algorithm3D = 10
           (HXT, in this Gmsh build; --algo3d delaunay: 1, Gmsh's Delaunay), tet sizes
           interpolated from the boundary. Three timed stages in the same model:
             surface  generate(2): the wall, the layers' top (a copy of the wall's triangles),
                      the layers' lateral quads between patches, the farfield sphere;
             layers   generate(3) with Mesh.MeshOnlyVisible and the tet volume hidden: the
                      extrusion alone (Gmsh re-extrudes on every generate(3), visible or not);
             volume   the layers' volumes removed from the model (their prisms counted first;
                      their surfaces and the top's triangles stay), then generate(3): the tets
                      alone, from the same front.
           total = their sum.

cells/s = (prisms + tets) / total. Goals (the issue): plaf's layer stage costs no more than its
fill stage, and plaf's total cells/s >= Gmsh's. What is compared is not two equal algorithms:
plaf's layers are curved (order 2), attenuated and certified cell by cell as they grow, and its
tets are written at order 2 sharing the prisms' top nodes; Gmsh's are straight and unchecked.
Gmsh's mesh is not checked here (bench_prisms checks its extrusion with `plaf check`).

Run by hand after building (Debian's gmsh and python3-gmsh):
    /usr/bin/python3 bench/bench_volume.py [--plaf build/apps/plaf] [--h-wall 0.039]
        [--layers 30] [--h0 1e-5] [--growth 1.25] [--radius 20] [--algo3d hxt|delaunay]
        [--gmsh-threads 1]

Measured on 2026-11-24, this machine (2 cores, 24 GiB; load 0.8-1.7 from other agents, so
+-10 %), plaf Release build of 1aa061b+ (binary built 11:25), Gmsh 4.8.4, default options
(two runs, the second printed):
                   wall tris   prisms    tets    cells surface s layers s  fill s  mesh s total s  cells/s
plaf Q2 (TetGen)       19770   593100   94414   687514     0.471    3.773   1.397   0.167   5.807   118386
gmsh Q1 (HXT)          19552   586560  105257   691817     0.503    0.967   0.285       -   1.756   394024
   plaf/gmsh cells/s: 0.30 (goal >= 1: not met); by stage: prisms/s 0.26, tets/s 0.18
   plaf layers/fill time: 2.70 (goal <= 1: not met); gmsh layers/volume time: 3.39
   plaf: 30 layers, farfield 720 triangles (h 4.75), 0 invalid, min scaled Jacobian 0.729;
     quality stage 9.54 s, process 15.4 s, peak RSS 511 MiB
   gmsh: wall size 0.0397, farfield 626 triangles, 1 thread(s), peak RSS 328 MiB (this process)
  The first run: plaf total 6.01 s (114,409 cells/s, layers/fill 2.60), Gmsh 1.81 s (382,556
  cells/s): 0.30. The whole script 18 s. With --algo3d delaunay Gmsh's volume stage is 2.13 s for
  55,444 tets (Gmsh total 3.63 s, 176,723 cells/s): plaf/Gmsh 0.64, tets/s 2.29 (TetGen 5.6x
  slower per tet than HXT, 2.3x faster than Gmsh's Delaunay). --gmsh-threads 2 changes little
  (HXT 0.24 s, plaf/Gmsh 0.31). Neither goal is met: plaf's layers cost 2.6-2.7x its fill, and
  its total rate is 0.30 of Gmsh's (the layer stage alone, 3.8 s, is 2.1x Gmsh's whole 1.76 s).
"""
import argparse
import json
import math
import os
import resource
import shutil
import sys
import tempfile
import time

from sphere_common import gmsh_sphere, heights, run_process

# Gmsh's first size guess: 0.039 at the sphere's points gave 20,528 wall triangles.
GMSH_H_REF, GMSH_N_REF = 0.039, 20528
ALGO3D = {"hxt": (10, "HXT"), "delaunay": (1, "Delaunay")}


def fail(msg):
    """One line on stderr, exit 1."""
    sys.exit(f"bench_volume: {msg}")


def run_plaf(exe, work, a):
    """plaf run of sphere_hybrid with h_wall_max a.h_wall; its report's cells and stage times."""
    name = "sphere_volume"
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(f"""name: {name}
order: 2
geometry: {{type: sphere, center: [0, 0, 0], radius: 1}}
metric: {{type: wall_power_law, h0: {a.h0}, growth: {a.growth}, h_max: 5.0, h_wall_max: {a.h_wall}}}
layers: {{type: extrude, max: {a.layers}, f_atten: 0.2}}
fill: {{type: tetgen, farfield: {{shape: sphere, radius: {a.radius}}}}}
output: {{formats: [report]}}
""")
    rc, err, wall, rss = run_process([exe, "run", cfg, "--out", work], work)
    rep_path = os.path.join(work, name + ".report.json")
    if not os.path.exists(rep_path):
        last = (err.strip().splitlines() or ["no message"])[-1]
        fail(f"plaf run failed (exit {rc}): {last}")
    rep = json.load(open(rep_path))
    t = rep["timings_s"]
    by_type = rep["cells"]["by_type"]
    prisms = sum(v for k, v in by_type.items() if k.startswith("prism"))
    tets = sum(v for k, v in by_type.items() if k.startswith("tetrahedron"))
    # The meshing pipeline: every stage before the quality stage (config reading excluded).
    stages = ["geometry", "metric", "surface", "layers", "fill", "mesh"]
    return {
        "rc": rc,
        "triangles": rep["surface"]["triangles"],
        "prisms": prisms,
        "tets": tets,
        "cells": rep["cells"]["total"],
        "fill_tets": rep["fill"]["tets"],
        "farfield_h": rep["fill"]["farfield"]["h"],
        "farfield_tris": rep["fill"]["farfield"]["triangles"],
        "layers_built": rep["layers"]["count"],
        "surface_s": t["surface"],
        "layers_s": t["layers"],
        "fill_s": t["fill"],
        "mesh_s": t["mesh"],
        "total_s": sum(t.get(k, 0.0) for k in stages),
        "quality_s": t["quality"],
        "process_s": wall,
        "rss_mib": rss,
        "invalid": rep["cells"]["invalid"],
        "min_sj": rep["scaled_jacobian"]["min"],
    }


def gmsh_reset(gmsh, algo, threads):
    gmsh.clear()
    gmsh.option.setNumber("General.Verbosity", 0)  # errors come back in the exception
    gmsh.option.setNumber("General.NumThreads", threads)
    gmsh.option.setNumber("Geometry.ExtrudeReturnLateralEntities", 0)
    gmsh.option.setNumber("Mesh.Algorithm3D", algo)
    gmsh.option.setNumber("Mesh.MeshOnlyVisible", 0)


def count(gmsh, etype, tag=-1):
    """Elements of Gmsh type etype (2 triangle, 4 tet, 6 prism) on the entity tag, or everywhere."""
    return len(gmsh.model.mesh.getElementsByType(etype, tag)[0])


def run_gmsh(a, target, farfield_h):
    """Gmsh's sphere, boundary layer and tet fill; per stage times and cells (see the docstring)."""
    import gmsh
    algo, algo_name = ALGO3D[a.algo3d]
    gmsh.initialize(["", "-v", "0"])
    try:
        # The wall's size h corrected (N ~ 1/h^2) on the sphere alone, untimed, until its
        # triangle count is within 2 % of plaf's.
        h = GMSH_H_REF * math.sqrt(GMSH_N_REF / target)
        for attempt in range(4):
            gmsh_reset(gmsh, algo, a.gmsh_threads)
            gmsh_sphere(gmsh, h)
            gmsh.model.geo.synchronize()
            gmsh.model.mesh.generate(2)
            n = count(gmsh, 2)
            if abs(n - target) <= 0.02 * target or attempt == 3:
                break
            h *= math.sqrt(n / target)

        # The model: wall, boundary layer, farfield, the volume between the layers' top and it.
        gmsh_reset(gmsh, algo, a.gmsh_threads)
        geo = gmsh.model.geo
        wall = gmsh_sphere(gmsh, h)
        out = geo.extrudeBoundaryLayer([(2, s) for s in wall], [1] * a.layers,
                                       heights(a.h0, a.growth, a.layers), True)
        tops = [t for d, t in out if d == 2]
        layer_vols = [t for d, t in out if d == 3]
        far = gmsh_sphere(gmsh, farfield_h, a.radius)
        vol = geo.addVolume([geo.addSurfaceLoop(far), geo.addSurfaceLoop(tops)])
        geo.synchronize()

        t0 = time.perf_counter()
        gmsh.model.mesh.generate(2)
        t1 = time.perf_counter()
        wall_tris = sum(count(gmsh, 2, s) for s in wall)
        far_tris = sum(count(gmsh, 2, s) for s in far)

        gmsh.option.setNumber("Mesh.MeshOnlyVisible", 1)
        gmsh.model.setVisibility([(3, vol)], 0)
        t2 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t3 = time.perf_counter()
        prisms = count(gmsh, 6)

        gmsh.model.removeEntities([(3, v) for v in layer_vols])
        gmsh.model.setVisibility([(3, vol)], 1)
        gmsh.option.setNumber("Mesh.MeshOnlyVisible", 0)
        t4 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t5 = time.perf_counter()
        tets = count(gmsh, 4)
    except Exception as e:  # gmsh raises Exception with its last error message
        lines = str(e).strip().splitlines() or [type(e).__name__]
        fail(f"Gmsh failed: {lines[-1]}")
    finally:
        gmsh.finalize()
    if prisms == 0 or tets == 0:
        fail(f"Gmsh gave {prisms} prisms and {tets} tetrahedra")
    return {"h": h, "algo": algo_name, "triangles": wall_tris, "farfield_tris": far_tris,
            "prisms": prisms, "tets": tets, "cells": prisms + tets, "surface_s": t1 - t0,
            "layers_s": t3 - t2, "fill_s": t5 - t4, "total_s": (t1 - t0) + (t3 - t2) + (t5 - t4),
            # This process's peak so far: Gmsh's (plaf ran as a child, counted apart).
            "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}


def report(p, g, a):
    """The table and the goals."""
    hdr = (f"{'':18} {'wall tris':>9} {'prisms':>8} {'tets':>7} {'cells':>8} {'surface s':>9} "
           f"{'layers s':>8} {'fill s':>7} {'mesh s':>7} {'total s':>7} {'cells/s':>8}")
    print(hdr)
    rate_p = p["cells"] / p["total_s"]
    rate_g = g["cells"] / g["total_s"]
    print(f"{'plaf Q2 (TetGen)':18} {p['triangles']:>9} {p['prisms']:>8} {p['tets']:>7} "
          f"{p['cells']:>8} {p['surface_s']:9.3f} {p['layers_s']:8.3f} {p['fill_s']:7.3f} "
          f"{p['mesh_s']:7.3f} {p['total_s']:7.3f} {rate_p:8.0f}")
    name = f"gmsh Q1 ({g['algo']})"
    print(f"{name:18} {g['triangles']:>9} {g['prisms']:>8} {g['tets']:>7} {g['cells']:>8} "
          f"{g['surface_s']:9.3f} {g['layers_s']:8.3f} {g['fill_s']:7.3f} {'-':>7} "
          f"{g['total_s']:7.3f} {rate_g:8.0f}")
    ratio = rate_p / rate_g
    print(f"   plaf/gmsh cells/s: {ratio:.2f} (goal >= 1: {'met' if ratio >= 1 else 'not met'}); "
          f"by stage: prisms/s {(p['prisms'] / p['layers_s']) / (g['prisms'] / g['layers_s']):.2f}, "
          f"tets/s {(p['tets'] / p['fill_s']) / (g['tets'] / g['fill_s']):.2f}")
    lf = p["layers_s"] / p["fill_s"]
    print(f"   plaf layers/fill time: {lf:.2f} (goal <= 1: {'met' if lf <= 1 else 'not met'}); "
          f"gmsh layers/volume time: {g['layers_s'] / g['fill_s']:.2f}")
    print(f"   plaf: {p['layers_built']} layers, farfield {p['farfield_tris']} triangles (h "
          f"{p['farfield_h']:.2f}), {p['invalid']} invalid, min scaled Jacobian {p['min_sj']:.3f}; "
          f"quality stage {p['quality_s']:.2f} s, process {p['process_s']:.1f} s, "
          f"peak RSS {p['rss_mib']:.0f} MiB")
    print(f"   gmsh: wall size {g['h']:.4f}, farfield {g['farfield_tris']} triangles, "
          f"{a.gmsh_threads} thread(s), peak RSS {g['rss_mib']:.0f} MiB (this process)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plaf", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                   "..", "build", "apps", "plaf"),
                    help="the plaf binary (default: build/apps/plaf of this checkout)")
    ap.add_argument("--h-wall", type=float, default=0.039,
                    help="plaf's metric.h_wall_max (0.039: ~20k wall triangles)")
    ap.add_argument("--layers", type=int, default=30, help="number of layers")
    ap.add_argument("--h0", type=float, default=1e-5, help="first layer height")
    ap.add_argument("--growth", type=float, default=1.25, help="layer growth factor")
    ap.add_argument("--radius", type=float, default=20.0, help="farfield sphere's radius")
    ap.add_argument("--algo3d", choices=sorted(ALGO3D), default="hxt",
                    help="Gmsh's 3D algorithm (hxt: 10, delaunay: 1)")
    ap.add_argument("--gmsh-threads", type=int, default=1, help="Gmsh's General.NumThreads")
    a = ap.parse_args()
    exe = os.path.abspath(a.plaf)
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        fail(f"no plaf binary at {exe}; build it first or pass --plaf PATH")
    try:
        import gmsh  # noqa: F401
    except ImportError:
        fail("the Gmsh Python API is missing (apt-get install python3-gmsh; run with /usr/bin/python3)")
    work = tempfile.mkdtemp(prefix="plaf_bench_volume_")
    try:
        print(f"unit sphere, {a.layers} layers h0 g^k (h0 = {a.h0}, g = {a.growth}), farfield sphere "
              f"R = {a.radius}; plaf h_wall_max {a.h_wall}")
        p = run_plaf(exe, work, a)
        g = run_gmsh(a, p["triangles"], p["farfield_h"])
        report(p, g, a)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if p["rc"] != 0:
        fail(f"plaf run exited {p['rc']} ({p['invalid']} invalid cells); the numbers above are "
             "from its report")


if __name__ == "__main__":
    main()
