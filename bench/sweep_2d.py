#!/usr/bin/env python3
"""The 2D robustness sweep (issue 12): every airfoil at every wall spacing, order, corner angle
and growth through the complete pipeline (surface mesh, layers until linear, advancing front).

Grid: the published airfoils (e387, rae2822, naca0012, n0012, nlr7301), found in the data root as
plaf finds them (`plaf data`, docs/data.md), the sharp NACA 0012 data/make_naca0012_sharp.py writes, the generated
NACA 4412 (sharp) and 23012 (blunt) sections (`naca:`), one body each, and every --extra case
(several bodies, e.g. the 30P-30N from the data root: pass their paths)
  x h0 in {1e-6, 1e-5, 1e-4, 1e-3, 5e-3} (chords)
  x order in {1, 2, 3, 4}
  x layers.corner_angle_deg in {30, 70}
  x metric.growth in {1.1, 1.2, 1.5}.
The configuration is configs/naca0012_hybrid.yaml's (circle farfield R = 20, h_max 2,
h_wall_max 0.04, curvature_factor 0.3, h_corner 0.005, layers max 40 until linear, fill {}),
with the row's keys; multi-body cases use R = 25, h_wall_max 0.03, h_corner 0.003 (the old
30p30n_hybrid config's).

Per run, one row: exit code; invalid cells; the certified min scaled Jacobian; the fill's
triangles in the metric: min shape quality, shortest edge (the closest linked node pair, in
metric units), longest edge and the fraction of unit edges ([1/sqrt2, sqrt2]); layers and the
layer after which the front is linear; wall time; and `gmsh -check` on the written MSH: "ok",
"dup" (duplicate nodes) or "err" (any other error). Gmsh calls two nodes duplicates when they are
closer than Geometry.Tolerance times the model's size (default 1e-8 x ~57 here = 5.7e-7 c), which
every layer mesh with h0 = 1e-6 c violates by design (its first layer's nodes are h0/Q apart): the
check runs with -tol set so that nodes closer than 1 % of h0/Q are duplicates.

A row fails when the exit code is not 0, a cell is invalid, or Gmsh's check is not ok. The
script writes OUT/sweep.csv and OUT/sweep.md (the table and a summary: runs, failures, worst min
scaled Jacobian, worst triangle quality, worst unit fraction, shortest edge) and exits 1 when a
row failed. Outputs of passing runs are deleted unless --keep.

    python3 bench/sweep_2d.py [--plaf build/apps/plaf] [--out sweep_out] [--jobs 2]
                              [--subset] [--keep] [--timeout 900] [--only BODY,...] [--h0 H,...]
                              [--extra 30p30n=DIR/30p30n_slat.dat,DIR/30p30n_main.dat,...]

--subset runs the ~20 representative rows of SUBSET (registered in ctest).
"""
import argparse
import concurrent.futures
import glob
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

H0S = [1e-6, 1e-5, 1e-4, 1e-3, 5e-3]
ORDERS = [1, 2, 3, 4]
CORNERS = [30, 70]
GROWTHS = [1.1, 1.2, 1.5]

# (body, h0, order, corner angle, growth): every shipped airfoil, every h0, order, corner angle
# and growth at least once, and the hard corners of the grid (the finest spacings on the blunt
# and sharp trailing edges, the largest growth at order 4).
SUBSET = [
    ("nlr7301", 1e-5, 3, 30, 1.2),  # issue 12's failing run
    ("nlr7301", 1e-6, 4, 30, 1.1),
    ("nlr7301", 5e-3, 1, 70, 1.5),
    ("nlr7301", 1e-4, 2, 70, 1.2),
    ("naca0012_sharp", 1e-6, 3, 30, 1.5),
    ("naca0012_sharp", 1e-5, 4, 70, 1.2),
    ("naca0012_sharp", 1e-3, 2, 30, 1.1),
    ("naca0012", 1e-6, 2, 70, 1.2),
    ("naca0012", 1e-4, 4, 30, 1.5),
    ("n0012", 1e-5, 1, 30, 1.1),
    ("n0012", 5e-3, 3, 70, 1.2),
    ("e387", 1e-6, 4, 70, 1.5),
    ("e387", 1e-5, 2, 30, 1.2),
    ("e387", 1e-3, 3, 30, 1.1),
    ("rae2822", 1e-6, 3, 30, 1.2),
    ("rae2822", 1e-4, 1, 70, 1.1),
    ("rae2822", 5e-3, 4, 30, 1.5),
    ("rae2822", 1e-3, 2, 70, 1.5),
    ("nlr7301", 1e-3, 4, 30, 1.1),
    ("e387", 5e-3, 1, 30, 1.2),
    ("naca4412", 1e-5, 3, 30, 1.2),
    ("naca23012_blunt", 1e-6, 2, 70, 1.5),
]

