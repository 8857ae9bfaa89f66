#!/usr/bin/env python3
"""Benchmark: plaf's advancing-front fill (paper Sec. II.C) against two peers, in one run.

A. Metric-conforming linear triangles, plaf vs BAMG (F. Hecht's bidimensional anisotropic mesh
   generator; Debian's freefem++ ships it as /usr/bin/ffbamg, also looked up as `bamg`).
   Domain: the NACA 0012 with a sharp trailing edge (written by data/make_naca0012_sharp.py,
   199 distinct points) inside a circle of radius R = 10 centred at (0.5, 0).
   Metric: analytic, anisotropic, smooth: the intersection (simultaneous reduction) of
     - a boundary-layer-like field: normal size h_n = 0.005 + 0.15 d (d: distance to the airfoil
       polygon, along the direction to its closest point), size along the wall
       h_t = 0.01 + 0.24 sin^2(pi x_f) + 0.25 d (x_f: x of that closest point), both capped at
       min(1, 0.25 + 0.1 d): sizes 0.005..1, anisotropy up to 50 at mid chord;
     - a shock-like band across the line x = 0.6 + 0.2 y: sizes 0.005/s across, 0.25/s along,
       s = exp(-((y - 0.5)/0.5)^2) exp(-(dist/0.03)^2) (anisotropy 50 where s = 1).
   It is run at levels ("sizes x L", default L = 1, 0.5, 0.25: the metric times 1/L^2, about
   4k, 16k and 60k triangles) on ONE background triangulation, built here with Gmsh (Delaunay,
   isotropic, edges about half the smallest size of the L = 1 metric; ~28k vertices, 54k
   triangles) whose boundary is every airfoil point joined by straight segments (subdivided)
   and a 360-gon inscribed in the circle. Each mesher gets the metric at its vertices:
     - plaf: `plaf run` of a config with order: 1, geometry: airfoils (a spline through the same
       .dat points, corner angle 30 deg, circle farfield R at (0.5, 0)), metric: background
       (bg.mesh + bg.sol: libMeshb text, Vertices/Edges/Triangles and SolAtVertices of type 3,
       m11 m12 m22), fill: {}, formats [msh, report];
     - BAMG: `bamg -b bg.mesh -M bg.mtr -o bamg.mesh -thetamax 30 -nbv N -v 1`, adaptation mode:
       the domain is the background mesh itself, its boundary rediscretized by the metric along
       a curve through the background's boundary vertices (corners where the turning angle
       exceeds 30 deg, as plaf's default: only the trailing edge); metric file bg.mtr: "nv 3",
       then m11 m12 m22 per vertex. Defaults otherwise (3 smoothing passes, background vertices
       kept where they fit the metric; that needs -nbv >= the background's vertex count, so
       N = background vertices + twice the metric's vertex estimate).
   Both meshes are measured by plaf in that same background metric: plaf's from its run report;
   BAMG's output is converted here to Gmsh MSH 4.1 (triangles + boundary edges tagged wall /
   farfield) and measured by `plaf check bamg.msh --metric A.yaml --report r.json`.

B. The NACA 0012 boundary-layer case at order 3, plaf vs Gmsh.
     - plaf: order 3, circle farfield R = 20, metric wall_power_law (h0 = 0.001, g = 1.2,
       h_max = 1, h_wall_max = 0.02, curvature_factor 0.25, h_corner 0.005), layers {max: 20,
       fan_angle_deg: 20} (the default 45 deg fan stops growth at this sharp trailing edge after
       4 layers), fill: {} (triangles written at order 3: output.uniform_order's default);
       --quick: 12 layers, h_wall_max 0.04, h_corner 0.01;
     - Gmsh (python3-gmsh): the same points as one closed Spline (its end point the sharp
       trailing edge, a fan there), transfinite with as many wall elements as plaf's surface mesh
       (read from plaf's msh), a BoundaryLayer field (Size h0, Ratio 1.2, the thickness of 20
       layers, quads), elsewhere the size f * min(1, max(h_wall_max, h0 + 0.2 d)) (Distance +
       MathEval), Frontal-Delaunay (Mesh.Algorithm = 6), generate(2) + setOrder(3). The factor f
       is tuned by untimed trials until Gmsh's element count is within 5% of plaf's (f = 1 often
       is); row "gmsh+el" adds optimize("HighOrderElastic"), Gmsh's remedy for invalid curved
       cells.
   Gmsh's order-3 meshes are measured by `plaf check gmsh.msh --metric B.yaml --report r.json`.

Columns: elements; "mesh s": each tool's own meshing time (plaf: its surface, layers, fill and
mesh (assembly) stages, from the report's timings_s; bamg: its "Cpu time for meshing" line, meshing +
smoothing without reading the background or building the metric, printed by bamg in steps of
0.01 s; Gmsh: generate(2) + setOrder(3) [+ the optimization] timed in this process); "wall s":
the whole plaf or bamg process (plaf: + reading the config and background, certifying every
cell, writing msh + report; bamg: + reading the background, writing its mesh), Gmsh: = mesh s;
elem/s = elements / mesh s; then, measured by plaf for every mesher: unit frac (share of edges
whose metric length is in [1/sqrt2, sqrt2]), max len (the longest edge in the metric), min sJ
(certified scaled Jacobian; 1 for straight triangles), max AR, invalid cells. Every time is the
least of --repeat runs (default 3). The run is deterministic (one thread everywhere).

Run by hand after building (needs Debian's freefem++, gmsh and python3-gmsh; numpy not needed):
    /usr/bin/python3 bench/bench_fill.py [--build build] [--quick] [--only A|B] [--levels 1,0.5]
                                         [--repeat 3] [--keep]
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

try:
    import gmsh
except ImportError:
    gmsh = None


def die(msg):
    print(f"bench_fill: error: {msg}", file=sys.stderr)
    sys.exit(1)


# ---- airfoil and geometry helpers ----------------------------------------------------------

def find_airfoil():
    """The sharp NACA 0012's 200 points, written by data/make_naca0012_sharp.py into a scratch
    file (the repository ships the generator, not its output)."""
    p = os.path.join(tempfile.mkdtemp(prefix="bench_fill_"), "naca0012_sharp.dat")
    gen = os.path.join(REPO, "data", "make_naca0012_sharp.py")
    if subprocess.run([sys.executable, gen, p], capture_output=True).returncode != 0 or not os.path.isfile(p):
        die(f"{gen} could not write {p}")
    return p


def read_airfoil(path):
    """The .dat points (Selig order: TE, upper, LE, lower, TE), closing duplicate dropped."""
    pts = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) < 2:
                continue
            try:
                pts.append((float(parts[0]), float(parts[1])))
            except ValueError:
                continue
    if math.dist(pts[0], pts[-1]) < 1e-12:
        pts.pop()
    area = 0.5 * sum(pts[i - 1][0] * pts[i][1] - pts[i][0] * pts[i - 1][1] for i in range(len(pts)))
    if area < 0:  # make it counter-clockwise, so (dy, -dx) points out of the airfoil
        pts.reverse()
    return pts


class Polygon:
    """Distance to a closed polygon with a bounding-circle cull over chunks of segments."""

    def __init__(self, pts, chunk=8):
        self.pts = pts
        n = len(pts)
        self.segs = [(pts[i], pts[(i + 1) % n]) for i in range(n)]
        self.normals = []
        for (ax, ay), (bx, by) in self.segs:
            L = math.hypot(bx - ax, by - ay)
            self.normals.append(((by - ay) / L, -(bx - ax) / L))
        self.chunks = []
        for s in range(0, n, chunk):
            ids = list(range(s, min(n, s + chunk)))
            xs = [c for i in ids for c in (self.segs[i][0][0], self.segs[i][1][0])]
            ys = [c for i in ids for c in (self.segs[i][0][1], self.segs[i][1][1])]
            cx, cy = 0.5 * (min(xs) + max(xs)), 0.5 * (min(ys) + max(ys))
            r = max(math.hypot(x - cx, y - cy) for x, y in zip(xs, ys))
            self.chunks.append((cx, cy, r, ids))

    def closest(self, x, y):
        """(distance, foot x, foot y, unit direction (nx, ny) from the foot towards the point)."""
        order = sorted((max(0.0, math.hypot(x - cx, y - cy) - r), ids) for cx, cy, r, ids in self.chunks)
        best = (math.inf, 0, 0.0)
        for lb, ids in order:
            if lb * lb >= best[0]:
                break
            for i in ids:
                (ax, ay), (bx, by) = self.segs[i]
                ex, ey = bx - ax, by - ay
                t = ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)
                t = min(1.0, max(0.0, t))
                qx, qy = ax + t * ex - x, ay + t * ey - y
                d2 = qx * qx + qy * qy
                if d2 < best[0]:
                    best = (d2, i, t)
        d2, i, t = best
        (ax, ay), (bx, by) = self.segs[i]
        fx, fy = ax + t * (bx - ax), ay + t * (by - ay)
        d = math.sqrt(d2)
        if d > 1e-9:
            nx, ny = (x - fx) / d, (y - fy) / d
        else:  # on the polygon: the segment normal, averaged with the neighbour's at a vertex
            nx, ny = self.normals[i]
            j = (i - 1) % len(self.segs) if t < 1e-9 else (i + 1) % len(self.segs) if t > 1 - 1e-9 else None
            if j is not None:
                nx, ny = nx + self.normals[j][0], ny + self.normals[j][1]
                L = math.hypot(nx, ny)
                nx, ny = nx / L, ny / L
        return d, fx, fy, nx, ny


# ---- 2x2 symmetric metrics: (m11, m12, m22) -------------------------------------------------

def metric_from(nx, ny, h_n, h_t):
    """Size h_n along the unit vector (nx, ny), h_t across it."""
    a, b = 1.0 / (h_n * h_n), 1.0 / (h_t * h_t)
    return (a * nx * nx + b * ny * ny, (a - b) * nx * ny, a * ny * ny + b * nx * nx)


def sym_eig(m):
    """Eigenvalues l1 >= l2 and the unit eigenvector of l1 of a symmetric 2x2 matrix."""
    a, b, c = m
    mean, diff = 0.5 * (a + c), 0.5 * (a - c)
    r = math.hypot(diff, b)
    l1, l2 = mean + r, mean - r
    if r < 1e-300:
        return l1, l2, (1.0, 0.0)
    ang = 0.5 * math.atan2(b, diff)
    return l1, l2, (math.cos(ang), math.sin(ang))


def sym_from_eig(l1, l2, v):
    vx, vy = v
    return (l1 * vx * vx + l2 * vy * vy, (l1 - l2) * vx * vy, l1 * vy * vy + l2 * vx * vx)


def sym_pow(m, p):
    l1, l2, v = sym_eig(m)
    return sym_from_eig(l1 ** p, l2 ** p, v)


def sym_mul(x, y, z):
    """x y z for symmetric x, z and symmetric y, returning the symmetric part."""
    def mat(s):
        return ((s[0], s[1]), (s[1], s[2]))

    def mm(p, q):
        return tuple(tuple(sum(p[i][k] * q[k][j] for k in range(2)) for j in range(2)) for i in range(2))
    r = mm(mm(mat(x), mat(y)), mat(z))
    return (r[0][0], 0.5 * (r[0][1] + r[1][0]), r[1][1])


def intersect(m1, m2):
    """The metric intersection (simultaneous reduction): the largest ellipse in both unit balls."""
    h = sym_pow(m1, 0.5)
    hi = sym_pow(m1, -0.5)
    c = sym_mul(hi, m2, hi)
    l1, l2, v = sym_eig(c)
    return sym_mul(h, sym_from_eig(max(l1, 1.0), max(l2, 1.0), v), h)


# ---- A: background mesh + analytic metric ---------------------------------------------------

SHOCK_W = 0.03


def shock_strength(x, y):
    """Signed distance to the line x = 0.6 + 0.2 y and the band strength s in (0, 1]."""
    dist = (x - 0.6 - 0.2 * y) / math.sqrt(1.04)
    return dist, math.exp(-((y - 0.5) / 0.5) ** 2) * math.exp(-(dist / SHOCK_W) ** 2)


def analytic_metric(poly, x, y, scale):
    """The A metric at (x, y); all sizes multiplied by `scale` (1: sizes 0.005..1)."""
    d, fx, fy, nx, ny = poly.closest(x, y)
    cap = min(1.0, 0.25 + 0.1 * d)
    h_n = min(cap, 0.005 + 0.15 * d)
    h_t = min(cap, 0.01 + 0.24 * math.sin(math.pi * min(1.0, max(0.0, fx))) ** 2 + 0.25 * d)
    m = metric_from(nx, ny, scale * h_n, scale * max(h_t, h_n))
    _, s = shock_strength(x, y)
    if s > 1e-4:
        bx, by = 1.0 / math.sqrt(1.04), -0.2 / math.sqrt(1.04)  # normal to the band
        m = intersect(m, metric_from(bx, by, scale * 0.005 / s, scale * 0.25 / s))
    return m


def build_background(pts, R, center, scale, bg_factor):
    """Gmsh triangulation of the disk minus the airfoil polygon; returns nodes, tris, edges."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("background")
        geo = gmsh.model.geo
        ap = [geo.addPoint(x, y, 0) for x, y in pts]
        al = [geo.addLine(ap[i], ap[(i + 1) % len(ap)]) for i in range(len(ap))]
        nc = 360
        cp = [geo.addPoint(center[0] + R * math.cos(2 * math.pi * k / nc), center[1] + R * math.sin(2 * math.pi * k / nc), 0)
              for k in range(nc)]
        cl = [geo.addLine(cp[k], cp[(k + 1) % nc]) for k in range(nc)]
        outer = geo.addCurveLoop(cl)
        inner = geo.addCurveLoop(al)
        geo.addPlaneSurface([outer, inner])
        geo.synchronize()
        fld = gmsh.model.mesh.field
        dist = fld.add("Distance")
        fld.setNumbers(dist, "CurvesList", al)
        fld.setNumber(dist, "NumPointsPerCurve", 20)
        bl = fld.add("MathEval")
        k = bg_factor * scale
        fld.setString(bl, "F", f"{k}*min(0.25+0.1*F{dist}, min(0.005+0.15*F{dist}, 0.01+0.25*F{dist}))")
        band = fld.add("MathEval")
        dexpr = "((x-0.6-0.2*y)/1.0198039)"
        # (MathEval reads -(a)^2 as (-a)^2: squares written as products)
        fld.setString(band, "F", f"{k}*0.005/max(0.005, exp(0-((y-0.5)/0.5)*((y-0.5)/0.5))"
                                 f"*exp(0-({dexpr}/{SHOCK_W})*({dexpr}/{SHOCK_W})))")
        mn = fld.add("Min")
        fld.setNumbers(mn, "FieldsList", [bl, band])
        fld.setAsBackgroundMesh(mn)
        for opt in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"):
            gmsh.option.setNumber(opt, 0)
        gmsh.option.setNumber("Mesh.Algorithm", 5)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        index = {int(t): i for i, t in enumerate(tags)}
        nodes = [(coords[3 * i], coords[3 * i + 1]) for i in range(len(tags))]
        _, tn = gmsh.model.mesh.getElementsByType(2)
        tris = []
        for e in range(len(tn) // 3):
            a, b, c = (index[int(tn[3 * e + j])] for j in range(3))
            (ax, ay), (bx, by), (cx, cy) = nodes[a], nodes[b], nodes[c]
            if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) < 0:
                b, c = c, b
            tris.append((a, b, c))
        edges = []
        for ref, lines in ((1, al), (2, cl)):
            for ln in lines:
                _, _, en = gmsh.model.mesh.getElements(1, ln)
                flat = en[0]
                for e in range(len(flat) // 2):
                    edges.append((index[int(flat[2 * e])], index[int(flat[2 * e + 1])], ref))
    finally:
        gmsh.finalize()
    return nodes, tris, edges


def write_background(work, nodes, tris, edges, metrics):
    """bg.mesh (read by plaf and bamg; Edges, which plaf skips, give bamg the boundary refs),
    bg.sol (plaf) and bg.mtr (bamg). Vertex refs: the boundary's for boundary vertices, 0 inside."""
    vref = [0] * len(nodes)
    for a, b, r in edges:
        vref[a] = vref[b] = r
    mesh = os.path.join(work, "bg.mesh")
    with open(mesh, "w") as f:
        f.write(f"MeshVersionFormatted 1\n\nDimension\n2\n\nVertices\n{len(nodes)}\n")
        f.writelines(f"{x:.17g} {y:.17g} {r}\n" for (x, y), r in zip(nodes, vref))
        f.write(f"\nEdges\n{len(edges)}\n")
        f.writelines(f"{a + 1} {b + 1} {r}\n" for a, b, r in edges)
        f.write(f"\nTriangles\n{len(tris)}\n")
        f.writelines(f"{a + 1} {b + 1} {c + 1} 0\n" for a, b, c in tris)
        f.write("\nEnd\n")
    sol = os.path.join(work, "bg.sol")
    with open(sol, "w") as f:
        f.write(f"MeshVersionFormatted 1\n\nDimension\n2\n\nSolAtVertices\n{len(nodes)}\n1 3\n")
        f.writelines(f"{a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in metrics)
        f.write("\nEnd\n")
    mtr = os.path.join(work, "bg.mtr")  # bamg's metric file: "nv 3", then m11 m12 m22 per vertex
    with open(mtr, "w") as f:
        f.write(f"{len(nodes)} 3\n")
        f.writelines(f"{a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in metrics)
    return mesh, sol, mtr


# ---- MSH 4.1 for a linear triangle mesh (bamg's output) ------------------------------------

def read_bamg_mesh(path):
    """Vertices and Triangles of a bamg (BD mesh / INRIA) text file; 0-based triangles."""
    with open(path) as f:
        toks = f.read().split()
    nodes, tris = [], []
    i = 0
    while i < len(toks):
        t = toks[i]
        if t == "Vertices":
            n = int(toks[i + 1])
            i += 2
            nodes = [(float(toks[i + 3 * k]), float(toks[i + 3 * k + 1])) for k in range(n)]
            i += 3 * n
        elif t == "Triangles":
            n = int(toks[i + 1])
            i += 2
            tris = [tuple(int(toks[i + 4 * k + j]) - 1 for j in range(3)) for k in range(n)]
            i += 4 * n
        else:
            i += 1
    return nodes, tris


def write_msh_triangles(path, nodes, tris, center, R):
    """Gmsh MSH 4.1 ASCII: triangles in a "domain" surface, boundary edges (used by one triangle)
    in curves "wall" (near the airfoil) and "farfield" (near the circle)."""
    count = {}
    for a, b, c in tris:
        for e in ((a, b), (b, c), (c, a)):
            k = (min(e), max(e))
            count[k] = count.get(k, 0) + 1
    wall, far = [], []
    for (a, b), n in sorted(count.items()):
        if n != 1:
            continue
        mx, my = 0.5 * (nodes[a][0] + nodes[b][0]), 0.5 * (nodes[a][1] + nodes[b][1])
        (far if math.hypot(mx - center[0], my - center[1]) > 0.5 * R else wall).append((a, b))
    xs, ys = [p[0] for p in nodes], [p[1] for p in nodes]
    box = f"{min(xs):.17g} {min(ys):.17g} 0 {max(xs):.17g} {max(ys):.17g} 0"
    out = ["$MeshFormat\n4.1 0 8\n$EndMeshFormat\n",
           '$PhysicalNames\n3\n1 1 "wall"\n1 2 "farfield"\n2 3 "domain"\n$EndPhysicalNames\n',
           f"$Entities\n0 2 1 0\n1 {box} 1 1 0\n2 {box} 1 2 0\n3 {box} 1 3 2 1 2\n$EndEntities\n",
           f"$Nodes\n1 {len(nodes)} 1 {len(nodes)}\n2 3 0 {len(nodes)}\n"]
    out.append("".join(f"{i + 1}\n" for i in range(len(nodes))))
    out.append("".join(f"{x:.17g} {y:.17g} 0\n" for x, y in nodes))
    out.append("$EndNodes\n")
    ne = len(wall) + len(far) + len(tris)
    out.append(f"$Elements\n3 {ne} 1 {ne}\n")
    tag = 1
    for ent, edges in ((1, wall), (2, far)):
        out.append(f"1 {ent} 1 {len(edges)}\n")
        for a, b in edges:
            out.append(f"{tag} {a + 1} {b + 1}\n")
            tag += 1
    out.append(f"2 3 2 {len(tris)}\n")
    for a, b, c in tris:
        out.append(f"{tag} {a + 1} {b + 1} {c + 1}\n")
        tag += 1
    out.append("$EndElements\n")
    with open(path, "w") as f:
        f.write("".join(out))


# ---- running plaf ---------------------------------------------------------------------------

def plaf_run(plaf, cfg, out, repeat):
    """Runs `plaf run` `repeat` times: the last report, the least process wall time and the
    least meshing time (the surface, layers, fill and mesh stages)."""
    walls, meshes = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = subprocess.run([plaf, "run", cfg, "--out", out], capture_output=True, text=True)
        walls.append(time.perf_counter() - t0)
        if r.returncode not in (0, 2):
            die(f"plaf run {cfg} failed ({r.returncode}):\n{r.stderr.strip()}")
        reports = [f for f in os.listdir(out) if f.endswith(".report.json")]
        if len(reports) != 1:
            die(f"plaf run {cfg}: expected one report in {out}, found {reports}")
        with open(os.path.join(out, reports[0])) as f:
            rep = json.load(f)
        # The meshing stages: surface mesh, layers, fill (with its post-optimisation) and the
        # assembly ("mesh"); not config, metric, budget, quality or writing.
        t = rep["timings_s"]
        meshes.append(sum(t.get(k, 0.0) for k in ("surface", "layers", "fill", "mesh")))
    return rep, min(walls), min(meshes)


def plaf_check(plaf, msh, cfg, report):
    cmd = [plaf, "check", msh, "--report", report] + (["--metric", cfg] if cfg else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 2) or not os.path.isfile(report):
        die(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr.strip()}")
    with open(report) as f:
        return json.load(f)


def has_fill(rep):
    """Whether a run report holds a filled domain (triangles beyond a surface mesh)."""
    return any(k.startswith("triangle") for k in rep["cells"]["by_type"])


def metric_of(rep):
    m = rep.get("metric")
    return m["unit_fraction"] if m else float("nan")


def metric_max(rep):
    m = rep.get("metric")
    return m["max"] if m else float("nan")


# ---- A ---------------------------------------------------------------------------------------

def part_a(plaf, bamg, work, dat, levels, repeat):
    """One table per level s: the metric's sizes times s on the same background."""
    R, center = 10.0, (0.5, 0.0)
    pts = read_airfoil(dat)
    poly = Polygon(pts)
    t0 = time.perf_counter()
    nodes, tris, edges = build_background(pts, R, center, 1.0, 0.5)
    base = [analytic_metric(poly, x, y, 1.0) for x, y in nodes]
    print(f"A: background mesh {len(nodes)} vertices, {len(tris)} triangles, metric evaluated "
          f"({time.perf_counter() - t0:.1f} s, not timed)", flush=True)
    # bamg allocates for -nbv vertices up front (its time grows with it), and keeps background
    # vertices (its default) only when -nbv is at least the background's vertex count: the
    # background's count plus twice the vertex count the metric asks for (unit equilateral
    # triangles: area sqrt(3)/4 in the metric; about 2 triangles per vertex).
    cells = 0.0
    for a, b, c in tris:
        (ax, ay), (bx, by), (cx, cy) = nodes[a], nodes[b], nodes[c]
        area = 0.5 * abs((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))
        dens = sum(math.sqrt(max(0.0, m[0] * m[2] - m[1] * m[1])) for m in (base[a], base[b], base[c])) / 3
        cells += area * dens / (math.sqrt(3) / 4)
    tables = []
    for level in levels:
        k = 1.0 / (level * level)
        sub = os.path.join(work, f"A_{level:g}")
        os.makedirs(sub)
        mesh, sol, mtr = write_background(sub, nodes, tris, edges, [(k * a, k * b, k * c) for a, b, c in base])
        cfg = os.path.join(sub, "A.yaml")
        out = os.path.join(sub, "plaf")
        os.makedirs(out)
        with open(cfg, "w") as f:
            f.write(f"""name: bench_af
order: 1
geometry:
  type: airfoils
  bodies: [{{file: {dat}, name: wall}}]
  farfield: {{shape: circle, radius: {R}, center: [{center[0]}, {center[1]}]}}
metric: {{type: background, file: {mesh}, sol: {sol}}}
fill: {{}}
output: {{dir: {out}, formats: [msh, report], msh: ascii}}
""")
        rows = []
        rep, wall, tmesh = plaf_run(plaf, cfg, out, repeat)
        if has_fill(rep):
            rows.append(("plaf", rep["cells"]["total"], tmesh, wall, metric_of(rep), metric_max(rep),
                         rep["scaled_jacobian"]["min"], rep["aspect_ratio"]["max"], rep["cells"]["invalid"]))
        else:
            print(f"A (sizes x {level:g}): plaf's run produced no fill (not in this build): plaf row skipped",
                  flush=True)
        bout = os.path.join(sub, "bamg.mesh")
        cmd = [bamg, "-b", mesh, "-M", mtr, "-o", bout, "-nbv", str(len(nodes) + int(cells / level ** 2) + 10000), "-thetamax", "30", "-v", "1"]
        bwall = bmesh = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=sub)
            bwall = min(bwall, time.perf_counter() - t0)
            if r.returncode != 0 or not os.path.isfile(bout):
                die(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
            m = re.search(r"Cpu time for meshing\s*:\s*([0-9.eE+-]+)", r.stdout)
            if not m:
                die(f"no 'Cpu time for meshing' line in the output of {' '.join(cmd)}")
            bmesh = min(bmesh, float(m.group(1)))
        bnodes, btris = read_bamg_mesh(bout)
        bmsh = os.path.join(sub, "bamg.msh")
        write_msh_triangles(bmsh, bnodes, btris, center, R)
        brep = plaf_check(plaf, bmsh, cfg, os.path.join(sub, "bamg.report.json"))
        rows.append(("bamg", brep["cells"]["total"], bmesh, bwall, metric_of(brep), metric_max(brep),
                     brep["scaled_jacobian"]["min"], brep["aspect_ratio"]["max"], brep["cells"]["invalid"]))
        tables.append((level, rows))
    return tables


# ---- B ---------------------------------------------------------------------------------------

def msh_boundary_elements(path, name):
    """Number of boundary (dimension-1) elements in the physical group `name` of an MSH 4.1 file."""
    with open(path) as f:
        lines = f.read().splitlines()
    i = lines.index("$PhysicalNames")
    phys = None
    for ln in lines[i + 2:i + 2 + int(lines[i + 1])]:
        d, t, nm = ln.split(maxsplit=2)
        if d == "1" and nm.strip('"') == name:
            phys = int(t)
    i = lines.index("$Entities")
    npnt, ncur = (int(v) for v in lines[i + 1].split()[:2])
    curves = set()
    for ln in lines[i + 2 + npnt:i + 2 + npnt + ncur]:
        v = ln.split()
        nph = int(v[7])
        if phys in (int(x) for x in v[8:8 + nph]):
            curves.add(int(v[0]))
    i = lines.index("$Elements")
    nblocks = int(lines[i + 1].split()[0])
    j, n = i + 2, 0
    for _ in range(nblocks):
        d, ent, _, cnt = (int(v) for v in lines[j].split())
        if d == 1 and ent in curves:
            n += cnt
        j += 1 + cnt
    return n


def gmsh_bl(pts, R, center, h0, layers, h_wall, n_wall, factor, out_msh=None, optimize=0):
    """Gmsh boundary layer + Frontal-Delaunay + order 3; returns (elements, seconds)."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        t0 = time.perf_counter()
        gmsh.model.add("bl")
        geo = gmsh.model.geo
        # Start at the trailing edge: the spline's end point is the sharp corner.
        te = max(range(len(pts)), key=lambda i: pts[i][0])
        order = pts[te:] + pts[:te]
        tags = [geo.addPoint(x, y, 0) for x, y in order]
        spline = geo.addSpline(tags + [tags[0]])
        c = geo.addPoint(center[0], center[1], 0)
        q = [geo.addPoint(center[0] + R * math.cos(a), center[1] + R * math.sin(a), 0)
             for a in (0, 0.5 * math.pi, math.pi, 1.5 * math.pi)]
        arcs = [geo.addCircleArc(q[k], c, q[(k + 1) % 4]) for k in range(4)]
        geo.addPlaneSurface([geo.addCurveLoop(arcs), geo.addCurveLoop([spline])])
        geo.synchronize()
        gmsh.model.addPhysicalGroup(1, [spline], 1)
        gmsh.model.setPhysicalName(1, 1, "wall")
        gmsh.model.addPhysicalGroup(1, arcs, 2)
        gmsh.model.setPhysicalName(1, 2, "farfield")
        gmsh.model.addPhysicalGroup(2, [1], 3)
        gmsh.model.setPhysicalName(2, 3, "domain")
        gmsh.model.mesh.setTransfiniteCurve(spline, n_wall + 1)
        fld = gmsh.model.mesh.field
        bl = fld.add("BoundaryLayer")
        fld.setNumbers(bl, "CurvesList", [spline])
        fld.setNumbers(bl, "FanPointsList", [tags[0]])
        fld.setNumber(bl, "Size", h0)
        fld.setNumber(bl, "Ratio", 1.2)
        fld.setNumber(bl, "Thickness", h0 * (1.2 ** layers - 1) / 0.2)
        fld.setNumber(bl, "Quads", 1)
        fld.setAsBoundaryLayer(bl)
        dist = fld.add("Distance")
        fld.setNumbers(dist, "CurvesList", [spline])
        fld.setNumber(dist, "NumPointsPerCurve", 2000)
        size = fld.add("MathEval")
        fld.setString(size, "F", f"{factor}*min(1, max({h_wall}, {h0}+0.2*F{dist}))")
        fld.setAsBackgroundMesh(size)
        for opt in ("Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromPoints", "Mesh.MeshSizeFromCurvature"):
            gmsh.option.setNumber(opt, 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(3)
        if optimize:  # the elastic analogy on the curved boundary's displacement (Gmsh's remedy)
            gmsh.model.mesh.optimize("HighOrderElastic")
        t = time.perf_counter() - t0
        types, etags, _ = gmsh.model.mesh.getElements(2)
        n = sum(len(e) for e in etags)
        if out_msh:
            gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
            gmsh.option.setNumber("Mesh.Binary", 0)
            gmsh.write(out_msh)
    finally:
        gmsh.finalize()
    return n, t


def part_b(plaf, work, dat, quick, repeat):
    R, center = 20.0, (0.5, 0.0)
    h0, layers = 1e-3, (12 if quick else 20)
    h_wall, h_corner = (0.04, 0.01) if quick else (0.02, 0.005)
    cfg = os.path.join(work, "B.yaml")
    out = os.path.join(work, "B_plaf")
    os.makedirs(out, exist_ok=True)
    with open(cfg, "w") as f:
        f.write(f"""name: bench_bl
order: 3
geometry:
  type: airfoils
  bodies: [{{file: {dat}, name: wall}}]
  farfield: {{shape: circle, radius: {R}, center: [{center[0]}, {center[1]}]}}
metric: {{type: wall_power_law, h0: {h0}, growth: 1.2, h_max: 1.0, h_wall_max: {h_wall}, curvature_factor: 0.25, h_corner: {h_corner}}}
layers: {{max: {layers}, fan_angle_deg: 20}}
fill: {{}}
output: {{dir: {out}, formats: [msh, report], msh: ascii}}
""")
    rep, wall, tmesh = plaf_run(plaf, cfg, out, repeat)
    rows = []
    n_wall = msh_boundary_elements(os.path.join(out, "bench_bl.msh"), "wall")
    target = rep["cells"]["total"]
    if has_fill(rep):
        rows.append(("plaf", target, tmesh, wall, metric_of(rep), metric_max(rep),
                     rep["scaled_jacobian"]["min"], rep["aspect_ratio"]["max"], rep["cells"]["invalid"]))
    else:
        target = None
        print(f"B: plaf's run produced no fill (not in this build): plaf row skipped, Gmsh's size factor "
              f"left at 1; plaf's layers: {rep['cells']['total']} cells on {n_wall} wall elements", flush=True)

    # Untimed trials: the fill's count goes as factor^-2; the layers' quads stay.
    pts = read_airfoil(dat)
    factor = 1.0
    for _ in range(8):
        n, _ = gmsh_bl(pts, R, center, h0, layers, h_wall, n_wall, factor)
        if target is None or abs(n - target) <= 0.05 * target:
            break
        quads = n_wall * layers
        factor *= math.sqrt(max(1, n - quads) / max(1, target - quads))
    for name, optimize in (("gmsh", 0), ("gmsh+el", 1)):
        msh = os.path.join(work, f"B_{name}.msh")
        t = math.inf
        for k in range(repeat):
            n, tk = gmsh_bl(pts, R, center, h0, layers, h_wall, n_wall, factor, msh if k == 0 else None, optimize)
            t = min(t, tk)
        grep = plaf_check(plaf, msh, cfg, os.path.join(work, f"B_{name}.report.json"))
        rows.append((name, grep["cells"]["total"], t, t, metric_of(grep), metric_max(grep),
                     grep["scaled_jacobian"]["min"], grep["aspect_ratio"]["max"], grep["cells"]["invalid"]))
    return rows, factor


# ---- output ----------------------------------------------------------------------------------

def print_table(title, rows, peer):
    print(f"\n{title}")
    print(f"{'mesher':7} {'elements':>9} {'mesh s':>8} {'wall s':>8} {'elem/s':>10} {'unit frac':>9} "
          f"{'max len':>7} {'min sJ':>7} {'max AR':>7} {'invalid':>7}")
    for name, n, tm, tw, uf, ml, sj, ar, inv in rows:
        rate = f"{n / tm:10.0f}" if tm > 0 else f"{'inf':>10}"
        print(f"{name:7} {n:>9} {tm:8.3f} {tw:8.3f} {rate} {uf:9.4f} {ml:7.2f} {sj:7.4f} {ar:7.1f} {inv:>7}")
    byname = {r[0]: r for r in rows}
    if "plaf" in byname and peer in byname:
        p, q = byname["plaf"], byname[peer]

        def ratio(x, y):
            return f"{x / y:.2f}" if y > 0 else "n/a"
        print(f"plaf/{peer}: elements {ratio(p[1], q[1])}, mesh s {ratio(p[2], q[2])}, wall s {ratio(p[3], q[3])}, "
              f"elem/s {ratio(p[1] * q[2], p[2] * q[1])}, unit frac {ratio(p[4], q[4])}")
    else:
        print(f"plaf/{peer}: no ratios (no plaf row)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build", help="plaf build folder (default: build)")
    ap.add_argument("--quick", action="store_true", help="coarser metrics: a run of a few seconds")
    ap.add_argument("--keep", action="store_true", help="keep (and print) the work folder")
    ap.add_argument("--only", choices=["A", "B"], help="run one comparison")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per tool, the least time kept (default 3)")
    ap.add_argument("--levels", help="A: comma-separated size factors (default 1,0.5,0.25; --quick: 1)")
    a = ap.parse_args()
    plaf = os.path.abspath(os.path.join(a.build, "apps", "plaf"))
    if not os.access(plaf, os.X_OK):
        die(f"{plaf} not found: build plaf first (cmake --build {a.build} --target plaf) or pass --build")
    if gmsh is None:
        die("python3-gmsh is missing (apt-get install python3-gmsh; run with /usr/bin/python3)")
    bamg = shutil.which("bamg") or shutil.which("ffbamg")
    if bamg is None and a.only != "B":
        die("bamg is missing: apt-get install freefem++ (it ships bamg as /usr/bin/ffbamg)")
    dat = find_airfoil()
    levels = [float(v) for v in (a.levels or ("1" if a.quick else "1,0.5,0.25")).split(",")]
    work = tempfile.mkdtemp(prefix="plaf_bench_fill_")
    try:
        if a.only != "B":
            for level, rows in part_a(plaf, bamg, work, dat, levels, a.repeat):
                print_table(f"A. linear triangles in a background metric, sizes x {level:g} "
                            f"(NACA 0012 in a circle R = 10)", rows, "bamg")
        if a.only != "A":
            rows, factor = part_b(plaf, work, dat, a.quick, a.repeat)
            print_table(f"B. boundary layer + fill at order 3 (NACA 0012, circle R = 20; Gmsh size factor "
                        f"{factor:.3f})", rows, "gmsh")
        print("\nmesh s: plaf's \"mesh\" stage (surface mesh [+ layers] + fill), bamg's \"Cpu time for meshing\", "
              "Gmsh's generate(2) + setOrder(3) [+ optimize('HighOrderElastic') for gmsh+el]; least of --repeat runs.\nwall s: the whole plaf or bamg process (plaf: + reading, "
              "certifying every cell, writing msh + report; bamg: + reading the background, writing); "
              "Gmsh: = mesh s.\nelem/s = elements / mesh s. unit frac, min sJ (scaled Jacobian, 1 for "
              "straight triangles), max AR, invalid: measured by plaf for every mesher;\nmax len: the longest edge in the metric.")
    finally:
        if a.keep:
            print(f"work folder: {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
