#!/usr/bin/env python3
"""Benchmark: reading + validating + remeshing a 100k-triangle surface, plaf against Gmsh.

Input: a smooth, closed, genus-0 "bumpy sphere" written here as a binary STL of 99,372 triangles
(the cube-sphere of 6 x 91 x 91 quads, each split in two, on the radial surface
r(x) = 1 + 0.08 sin(5 x) sin(4 y) sin(3 z) for unit directions x; no numpy needed).

Target: isotropic size h (default 0.012, about the input's own resolution, so the output has
~100k triangles too; --h to change it).

  - plaf: `plaf run` of a surface_file config (order 1, metric uniform h, 8 remeshing rounds,
    no curvature metric, formats msh + report). Its report's timings give the stages: geometry
    (= STL read + welding + validation incl. the self-intersection test + feature detection +
    the discrete reference's AABB tree) and remesh. The whole process time is measured too.
  - Gmsh (python3-gmsh, in this same process, 1 thread): merge the STL, classifySurfaces(40 deg,
    boundary, forReparametrization), createGeometry, Mesh.MeshSizeMin = MeshSizeMax = h,
    Mesh.Algorithm = 6 (Frontal-Delaunay), generate(2). Its read (merge) and remesh
    (classify + createGeometry + generate) are timed separately. Gmsh does no orientation,
    volume or self-intersection check.

Both outputs are measured here the same way: triangles, the fraction of edges with length in
[h/sqrt 2, h sqrt 2], the smallest angle, the largest distance of a vertex from the exact
bumpy surface (radial residual), and the fidelity: the largest radial gap sampled inside every
triangle, which bounds the two-sided (Hausdorff) distance to the exact surface (issue 13). plaf's
own report's fidelity (against the STL) is printed too.

Run by hand:  /usr/bin/python3 bench/bench_surface.py [--h 0.012] [--plaf build/apps/plaf]
Prints one table and the ratios plaf / Gmsh for the same run.
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time


def radius(d):
    return 1 + 0.08 * math.sin(5 * d[0]) * math.sin(4 * d[1]) * math.sin(3 * d[2])


def cube_sphere_stl(path, n):
    """6 n^2 quads of the cube [-1,1]^3, mapped radially to the bumpy surface, outward."""
    faces = []
    # (axis, sign): the face normal; u, v span it counter-clockwise seen from outside.
    for axis in range(3):
        for sign in (-1, 1):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            if sign < 0:
                a, b = b, a
            grid = []
            for i in range(n + 1):
                row = []
                for j in range(n + 1):
                    p = [0.0, 0.0, 0.0]
                    p[axis] = sign
                    p[a] = -1 + 2 * i / n
                    p[b] = -1 + 2 * j / n
                    norm = math.sqrt(sum(c * c for c in p))
                    d = [c / norm for c in p]
                    r = radius(d)
                    row.append(tuple(r * c for c in d))
                grid.append(row)
            for i in range(n):
                for j in range(n):
                    p00, p10, p11, p01 = grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]
                    faces.append((p00, p10, p11))
                    faces.append((p00, p11, p01))
    with open(path, "wb") as f:
        f.write(b"bench_surface bumpy sphere".ljust(80, b" "))
        f.write(struct.pack("<I", len(faces)))
        for t in faces:
            f.write(struct.pack("<3f", 0, 0, 0))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")
    return len(faces)


def read_msh_triangles(path):
    """Vertices (by tag) and linear triangles of an MSH 4.1 ASCII file (first 3 nodes of any
    triangle type)."""
    lines = open(path).read().split("\n")
    i = lines.index("$Nodes")
    blocks = int(lines[i + 1].split()[0])
    k = i + 2
    nodes = {}
    for _ in range(blocks):
        _, _, _, n = map(int, lines[k].split())
        k += 1
        tags = [int(lines[k + j]) for j in range(n)]
        k += n
        for j in range(n):
            nodes[tags[j]] = tuple(map(float, lines[k + j].split()[:3]))
        k += n
    i = lines.index("$Elements")
    blocks = int(lines[i + 1].split()[0])
    k = i + 2
    tris = []
    triangle_types = {2, 9, 21, 23}
    for _ in range(blocks):
        _, _, typ, n = map(int, lines[k].split())
        k += 1
        if typ in triangle_types:
            for j in range(n):
                tris.append(tuple(map(int, lines[k + j].split()[1:4])))
        k += n
    return nodes, tris


def measure(nodes, tris, h):
    edges = set()
    min_angle = 180.0
    for t in tris:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges.add((min(a, b), max(a, b)))
        p = [nodes[x] for x in t]
        for q in range(3):
            u = [p[(q + 1) % 3][c] - p[q][c] for c in range(3)]
            w = [p[(q + 2) % 3][c] - p[q][c] for c in range(3)]
            nu, nw = math.sqrt(sum(c * c for c in u)), math.sqrt(sum(c * c for c in w))
            if nu > 0 and nw > 0:
                cosang = max(-1.0, min(1.0, sum(u[c] * w[c] for c in range(3)) / (nu * nw)))
                min_angle = min(min_angle, math.degrees(math.acos(cosang)))
            else:
                min_angle = 0.0
    unit = 0
    for a, b in edges:
        l = math.dist(nodes[a], nodes[b]) / h
        if 1 / math.sqrt(2) <= l <= math.sqrt(2):
            unit += 1
    used = {x for t in tris for x in t}
    dev = 0.0
    for x in used:
        p = nodes[x]
        r = math.sqrt(sum(c * c for c in p))
        d = [c / r for c in p]
        dev = max(dev, abs(r - radius(d)))
    # Fidelity, the same way for both meshes: the surface is a radial graph r = radius(d), so the
    # two-sided (Hausdorff) distance between it and a star-shaped mesh is at most the largest
    # radial gap |r - radius(d)| over the mesh's points; sampled on a barycentric lattice of
    # 15 points per triangle (k = 4), inside the triangles and not only at vertices.
    gap = 0.0
    k = 4
    for t in tris:
        a, b, c = (nodes[x] for x in t)
        for i in range(k + 1):
            for j in range(k + 1 - i):
                u, v = i / k, j / k
                p = [a[q] + u * (b[q] - a[q]) + v * (c[q] - a[q]) for q in range(3)]
                r = math.sqrt(sum(q * q for q in p))
                gap = max(gap, abs(r - radius([q / r for q in p])))
    return {"triangles": len(tris), "unit": unit / max(1, len(edges)), "min_angle": min_angle, "deviation": dev,
            "gap": gap}


def run_plaf(exe, stl, h, work):
    cfg = os.path.join(work, "bumpy.yaml")
    with open(cfg, "w") as f:
        f.write(f"name: bumpy\norder: 1\ngeometry:\n  type: surface_file\n  file: {stl}\n"
                f"metric: {{type: uniform, h: {h}}}\nsurface: {{iterations: 8}}\n"
                f"output: {{formats: [msh, report], msh: ascii}}\n")
    t0 = time.perf_counter()
    r = subprocess.run([exe, "run", cfg, "--out", work], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit("plaf failed:\n" + r.stderr)
    rep = json.load(open(os.path.join(work, "bumpy.report.json")))
    t = rep["timings_s"]
    nodes, tris = read_msh_triangles(os.path.join(work, "bumpy.msh"))
    m = measure(nodes, tris, h)
    m.update(read=t["geometry"], remesh=t["surface"], total=wall)  # surface: remesh + order-Q nodes + fidelity
    m["plaf_fidelity"] = rep["surface"]["fidelity"]
    return m


def run_gmsh(stl, h, work):
    import gmsh
    gmsh.initialize(["", "-v", "0"])
    gmsh.option.setNumber("General.NumThreads", 1)
    t0 = time.perf_counter()
    gmsh.merge(stl)
    t1 = time.perf_counter()
    gmsh.model.mesh.classifySurfaces(40 * math.pi / 180, True, True)
    gmsh.model.mesh.createGeometry()
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.model.mesh.generate(2)
    t2 = time.perf_counter()
    out = os.path.join(work, "gmsh.msh")
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.write(out)
    gmsh.finalize()
    nodes, tris = read_msh_triangles(out)
    m = measure(nodes, tris, h)
    m.update(read=t1 - t0, remesh=t2 - t1, total=t2 - t0)
    return m


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--h", type=float, default=0.012)
    ap.add_argument("--n", type=int, default=91, help="cube-sphere quads per face edge (91: 99,372 triangles)")
    ap.add_argument("--plaf", default=os.path.join(os.path.dirname(__file__), "..", "build", "apps", "plaf"))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as work:
        stl = os.path.join(work, "bumpy.stl")
        n = cube_sphere_stl(stl, a.n)
        print(f"input: {n} triangles (binary STL), target size h = {a.h}")
        p = run_plaf(os.path.abspath(a.plaf), stl, a.h, work)
        g = run_gmsh(stl, a.h, work)
        diag = 2 * 1.08 * math.sqrt(3)  # the bumpy sphere's bounding-box diagonal, at most
        print(f"{'mesher':8} {'tris':>8} {'read+check s':>13} {'remesh s':>9} {'total s':>8} {'unit frac':>9} "
              f"{'min angle':>9} {'max dev':>9} {'fidelity':>9} {'/diag':>8}")
        for name, m in (("plaf", p), ("gmsh", g)):
            print(f"{name:8} {m['triangles']:8d} {m['read']:13.3f} {m['remesh']:9.3f} {m['total']:8.3f} "
                  f"{m['unit']:9.3f} {m['min_angle']:9.2f} {m['deviation']:9.2e} {m['gap']:9.2e} {m['gap'] / diag:8.1e}")
        f = p["plaf_fidelity"]
        print(f"max dev: vertices' radial residual; fidelity: largest radial gap sampled inside the triangles "
              f"(bounds the two-sided distance). plaf's own report (against the STL input): Hausdorff "
              f"{f['hausdorff']:.2e}, {f['relative']:.1e} of its diagonal")
        print(f"ratios plaf/gmsh: read+check {p['read'] / g['read']:.2f}, remesh {p['remesh'] / g['remesh']:.2f}, "
              f"total {p['total'] / g['total']:.2f}, triangles/s "
              f"{(p['triangles'] / p['total']) / (g['triangles'] / g['total']):.2f}")


if __name__ == "__main__":
    main()