# The published airfoils, read from the data root; rows of one the root does not hold are skipped
# (with --subset the script then exits 77, which ctest reports as skipped, once the rest passed).
PUBLISHED = ["e387", "rae2822", "naca0012", "n0012", "nlr7301"]
# Generated sections: the `naca:` key's map.
GENERATED = {"naca4412": {"digits": "4412", "trailing_edge": "sharp"},
             "naca23012_blunt": {"digits": "23012", "trailing_edge": "blunt"}}

COLUMNS = ["run", "body", "h0", "order", "corner", "growth", "exit", "invalid", "min_sj", "min_tri_q",
           "min_edge", "max_edge", "unit_frac", "layers", "linear_after", "seconds", "gmsh", "note"]


def config_text(case, bodies, h0, order, corner, growth):
    multi = len(bodies) > 1
    lines = [
        f"name: {case}",
        f"order: {order}",
        "geometry:",
        "  type: airfoils",
        "  bodies:",
    ]
    for name, path in bodies:
        if isinstance(path, dict):
            lines.append(f"    - {{naca: {json.dumps(path)}, name: {name}}}")
        else:
            lines.append(f"    - {{file: {json.dumps(os.path.abspath(path))}, name: {name}}}")
    lines += [
        f"  farfield: {{shape: circle, radius: {25 if multi else 20}}}",
        "metric:",
        "  type: wall_power_law",
        f"  h0: {h0!r}",
        f"  growth: {growth!r}",
        "  h_max: 2.0",
        f"  h_wall_max: {0.03 if multi else 0.04}",
        "  curvature_factor: 0.3",
        f"  h_corner: {0.003 if multi else 0.005}",
        "layers:",
        "  max: 40",
        "  stop_when_linear: true",
        f"  corner_angle_deg: {corner}",
        "fill: {}",
        "output:",
        "  formats: [msh, report]",
    ]
    return "\n".join(lines) + "\n"


def gmsh_check(msh, h0, order):
    gmsh = shutil.which("gmsh")
    if not gmsh:
        return "n/a", "gmsh not installed"
    # The model's size: Gmsh's characteristic length is its bounding box diagonal (~2 R sqrt 2).
    lc = 2 * 25 * math.sqrt(2)
    tol = 0.01 * h0 / order / lc
    p = subprocess.run([gmsh, "-check", "-tol", f"{tol:.3e}", msh], capture_output=True, text=True, timeout=600)
    text = p.stdout + p.stderr
    errors = [l for l in text.splitlines() if l.startswith("Error")]
    if any("duplicate node" in l for l in errors):
        return "dup", next(l for l in errors if "duplicate node" in l)
    if errors or p.returncode != 0:
        return "err", errors[0] if errors else f"gmsh exit {p.returncode}"
    return "ok", ""


