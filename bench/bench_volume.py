#!/usr/bin/env python3
"""Benchmark: plaf's whole 3D pipeline (surface, layers, TetGen fill) against Gmsh's on one sphere.

The complete hybrid mesh around the unit sphere of configs/sphere_hybrid.yaml, stage by stage,
in two runs of plaf (the fill's optimiser off and on) and one of Gmsh: a wall triangulation, N
layers of prisms (default 30, layer k of height h0 g^k, h0 = 1e-5, g = 1.25: 0.0323 in all) and
tetrahedra from the layers' top to a farfield sphere of radius 20.

  - plaf:  `plaf run` of a temporary config that is configs/sphere_hybrid.yaml with a finer wall:
           order 2, geometry sphere (unit, at the origin), metric wall_power_law {h0, growth,
           h_max: 5, h_wall_max: H} (H = 0.039, as bench_prisms, gives 19,770 triangles),
           layers {type: extrude, max: N, f_atten: 0.2}, fill {type: tetgen, farfield: sphere of
           radius 20}, output: report only; run twice, "TetGen" with fill.optimize_passes: 0
           (TetGen's mesh as is) and "+optimise" with plaf's default (no key; --optimize-passes
           sets it). Its report gives the cells (cells.by_type: prism_Q2 and tetrahedron_Q2)
           and every stage's time (timings_s): surface (remeshed, curved wall), layers (grown
           and certified), fill (farfield sphere + TetGen + the metric optimiser,
           volume/optimize_3d.h), mesh (the order-2 assembly of prisms and tets). The fill's
           tets as the optimiser left them (TetGen's, with 0 passes) are fill.optimize.after:
           tets, unit_fraction, min_dihedral_deg, below_10deg. The stages' sum with geometry and
           metric is the compared "total"; the quality stage (every cell certified again, with
           tight bounds, plus metric and conformity measures) is printed separately, with the
           process's wall time and peak RSS (wait4). plaf uses its worker threads (2 on this
           machine; PLAF_THREADS overrides).
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
           total = their sum. Then, untimed, the model's mesh (the tets and the surfaces'
           triangles and quads; the prisms went with the layers' volumes) is written to MSH 4.1
           and measured by `plaf check --metric <plaf's "+optimise" config>` for the unit
           fraction of its tetrahedra's edges (its report's metric.tetrahedra). plaf check
           takes only 2D configurations for --metric (apps/run.cpp: "--metric takes a 2D
           configuration"), so this gives no number at 789cb9b: the table prints "-" and the
           refusal, and a second check without --metric, which reads the file (all its tets,
           0 invalid).

cells/s = (prisms + tets) / total. Goals (the issue): plaf's layer stage costs no more than its
fill stage, and plaf's total cells/s >= Gmsh's. What is compared is not two equal algorithms:
plaf's layers are curved (order 2), attenuated and certified cell by cell as they grow, and its
tets are written at order 2 sharing the prisms' top nodes; Gmsh's are straight and unchecked.
Gmsh's prisms are not checked here (bench_prisms checks its extrusion with `plaf check`).

A second table (issue 32) compares the fills alone: the fill stage's time, its tets, their unit
fraction (the share of tet edges of metric length in [1/sqrt2, sqrt2], in plaf's metric), min
dihedral angle and tets under 10 degrees, for TetGen alone, TetGen + the optimiser and Gmsh's
volume stage (time, tets and the unit fraction from plaf check, when it gives one), with ratios
from the same run: fill time with optimiser / TetGen alone and / Gmsh's volume, tets and unit
fraction with optimiser / without.

Run by hand after building (Debian's gmsh and python3-gmsh):
    /usr/bin/python3 bench/bench_volume.py [--plaf build/apps/plaf] [--h-wall 0.039]
        [--layers 30] [--h0 1e-5] [--growth 1.25] [--radius 20] [--algo3d hxt|delaunay]
        [--gmsh-threads 1] [--optimize-passes N]

Measured on 2026-12-06 18:30, this machine (2 cores, 24 GiB, nothing else running), plaf
Release build of 05555d4 (collapses to 1.6, slivers repaired under 0.15), Gmsh 4.8.4, default
options (one run; long printed lines wrapped here):
                     wall tris   prisms    tets    cells surface s layers s  fill s  mesh s total s  cells/s
plaf Q2 (TetGen)         19770   593100   94414   687514     0.460    9.072   1.712   0.275  11.518    59689
plaf Q2 (+optimise)      19770   593100  843387  1436487     0.452    9.504  25.024   3.389  38.370    37438
gmsh Q1 (HXT)            19552   586560  105569   692129     0.464    0.899   0.282       -   1.645   420682
   plaf (TetGen)/gmsh cells/s: 0.14 (goal >= 1: not met); by stage: prisms/s 0.10, tets/s 0.15;
     layers/fill time 5.30 (goal <= 1: not met)
   plaf (+optimise)/gmsh cells/s: 0.09 (goal >= 1: not met); by stage: prisms/s 0.10, tets/s 0.09;
     layers/fill time 0.38 (goal <= 1: met)
   gmsh layers/volume time: 3.19
   plaf (TetGen): 30 layers, farfield 720 triangles (h 4.75), 0 invalid, min scaled Jacobian 0.729;
     quality stage 10.82 s, process 22.4 s, peak RSS 743 MiB
   plaf (+optimise): 30 layers, farfield 720 triangles (h 4.75), 0 invalid, min scaled Jacobian
     0.729; quality stage 15.24 s, process 53.7 s, peak RSS 1217 MiB
   gmsh: wall size 0.0397, farfield 626 triangles, 1 thread(s), peak RSS 225 MiB (this process)

fill                      time s     tets unit edges min dihedral tets < 10 deg
plaf TetGen alone          1.712    94414      0.344         4.68           435
plaf TetGen + optimiser   25.024   843387      0.964         5.30          1745
gmsh HXT volume            0.282   105569      0.317            -             -
   gmsh unit edges: 138018 tet edges
   plaf fill time: with optimiser / TetGen alone 14.62, with optimiser / gmsh volume 88.68,
     TetGen alone / gmsh volume 6.07
   tets: with optimiser / TetGen alone 8.93, / gmsh 7.99; unit edges: with optimiser / TetGen
     alone 2.80, / gmsh 3.04
   optimiser: 384789 splits, 260475 collapses, 172696 swaps, 457172 moves, 483 sliver repairs; min
     dihedral off the fronts 6.10 -> 5.30 deg, under 5 deg 4 -> 0, flat 0 -> 0
  The optimiser takes the fill's unit edges from 34 % (Gmsh's HXT: 32 %) to 96 % by making 8.9x
  the tets, at 15x TetGen's fill time, 89x Gmsh's volume stage. Its physical min dihedral goes
  4.68 -> 5.30 deg, with 1745 tets under 10 deg against 435: the metric is anisotropic at the
  layers' top (30 layers stop short of isotropy), and those tets are stretched along it.
  "layers/fill met" with it is the fill grown slower, not the layers faster. The layer stage
  (9.1 s here, 3.8 s on 2026-11-24) is issue 33's regression, untouched here.
  The run of 15:05 the same day (5328d80: collapses to sqrt 2, repairs under 0.05) gave 94.0 %
  unit edges with 1,013,646 tets in 22.9 s of fill.

Before the fill's optimiser (one plaf run, TetGen alone; the table of the time): measured on
2026-11-24, this machine (2 cores, 24 GiB; load 0.8-1.7 from other agents, so +-10 %), plaf
Release build of 1aa061b+ (binary built 11:25), Gmsh 4.8.4, default options (two runs, the
second printed):
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


def run_plaf(exe, work, a, passes):
    """plaf run of sphere_hybrid with h_wall_max a.h_wall and fill.optimize_passes passes (None:
    plaf's default); its config's path and its report's cells, stage times and fill."""
    name = "sphere_volume" + ("" if passes is None else f"_opt{passes}")
    cfg = os.path.join(work, name + ".yaml")
    opt = "" if passes is None else f", optimize_passes: {passes}"
    with open(cfg, "w") as f:
        f.write(f"""name: {name}
order: 2
geometry: {{type: sphere, center: [0, 0, 0], radius: 1}}
metric: {{type: wall_power_law, h0: {a.h0}, growth: {a.growth}, h_max: 5.0, h_wall_max: {a.h_wall}}}
layers: {{type: extrude, max: {a.layers}, f_atten: 0.2}}
fill: {{type: tetgen, farfield: {{shape: sphere, radius: {a.radius}}}{opt}}}
output: {{formats: [report]}}
""")
    rc, err, wall, rss = run_process([exe, "run", cfg, "--out", work], work)
    rep_path = os.path.join(work, name + ".report.json")
    if not os.path.exists(rep_path):
        last = (err.strip().splitlines() or ["no message"])[-1]
        fail(f"plaf run ({name}) failed (exit {rc}): {last}")
    rep = json.load(open(rep_path))
    t = rep["timings_s"]
    by_type = rep["cells"]["by_type"]
    prisms = sum(v for k, v in by_type.items() if k.startswith("prism"))
    tets = sum(v for k, v in by_type.items() if k.startswith("tetrahedron"))
    # The meshing pipeline: every stage before the quality stage (config reading excluded).
    stages = ["geometry", "metric", "surface", "layers", "fill", "mesh"]
    opt = rep["fill"]["optimize"]
    return {
        "config": cfg,
        "passes": passes,
        "rc": rc,
        "triangles": rep["surface"]["triangles"],
        "prisms": prisms,
        "tets": tets,
        "cells": rep["cells"]["total"],
        "tetgen_tets": rep["fill"]["tets"],
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
        # The fill's tets as the optimiser left them (TetGen's with 0 passes) and its counts.
        "fill": opt["after"],
        "ops": {k: opt[k] for k in ("splits", "collapses", "swaps", "moves", "repairs")},
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


def run_gmsh(a, target, farfield_h, msh):
    """Gmsh's sphere, boundary layer and tet fill; per stage times and cells (see the docstring).
    The mesh left after the volume stage (tets and surfaces, no prisms) is written to msh."""
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
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveAll", 1)
        gmsh.write(msh)
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


def check_gmsh(exe, work, msh, config):
    """`plaf check --metric config` of Gmsh's volume mesh: the unit fraction of its tetrahedra's
    edges (metric.tetrahedra), or None and why not. When the metric is refused, a check without
    it says whether plaf reads the mesh at all."""
    rep_path = os.path.join(work, "gmsh_check.json")
    rc, err, _, _ = run_process([exe, "check", msh, "--metric", config, "--report", rep_path], work)
    if os.path.exists(rep_path):
        m = json.load(open(rep_path)).get("metric", {})
        if "tetrahedra" in m:
            return m["tetrahedra"]["unit_fraction"], f"{m['tetrahedra']['edges']} tet edges"
        return None, "plaf check's report has no metric.tetrahedra"
    why = (err.strip().splitlines() or [f"exit {rc}"])[-1].replace("plaf: error: ", "")
    why = why.replace(work + os.sep, "")
    rc, err, _, _ = run_process([exe, "check", msh, "--report", rep_path], work)
    if os.path.exists(rep_path):
        c = json.load(open(rep_path))["cells"]
        read = f"read without --metric: {c['total']} cells, {c['invalid']} invalid"
    else:
        last = (err.strip().splitlines() or [f"exit {rc}"])[-1]
        read = "not read without --metric either: " + last
    return None, f"plaf check --metric: {why}; {read}"


def report(p0, p, g, a):
    """The tables and the goals."""
    hdr = (f"{'':20} {'wall tris':>9} {'prisms':>8} {'tets':>7} {'cells':>8} {'surface s':>9} "
           f"{'layers s':>8} {'fill s':>7} {'mesh s':>7} {'total s':>7} {'cells/s':>8}")
    print(hdr)
    rate_g = g["cells"] / g["total_s"]
    for q, name in ((p0, "plaf Q2 (TetGen)"), (p, "plaf Q2 (+optimise)")):
        rate = q["cells"] / q["total_s"]
        print(f"{name:20} {q['triangles']:>9} {q['prisms']:>8} {q['tets']:>7} "
              f"{q['cells']:>8} {q['surface_s']:9.3f} {q['layers_s']:8.3f} {q['fill_s']:7.3f} "
              f"{q['mesh_s']:7.3f} {q['total_s']:7.3f} {rate:8.0f}")
    name = f"gmsh Q1 ({g['algo']})"
    print(f"{name:20} {g['triangles']:>9} {g['prisms']:>8} {g['tets']:>7} {g['cells']:>8} "
          f"{g['surface_s']:9.3f} {g['layers_s']:8.3f} {g['fill_s']:7.3f} {'-':>7} "
          f"{g['total_s']:7.3f} {rate_g:8.0f}")
    for q, name in ((p0, "TetGen"), (p, "+optimise")):
        ratio = (q["cells"] / q["total_s"]) / rate_g
        lf = q["layers_s"] / q["fill_s"]
        print(f"   plaf ({name})/gmsh cells/s: {ratio:.2f} (goal >= 1: "
              f"{'met' if ratio >= 1 else 'not met'}); by stage: prisms/s "
              f"{(q['prisms'] / q['layers_s']) / (g['prisms'] / g['layers_s']):.2f}, tets/s "
              f"{(q['tets'] / q['fill_s']) / (g['tets'] / g['fill_s']):.2f}; layers/fill time "
              f"{lf:.2f} (goal <= 1: {'met' if lf <= 1 else 'not met'})")
    print(f"   gmsh layers/volume time: {g['layers_s'] / g['fill_s']:.2f}")
    for q, name in ((p0, "TetGen"), (p, "+optimise")):
        print(f"   plaf ({name}): {q['layers_built']} layers, farfield {q['farfield_tris']} "
              f"triangles (h {q['farfield_h']:.2f}), {q['invalid']} invalid, min scaled Jacobian "
              f"{q['min_sj']:.3g}; quality stage {q['quality_s']:.2f} s, process "
              f"{q['process_s']:.1f} s, peak RSS {q['rss_mib']:.0f} MiB")
    print(f"   gmsh: wall size {g['h']:.4f}, farfield {g['farfield_tris']} triangles, "
          f"{a.gmsh_threads} thread(s), peak RSS {g['rss_mib']:.0f} MiB (this process)")

    # The fill alone: time, tets and their edges in plaf's metric (unit: in [1/sqrt2, sqrt2]).
    print()
    print(f"{'fill':24} {'time s':>7} {'tets':>8} {'unit edges':>10} {'min dihedral':>12} "
          f"{'tets < 10 deg':>13}")
    opt = "optimiser" if p["passes"] is None else f"opt {p['passes']}"
    for q, name in ((p0, "plaf TetGen alone"), (p, f"plaf TetGen + {opt}")):
        f = q["fill"]
        print(f"{name:24} {q['fill_s']:7.3f} {f['tets']:>8} {f['unit_fraction']:10.3f} "
              f"{f['min_dihedral_deg']:12.2f} {f['below_10deg']:>13}")
    name = f"gmsh {g['algo']} volume"
    unit = "-" if g["unit"] is None else f"{g['unit']:.3f}"
    print(f"{name:24} {g['fill_s']:7.3f} {g['tets']:>8} {unit:>10} {'-':>12} {'-':>13}")
    print(f"   gmsh unit edges: {g['unit_note']}")
    print(f"   plaf fill time: with optimiser / TetGen alone {p['fill_s'] / p0['fill_s']:.2f}, "
          f"with optimiser / gmsh volume {p['fill_s'] / g['fill_s']:.2f}, TetGen alone / gmsh "
          f"volume {p0['fill_s'] / g['fill_s']:.2f}")
    line = (f"   tets: with optimiser / TetGen alone {p['fill']['tets'] / p0['fill']['tets']:.2f}, "
            f"/ gmsh {p['fill']['tets'] / g['tets']:.2f}; unit edges: with optimiser / TetGen "
            f"alone {p['fill']['unit_fraction'] / p0['fill']['unit_fraction']:.2f}")
    if g["unit"]:
        line += f", / gmsh {p['fill']['unit_fraction'] / g['unit']:.2f}"
    print(line)
    o = p["ops"]
    print(f"   optimiser: {o['splits']} splits, {o['collapses']} collapses, {o['swaps']} swaps, "
          f"{o['moves']} moves, {o['repairs']} sliver repairs; min dihedral off the fronts "
          f"{p0['fill']['min_dihedral_inner_deg']:.2f} -> {p['fill']['min_dihedral_inner_deg']:.2f} "
          f"deg, under 5 deg {p0['fill']['below_5deg']} -> {p['fill']['below_5deg']}, flat "
          f"{p0['fill']['flat']} -> {p['fill']['flat']}")


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
    ap.add_argument("--optimize-passes", type=int, default=None,
                    help="fill.optimize_passes of plaf's second run (default: plaf's default)")
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
        p0 = run_plaf(exe, work, a, 0)
        p = run_plaf(exe, work, a, a.optimize_passes)
        msh = os.path.join(work, "gmsh_volume.msh")
        g = run_gmsh(a, p["triangles"], p["farfield_h"], msh)
        g["unit"], g["unit_note"] = check_gmsh(exe, work, msh, p["config"])
        report(p0, p, g, a)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for q in (p0, p):
        if q["rc"] != 0:
            fail(f"plaf run exited {q['rc']} ({q['invalid']} invalid cells); the numbers above are "
                 "from its report")


if __name__ == "__main__":
    main()
