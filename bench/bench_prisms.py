#!/usr/bin/env python3
"""Benchmark: plaf's certified order-2 prism layers against Gmsh's 3D boundary-layer extrusion.

Issue 14. The same unit sphere, the same 30 layers of a wall power law (layer k of height
h0 g^k, k = 0..29, default h0 = 1e-5, g = 1.25: a total thickness of 0.0323), in one run:

A. (default) about 20k surface triangles:
  - plaf:  `plaf run` of a temporary config: order 2, geometry sphere (unit, at the origin),
           metric wall_power_law {h0, growth, h_max: 10, h_wall_max: H} (H = 0.039 gives 19,770
           triangles: the report's surface.triangles; the count jumps, 0.040-0.042 give 11,520
           and 0.038 gives 24,130),
           layers {type: extrude, max: 30}, output: report only. Its report gives the prisms
           (cells.by_type) and the stages' times: `layers` (the 30 layers grown, each
           certified, curvature attenuated) is the one compared; `quality` (every cell
           certified again, with tight bounds, plus metric and conformity measures) is
           printed separately.
  - Gmsh (python3-gmsh, in this process, 1 thread, order 1): the same sphere in the built-in
           kernel (8 octant patches, addSurfaceFilling with the sphere's centre), size
           Mesh.MeshSizeMin = MeshSizeMax corrected (N ~ 1/h^2, up to 4 surface meshings) until
           the sphere alone has plaf's triangle count within 2 %, then
           geo.extrudeBoundaryLayer(the 8 patches, [1] * 30, cumulative heights
           sum_{j<=k} h0 g^j, recombine): one prism per triangle and layer along the mesh
           normals. generate(2) meshes the sphere and also copies the triangles to the top
           surface (plus the lateral quads between patches); generate(3) builds the prisms.
           The compared time is generate(3) alone (the extrusion proper); the table also
           shows "3D + top", adding the 2D stage's extra time over a sphere meshed alone with
           the same settings (the top surface's share of the extrusion).
  Both meshes are then certified the same way: plaf's own report, and Gmsh's mesh written to
  MSH 4.1 and measured by `plaf check` (invalid cells, min scaled Jacobian); --no-check skips
  the Gmsh check.

B. (--large, or --only-large; not run by default) h_wall_max 0.0133 (--h-wall-large): 184,320
   triangles x 30 layers (5.5M order-2 prisms), plaf only: the layer stage, the quality stage,
   the process's wall time and its peak memory (maximum resident set size, from wait4).

What is compared: plaf's layer stage computes the node normals, grows 30 curved (order-2)
layers with curvature attenuation and certifies every prism's Jacobian as it goes (shrinking
heights where one fails); Gmsh's extrusion copies the wall triangles along averaged mesh normals
to the given heights, straight-sided, and checks nothing. The ratio is therefore the price of
curved, certified layers against plain straight extrusion, not two equal algorithms.

Prints one table per case and the ratio plaf / Gmsh of prisms/s for the same run.

Run by hand after building (Debian's gmsh and python3-gmsh):
    /usr/bin/python3 bench/bench_prisms.py [--plaf build/apps/plaf] [--h-wall 0.039]
        [--h0 1e-5] [--growth 1.25] [--no-check] [--large | --only-large] [--h-wall-large 0.0133]

Measured on 2026-11-24, this machine (2 cores, 24 GiB; other agents' builds and tests running
beside it, load 2-11, so +-20 %), plaf Release build of f4776fc, Gmsh 4.8.4, default options:
  A (two runs): plaf 19,770 wall triangles, 593,100 Q2 prisms in 5.61-5.85 s of layer stage
     (101-106k prisms/s), 0 invalid, min scaled Jacobian 0.729; Gmsh 19,552 triangles,
     586,560 Q1 prisms in 0.99-1.04 s of generate(3) (563-593k prisms/s; 1.09-1.13 s with the
     top surface), 0 invalid by plaf check, min scaled Jacobian 0.986.
     plaf/Gmsh prisms/s = 0.18 (0.20 against 3D + top). plaf's quality stage 84-86 s (15x its
     layer stage), whole plaf process 90-93 s, peak RSS 524 MiB.
  B (one run, --only-large): 184,320 wall triangles, 5,529,600 Q2 prisms, 0 invalid; layer
     stage 81.0 s (68,300 prisms/s), quality stage 438.7 s, whole process 526 s (8.8 min),
     peak RSS 4,776 MiB.
  A again after the validity change (sub-cells by subdivision matrices, the layer stage proving
     the sign only), build of 2b0e0a1+, machine otherwise idle: plaf 593,100 prisms in 5.22 s
     (113,718 prisms/s), Gmsh 586,560 in 1.17 s (503,025/s): plaf/Gmsh 0.23 (0.27 against
     3D + top). Quality stage 15.5 s (was 84-86 s), whole process 21.3 s, peak RSS 528 MiB.
     The goal (plaf >= Gmsh's rate while certifying) is not met yet.
  After the ridge and corner fans (the layer stage's faces and directions generalised; a
     sphere has no fans) and lazy certifier products, build of the fan commits, other builds
     running beside it: A: plaf 593,100 prisms in 5.48 s (108,335/s), Gmsh 586,560 in 1.01 s
     (580,788/s): plaf/Gmsh 0.19 (0.21 against 3D + top); quality 16.2 s, process 22.4 s, peak
     RSS 430 MiB. B: 5,529,600 prisms, layer stage 94.8 s (58,353/s), quality 120.0 s, process
     217.6 s, peak RSS 3,877 MiB, 0 invalid.
  With worker threads (modules/base/parallel.h: 2 here) for the certification and the edge
     lengths, build of the threads commit, machine otherwise idle: A: plaf 593,100 prisms in
     3.60 s (164,723/s), Gmsh 586,560 in 0.96 s (611,547/s, one thread): plaf/Gmsh 0.27 (0.29
     against 3D + top); quality 8.67 s, process 12.8 s, peak RSS 425 MiB. Not met yet.
"""
import argparse
import json
import math
import os
import shutil
import sys
import tempfile
import time