def run_one(args, row):
    body, h0, order, corner, growth = row
    bodies = args.bodies[body]
    name = f"{body}_h{h0:.0e}_q{order}_c{corner}_g{growth}".replace(".", "p").replace("-", "m")
    cfg_dir = os.path.join(args.out, "configs")
    run_dir = os.path.join(args.out, "runs", name)
    cfg = os.path.join(cfg_dir, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config_text(name, bodies, h0, order, corner, growth))
    shutil.rmtree(run_dir, ignore_errors=True)
    t0 = time.time()
    note = ""
    try:
        p = subprocess.run([args.plaf, "run", cfg, "--out", run_dir], capture_output=True, text=True,
                           timeout=args.timeout)
        code = p.returncode
        if code != 0:
            note = (p.stderr.strip().splitlines() or [""])[-1][:200]
    except subprocess.TimeoutExpired:
        code, note = "timeout", f"over {args.timeout} s"
    seconds = time.time() - t0
    r = {c: "" for c in COLUMNS}
    r.update(run=name, body=body, h0=h0, order=order, corner=corner, growth=growth, exit=code,
             seconds=round(seconds, 2), note=note)
    report = os.path.join(run_dir, name + ".report.json")
    if os.path.exists(report):
        with open(report) as f:
            rep = json.load(f)
        tri = rep.get("metric", {}).get("triangles", {})
        r.update(invalid=rep["cells"]["invalid"] + rep["cells"].get("unproven", 0),
                 min_sj=rep["scaled_jacobian"]["min"], min_tri_q=tri.get("quality_min", ""),
                 min_edge=tri.get("edge_min", ""), max_edge=tri.get("edge_max", ""),
                 unit_frac=tri.get("unit_fraction", ""), layers=len(rep.get("layers", {}).get("table", [])),
                 linear_after=rep.get("layers", {}).get("linear_after", ""))
    msh = os.path.join(run_dir, name + ".msh")
    r["gmsh"], gnote = gmsh_check(msh, h0, order) if os.path.exists(msh) else ("none", "no msh")
    if gnote and r["gmsh"] not in ("ok", "n/a"):
        r["note"] = (r["note"] + " " + gnote).strip()
    failed = r["exit"] != 0 or r["invalid"] not in (0, "") or r["gmsh"] not in ("ok", "n/a")
    if not failed and not args.keep:
        shutil.rmtree(run_dir, ignore_errors=True)
    return r, failed


