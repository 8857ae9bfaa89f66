#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes bands/sphere_wake.mesh and .sol: a background metric with a thin wake sheet behind the
unit sphere, for the anisotropic fill case (configs/sphere_wake_hybrid.yaml, issue 32). The run
intersects it with the sphere's wall law (`metric: {intersect: [...]}`), so this field need only
say where the sheet is; everywhere else it asks for nothing finer than the wall law.

The sheet: the slab x in [3, 13], y in [-3, 3], |z| <= 0.15 (2 radii behind the sphere, beyond
its layers, which end near r = 1.7), with sizes 0.5 along x and y and 0.025 across (20:1).
Off the slab every size grows with the distance d to it, h + 0.25 d (a size gradation of 0.25,
the wall law's own), so the field is continuous and the fill can grade into the sheet.

The background mesh: a tensor grid over the box [-21, 21]^3 (the sphere's farfield, radius 20,
inside it), its lines at the slab's faces and graded away from them, each hexahedron cut into
six tetrahedra around its main diagonal (conforming across faces), the metric at every node.
libMeshb ASCII (as MMG reads it): `.mesh` with Dimension 3, Vertices and Tetrahedra; `.sol`
with SolAtVertices, one field of type 3 (a symmetric matrix, xx xy yy xz yz zz). Generated, no
source: MIT like the code.

Usage: python3 data/make_wake_band.py [output.mesh]  (default: bands/sphere_wake.mesh beside this
script; the .sol goes beside the .mesh, with the same name).
"""
import os
import sys

SLAB_LO = (3.0, -3.0, -0.15)
SLAB_HI = (13.0, 3.0, 0.15)
SIZE_ALONG = 0.5   # along x and y in the slab
SIZE_ACROSS = 0.025  # along z in the slab
GRADATION = 0.25

# Grid lines: the slab's faces, and lines graded away from them to the box.
XS = [-21, -6, 0, 2, 2.6, 3, 8, 13, 13.4, 14, 16, 21]
YS = [-21, -10, -6, -4, -3.4, -3, 0, 3, 3.4, 4, 6, 10, 21]
ZS = [-21, -7, -3, -1.5, -0.8, -0.45, -0.25, -0.15, 0, 0.15, 0.25, 0.45, 0.8, 1.5, 3, 7, 21]


def slab_distance(p):
    d2 = 0.0
    for k in range(3):
        gap = max(SLAB_LO[k] - p[k], 0.0, p[k] - SLAB_HI[k])
        d2 += gap * gap
    return d2 ** 0.5


def metric(p):
    """The diagonal of the metric at p: 1 / h^2 along x, y, z."""
    d = slab_distance(p)
    along = SIZE_ALONG + GRADATION * d
    across = SIZE_ACROSS + GRADATION * d
    return (1 / along ** 2, 1 / along ** 2, 1 / across ** 2)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    mesh = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "bands", "sphere_wake.mesh")
    stem = os.path.splitext(mesh)[0]
    os.makedirs(os.path.dirname(os.path.abspath(stem)), exist_ok=True)
    nx, ny, nz = len(XS), len(YS), len(ZS)

    def node(i, j, k):  # 1-based, x fastest
        return 1 + i + nx * (j + ny * k)

    points = [(x, y, z) for z in ZS for y in YS for x in XS]
    tets = []
    # The six tetrahedra of a cube around its diagonal 0 -> 7 (corner c = i + 2 j + 4 k): the
    # paths 0 -> 7 through the cube's edges, one per order of the three axes.
    paths = [(1, 2, 4), (1, 4, 2), (2, 1, 4), (2, 4, 1), (4, 1, 2), (4, 2, 1)]
    for k in range(nz - 1):
        for j in range(ny - 1):
            for i in range(nx - 1):
                corner = [node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)) for c in range(8)]
                for a, b, _ in paths:
                    t = [corner[0], corner[a], corner[a | b], corner[7]]
                    # Positive volume: the path's axes in a right-handed order keep the orientation.
                    right = (a, b) in ((1, 2), (2, 4), (4, 1))
                    if not right:
                        t[1], t[2] = t[2], t[1]
                    tets.append(t)
    with open(stem + ".mesh", "w") as f:
        f.write("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n%d\n" % len(points))
        for p in points:
            f.write("%g %g %g 0\n" % p)
        f.write("\nTetrahedra\n%d\n" % len(tets))
        for t in tets:
            f.write("%d %d %d %d 0\n" % tuple(t))
        f.write("\nEnd\n")
    with open(stem + ".sol", "w") as f:
        f.write("MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n%d\n1 3\n" % len(points))
        for p in points:
            mx, my, mz = metric(p)
            f.write("%.6g 0 %.6g 0 0 %.6g\n" % (mx, my, mz))
        f.write("\nEnd\n")


if __name__ == "__main__":
    main()
