#!/usr/bin/env python3
"""CAD parts as a user exports them, for the 3D sweep (bench/sweep_3d.py --body): Gmsh's
OpenCASCADE kernel builds each solid and tessellates it to an STL (curvature-sized triangles,
sharp edges where the solid has them), so the layers meet what machined and assembled bodies
bring -- circular convex rims, bores, fillets, junctions, a transom -- on bodies none of plaf's
tests were tuned on:

  cylinder   a post, radius 0.5, height 1: two circular convex ridges of 90 degrees
  flange     a disk (radius 2, 0.4 thick) with a hub (radius 0.8 to z = 1), a bore of 0.5 and
             six bolt holes of 0.15: convex rims, concave bores, a concave step
  car        a box 4 x 1.6 x 1 with every edge filleted at 0.25, on four cylindrical legs
             (radius 0.15): flat-ended legs, concave junctions under the body
  wingbody   a fuselage (cylinder, hemispherical nose, tapered tail cone) through a swept,
             tapered NACA 0012 wing (chord 1.6 at the root, 0.6 at the flat tips, span 6,
             sharp trailing edge): wing-body junctions, tip caps
  hull       half an ellipsoid hull (3 x 0.6 x 0.5) cut by a flat transom (x = 2.4) and a deck
             (y = 0.3), the half model open on z = 0 (its plane of symmetry)

    python3 bench/cad_bodies.py --out DIR [--gmsh gmsh]

writes DIR/NAME.geo and DIR/NAME.stl and prints the sweep's arguments, e.g.

    python3 bench/sweep_3d.py $(python3 bench/cad_bodies.py --out cad) --h0 1e-5 --orders 2 [--fill]

Needs Gmsh built with OpenCASCADE (Debian's gmsh is); exits 77 without it.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

HEADER = 'SetFactory("OpenCASCADE");\n'


def mesh_options(size):
    # Curvature-sized triangles (20 per 2 pi), at most size / 40, Gmsh's Frontal-Delaunay.
    return (f"Mesh.MeshSizeFromCurvature = 20;\nMesh.MeshSizeMax = {size / 40:g};\n"
            f"Mesh.MeshSizeMin = {size / 2000:g};\nMesh.Algorithm = 6;\n")


def naca0012_section(first_point, first_curve, chord, x0, y, z0, n=30):
    """A closed NACA 0012 section in the plane y: two splines (upper, lower) meeting at the
    leading edge and at the sharp trailing edge, and a wire of the two."""
    def half_thickness(x):
        return 5 * 0.12 * (0.2969 * math.sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x ** 3 - 0.1036 * x ** 4)
    xs = [0.5 * (1 - math.cos(math.pi * i / n)) for i in range(n + 1)]
    points = [(x, half_thickness(x)) for x in reversed(xs)] + [(x, -half_thickness(x)) for x in xs[1:-1]]
    lines, ids = [], []
    for k, (x, t) in enumerate(points):
        ids.append(first_point + k)
        lines.append(f"Point({first_point + k}) = {{{x0 + chord * x:.12g}, {y:.12g}, {z0 + chord * t:.12g}}};")
    upper, lower = ids[:n + 1], ids[n:] + [ids[0]]
    c = first_curve
    lines.append(f"Spline({c}) = {{{', '.join(map(str, upper))}}};")
    lines.append(f"Spline({c + 1}) = {{{', '.join(map(str, lower))}}};")
    lines.append(f"Wire({c}) = {{{c}, {c + 1}}};")
    return "\n".join(lines) + "\n"


def bodies():
    out = {}
    out["cylinder"] = (HEADER + "Cylinder(1) = {0, 0, 0, 0, 0, 1, 0.5};\n" + mesh_options(2.0), False, None)
    out["flange"] = (HEADER + "Cylinder(1) = {0, 0, 0, 0, 0, 0.4, 2};\nCylinder(2) = {0, 0, 0, 0, 0, 1, 0.8};\n"
                     "BooleanUnion(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};\n"
                     "Cylinder(4) = {0, 0, -1, 0, 0, 3, 0.5};\n"
                     "For k In {0:5}\n  Cylinder(10 + k) = {1.4 * Cos(k * Pi / 3), 1.4 * Sin(k * Pi / 3), -1, 0, 0, 3, 0.15};\n"
                     "EndFor\nBooleanDifference{Volume{3}; Delete;}{Volume{4, 10:15}; Delete;}\n" + mesh_options(4.0),
                     False, None)
    out["car"] = (HEADER + "Box(1) = {-2, -0.8, 0.5, 4, 1.6, 1};\nedges() = Abs(Curve{:});\nFillet{1}{edges()}{0.25}\n"
                  "Cylinder(10) = {-1.4, -0.5, 0, 0, 0, 0.6, 0.15};\nCylinder(11) = {-1.4, 0.5, 0, 0, 0, 0.6, 0.15};\n"
                  "Cylinder(12) = {1.4, -0.5, 0, 0, 0, 0.6, 0.15};\nCylinder(13) = {1.4, 0.5, 0, 0, 0, 0.6, 0.15};\n"
                  "v() = Volume{:};\nBooleanUnion{Volume{v(0)}; Delete;}{Volume{v({1:#v() - 1})}; Delete;}\n"
                  + mesh_options(4.0), False, None)
    out["wingbody"] = (HEADER + "Cylinder(1) = {-3, 0, 0, 6, 0, 0, 0.5};\nSphere(2) = {-3, 0, 0, 0.5};\n"
                       "Cone(3) = {3, 0, 0, 1.5, 0, 0, 0.5, 0.1};\n"
                       + naca0012_section(100, 100, 1.6, -0.8, 0.0, -0.15)
                       + naca0012_section(200, 110, 0.6, 0.4, 3.0, 0.05)
                       + naca0012_section(300, 120, 0.6, 0.4, -3.0, 0.05)
                       + "ThruSections(10) = {100, 110};\nThruSections(11) = {100, 120};\n"
                       "BooleanUnion{Volume{1}; Delete;}{Volume{2, 3, 10, 11}; Delete;}\n" + mesh_options(6.0),
                       False, None)
    # The hull's facets on z = 0 (the cut) are dropped from the STL: a half model on its plane.
    out["hull"] = (HEADER + "Sphere(1) = {0, 0, 0, 1};\nDilate{{0, 0, 0}, {3, 0.6, 0.5}}{Volume{1};}\n"
                   "Box(2) = {-4, -1, 0, 6.4, 1.3, 1};\nBooleanIntersection(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};\n"
                   + mesh_options(6.0), True, "z0")
    return out


def drop_plane_facets(path):
    """Removes the ASCII STL's facets with all three vertices on z = 0."""
    with open(path) as f:
        lines = f.read().split("\n")
    out, i = [], 0
    while i < len(lines):
        if lines[i].strip().startswith("facet"):
            block = lines[i:i + 7]
            i += 7
            zs = [float(l.split()[3]) for l in block if l.strip().startswith("vertex")]
            if len(zs) == 3 and all(abs(z) < 1e-9 for z in zs):
                continue
            out += block
        else:
            out.append(lines[i])
            i += 1
    with open(path, "w") as f:
        f.write("\n".join(out))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="cad_bodies")
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--only", default="", help="comma-separated bodies")
    args = ap.parse_args()
    if shutil.which(args.gmsh) is None:
        print(f"cad_bodies: {args.gmsh} not found: the parts are tessellated by Gmsh", file=sys.stderr)
        return 77
    os.makedirs(args.out, exist_ok=True)
    only = [b for b in args.only.split(",") if b]
    spec = []
    for name, (geo, half, plane) in bodies().items():
        if only and name not in only:
            continue
        geo_path = os.path.join(args.out, name + ".geo")
        stl = os.path.abspath(os.path.join(args.out, name + ".stl"))
        with open(geo_path, "w") as f:
            f.write(geo)
        r = subprocess.run([args.gmsh, geo_path, "-2", "-format", "stl", "-o", stl], capture_output=True, text=True)
        if r.returncode != 0 or not os.path.isfile(stl):
            print(f"cad_bodies: gmsh failed on {geo_path}:\n{r.stdout[-2000:]}{r.stderr[-2000:]}", file=sys.stderr)
            return 1
        if plane == "z0":
            drop_plane_facets(stl)
        spec.append(f"--body {name}={stl}{':half' if half else ''}")
    print(" ".join(spec))
    return 0


if __name__ == "__main__":
    sys.exit(main())