from sphere_common import gmsh_sphere, heights, run_process

LAYERS = 30
# Gmsh's first size guess: 0.0355 on the built-in-kernel sphere gave 24,692 triangles.
GMSH_H_REF, GMSH_N_REF = 0.0355, 24692


def run_plaf(exe, work, name, h_wall, h0, g):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(f"""name: {name}
order: 2
geometry: {{type: sphere, center: [0, 0, 0], radius: 1}}
metric: {{type: wall_power_law, h0: {h0}, growth: {g}, h_max: 10.0, h_wall_max: {h_wall}}}
layers: {{type: extrude, max: {LAYERS}}}
output: {{formats: [report]}}
""")
    rc, err, wall, rss = run_process([exe, "run", cfg, "--out", work], work)
    rep_path = os.path.join(work, name + ".report.json")
    if not os.path.exists(rep_path):
        sys.exit(f"plaf failed (exit {rc}):\n{err}")
    rep = json.load(open(rep_path))
    t = rep["timings_s"]
    prisms = sum(v for k, v in rep["cells"]["by_type"].items() if k.startswith("prism"))
    return {
        "rc": rc,
        "triangles": rep["surface"]["triangles"],
        "prisms": prisms,
        "layers_built": rep["layers"]["count"],
        "layers_s": t["layers"],
        "surface_s": t["surface"],
        "quality_s": t["quality"],
        "total_s": wall,
        "rss_mib": rss,
        "invalid": rep["cells"]["invalid"],
        "min_sj": rep["scaled_jacobian"]["min"],
    }


def gmsh_model(gmsh, h, bl_heights):
    gmsh.clear()
    gmsh.option.setNumber("General.Verbosity", 1)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Geometry.ExtrudeReturnLateralEntities", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    patches = gmsh_sphere(gmsh, h)
    if bl_heights:
        gmsh.model.geo.extrudeBoundaryLayer([(2, s) for s in patches], [1] * len(bl_heights),
                                            bl_heights, True)
    gmsh.model.geo.synchronize()


def run_gmsh(work, h, target, h0, g, check_exe):
    import gmsh
    gmsh.initialize(["", "-v", "0"])
    try:
        # The sphere alone (the 2D stage's baseline), its size h corrected (N ~ 1/h^2) until
        # its triangle count is within 2 % of the target.
        for attempt in range(4):
            gmsh_model(gmsh, h, None)
            t0 = time.perf_counter()
            gmsh.model.mesh.generate(2)
            surf_only = time.perf_counter() - t0
            n = len(gmsh.model.mesh.getElementsByType(2)[0])
            if abs(n - target) <= 0.02 * target or attempt == 3:
                break
            h *= math.sqrt(n / target)
        # The sphere and its boundary layer.
        gmsh_model(gmsh, h, heights(h0, g, LAYERS))
        t0 = time.perf_counter()
        gmsh.model.mesh.generate(2)
        t1 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t2 = time.perf_counter()
        tags, _ = gmsh.model.mesh.getElementsByType(6)  # 6-node prisms
        prisms = len(tags)
        # The triangles are the wall's and their copies on the layer's top.
        triangles = len(gmsh.model.mesh.getElementsByType(2)[0]) // 2
        res = {"h": h, "triangles": triangles, "prisms": prisms, "surface_s": surf_only,
               "mesh2d_s": t1 - t0, "extrude_s": t2 - t1,
               "extrude_top_s": (t2 - t1) + max(0.0, (t1 - t0) - surf_only)}
        if check_exe:
            msh = os.path.join(work, "gmsh_bl.msh")
            gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
            gmsh.option.setNumber("Mesh.SaveAll", 1)
            gmsh.write(msh)
    finally:
        gmsh.finalize()
    if check_exe:
        rep_path = os.path.join(work, "gmsh_check.json")
        rc, err, _, _ = run_process([check_exe, "check", msh, "--report", rep_path], work)
        if not os.path.exists(rep_path):
            sys.exit(f"plaf check of Gmsh's mesh failed (exit {rc}):\n{err}")
        rep = json.load(open(rep_path))
        res["invalid"] = rep["cells"]["invalid"]
        res["min_sj"] = rep["scaled_jacobian"]["min"]
        os.remove(msh)
    return res