def fmt(v):
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plaf", default=os.path.join(REPO, "build", "apps", "plaf"))
    ap.add_argument("--out", default="sweep_out")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--subset", action="store_true")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--only", default="",
                    help="comma-separated bodies (e.g. 30p30n,e387): run only their rows of the grid")
    ap.add_argument("--h0", default="", help="comma-separated wall spacings: only these rows of the grid")
    ap.add_argument("--extra", action="append", default=[],
                    help="NAME=file1.dat,file2.dat,... a multi-body case (bodies named by their files)")
    args = ap.parse_args()
    if not os.access(args.plaf, os.X_OK):
        sys.exit(f"sweep_2d: {args.plaf}: no plaf binary (build first, or pass --plaf)")
    # The sharp NACA 0012 the project's meshes were made from: its generator writes it (the
    # repository ships the script, not its output).
    os.makedirs(args.out, exist_ok=True)
    sharp = os.path.join(os.path.abspath(args.out), "naca0012_sharp.dat")
    subprocess.run([sys.executable, os.path.join(REPO, "data", "make_naca0012_sharp.py"), sharp], check=True,
                   capture_output=True)
    args.bodies = {"naca0012_sharp": [("wall", sharp)]}
    for name, spec in GENERATED.items():
        args.bodies[name] = [("wall", spec)]
    missing = []
    for name in PUBLISHED:
        found = subprocess.run([args.plaf, "data", f"airfoils/{name}.dat"], capture_output=True, text=True)
        if found.returncode == 0:
            args.bodies[name] = [("wall", found.stdout.strip())]
        else:
            missing.append(name)
            print(f"sweep_2d: {name} skipped: {found.stderr.strip()}", flush=True)
    for e in args.extra:
        if "=" not in e:
            sys.exit(f"sweep_2d: --extra {e}: expected NAME=file1,file2,...")
        name, files = e.split("=", 1)
        paths = files.split(",")
        for p in paths:
            if not os.path.isfile(p):
                sys.exit(f"sweep_2d: --extra {name}: {p}: no such file")
        args.bodies[name] = [(os.path.splitext(os.path.basename(p))[0], p) for p in paths]
    if args.subset:
        rows = [r for r in SUBSET if r[0] in args.bodies]
    else:
        only = [b for b in args.only.split(",") if b]
        for b in only:
            if b not in args.bodies:
                sys.exit(f"sweep_2d: --only {b}: no such body (known: {', '.join(sorted(args.bodies))})")
        h0s = [float(h) for h in args.h0.split(",") if h] or H0S
        rows = [(b, h0, q, c, g) for b in args.bodies if not only or b in only
                for h0 in h0s for q in ORDERS for c in CORNERS for g in GROWTHS]
    os.makedirs(os.path.join(args.out, "configs"), exist_ok=True)
    os.makedirs(os.path.join(args.out, "runs"), exist_ok=True)
    t0 = time.time()
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        futures = [ex.submit(run_one, args, row) for row in rows]
        for k, fu in enumerate(concurrent.futures.as_completed(futures)):
            r, failed = fu.result()
            results.append((r, failed))
            print(f"[{k + 1}/{len(rows)}] {'FAIL' if failed else 'ok  '} {r['run']} exit {r['exit']} "
                  f"invalid {r['invalid']} minSJ {fmt(r['min_sj'])} q {fmt(r['min_tri_q'])} "
                  f"unit {fmt(r['unit_frac'])} gmsh {r['gmsh']} {r['seconds']} s {r['note']}", flush=True)
    results.sort(key=lambda x: x[0]["run"])
    with open(os.path.join(args.out, "sweep.csv"), "w") as f:
        f.write(",".join(COLUMNS) + "\n")
        for r, _ in results:
            f.write(",".join(fmt(r[c]).replace(",", ";") for c in COLUMNS) + "\n")
    fails = [r for r, failed in results if failed]

    def worst(key, better_high=True):
        vals = [(r[key], r["run"]) for r, _ in results if isinstance(r[key], (int, float))]
        if not vals:
            return "n/a"
        v = min(vals) if better_high else max(vals)
        return f"{fmt(v[0])} ({v[1]})"

    summary = [
        f"runs: {len(results)}, failed: {len(fails)}, "
        f"exit 2: {sum(1 for r, _ in results if r['exit'] == 2)}, "
        f"with invalid cells: {sum(1 for r, _ in results if r['invalid'] not in (0, ''))}, "
        f"gmsh -check not ok: {sum(1 for r, _ in results if r['gmsh'] not in ('ok', 'n/a'))}",
        f"worst min scaled Jacobian: {worst('min_sj')}",
        f"worst triangle shape quality: {worst('min_tri_q')}",
        f"worst unit fraction: {worst('unit_frac')}",
        f"shortest fill edge (metric): {worst('min_edge')}",
        f"longest fill edge (metric): {worst('max_edge', False)}",
        f"longest run: {worst('seconds', False)} s; sweep wall time {time.time() - t0:.0f} s",
    ]
    with open(os.path.join(args.out, "sweep.md"), "w") as f:
        f.write("# 2D sweep\n\n" + "\n".join("- " + s for s in summary) + "\n\n")
        f.write("| " + " | ".join(COLUMNS) + " |\n|" + "---|" * len(COLUMNS) + "\n")
        for r, _ in results:
            f.write("| " + " | ".join(fmt(r[c]) for c in COLUMNS) + " |\n")
    print("\n".join(summary))
    for r in fails:
        print(f"FAILED {r['run']}: exit {r['exit']}, invalid {r['invalid']}, gmsh {r['gmsh']} {r['note']}")
    if fails:
        return 1
    if missing and args.subset:
        print(f"sweep_2d: SKIPPED the rows of {', '.join(missing)}: no data root holds them (docs/data.md)")
        return 77
    return 0


if __name__ == "__main__":
    sys.exit(main())