def case_a(exe, work, a):
    print(f"A. unit sphere, {LAYERS} layers h0 g^k (h0 = {a.h0}, g = {a.growth}), plaf h_wall_max {a.h_wall}")
    p = run_plaf(exe, work, "sphere_a", a.h_wall, a.h0, a.growth)
    h_g = GMSH_H_REF * math.sqrt(GMSH_N_REF / p["triangles"])
    g = run_gmsh(work, h_g, p["triangles"], a.h0, a.growth, None if a.no_check else exe)
    print(f"   Gmsh size {g['h']:.4f} (matching plaf's {p['triangles']} triangles within 2 %)")
    hdr = (f"{'':15} {'wall tris':>9} {'prisms':>9} {'seconds':>8} {'prisms/s':>10} "
           f"{'invalid':>7} {'min SJ':>7}")
    print(hdr)

    def row(name, tris, prisms, secs, inv, sj):
        inv_s = "-" if inv is None else str(inv)
        sj_s = "-" if sj is None else f"{sj:.3f}"
        print(f"{name:15} {tris:>9} {prisms:>9} {secs:8.3f} {prisms / secs:10.0f} {inv_s:>7} {sj_s:>7}")

    row("plaf layers Q2", p["triangles"], p["prisms"], p["layers_s"], p["invalid"], p["min_sj"])
    row("gmsh 3D Q1", g["triangles"], g["prisms"], g["extrude_s"], g.get("invalid"), g.get("min_sj"))
    row("gmsh 3D+top Q1", g["triangles"], g["prisms"], g["extrude_top_s"], g.get("invalid"), g.get("min_sj"))
    ratio = (p["prisms"] / p["layers_s"]) / (g["prisms"] / g["extrude_s"])
    ratio_top = (p["prisms"] / p["layers_s"]) / (g["prisms"] / g["extrude_top_s"])
    print(f"   plaf/gmsh prisms/s: {ratio:.2f} (against 3D alone), {ratio_top:.2f} (against 3D + top)")
    print(f"   plaf: {p['layers_built']} layers; surface {p['surface_s']:.2f} s; quality stage (every cell "
          f"re-certified, tight bounds) {p['quality_s']:.2f} s; process {p['total_s']:.1f} s, "
          f"peak RSS {p['rss_mib']:.0f} MiB")
    print(f"   gmsh: sphere alone {g['surface_s']:.2f} s; 2D stage with the layer's top {g['mesh2d_s']:.2f} s")
    if p["rc"] != 0:
        print(f"   note: plaf exited {p['rc']}")


def case_b(exe, work, a):
    h_wall = a.h_wall_large
    print(f"B. unit sphere, {LAYERS} layers, plaf only, h_wall_max {h_wall:.4f}")
    p = run_plaf(exe, work, "sphere_b", h_wall, a.h0, a.growth)
    print(f"{'':15} {'wall tris':>9} {'prisms':>9} {'layers s':>8} {'prisms/s':>10} {'quality s':>9} "
          f"{'total s':>8} {'peak MiB':>8} {'invalid':>7}")
    print(f"{'plaf layers Q2':15} {p['triangles']:>9} {p['prisms']:>9} {p['layers_s']:8.2f} "
          f"{p['prisms'] / p['layers_s']:10.0f} {p['quality_s']:9.2f} {p['total_s']:8.1f} "
          f"{p['rss_mib']:8.0f} {p['invalid']:>7}")
    if p["rc"] != 0:
        print(f"   note: plaf exited {p['rc']}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plaf", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                   "..", "build", "apps", "plaf"),
                    help="the plaf binary (default: build/apps/plaf of this checkout)")
    ap.add_argument("--h-wall", type=float, default=0.039, help="case A's h_wall_max (0.039: ~20k triangles)")
    ap.add_argument("--h-wall-large", type=float, default=0.0133,
                    help="case B's h_wall_max (0.0133: 184k triangles)")
    ap.add_argument("--h0", type=float, default=1e-5, help="first layer height")
    ap.add_argument("--growth", type=float, default=1.25, help="layer growth factor")
    ap.add_argument("--large", action="store_true", help="also case B: ~200k triangles, plaf only")
    ap.add_argument("--only-large", action="store_true", help="case B only")
    ap.add_argument("--no-check", action="store_true", help="skip `plaf check` of Gmsh's mesh")
    a = ap.parse_args()
    exe = os.path.abspath(a.plaf)
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        sys.exit(f"bench_prisms: no plaf binary at {exe}; build it first "
                 "(cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j2) "
                 "or pass --plaf PATH")
    work = tempfile.mkdtemp(prefix="plaf_bench_prisms_")
    try:
        if not a.only_large:
            try:
                import gmsh  # noqa: F401
            except ImportError:
                sys.exit("bench_prisms: the Gmsh Python API is missing "
                         "(apt-get install python3-gmsh; run with /usr/bin/python3)")
            case_a(exe, work, a)
        if a.large or a.only_large:
            case_b(exe, work, a)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
