# SPDX-License-Identifier: MIT
"""Helpers shared by the sphere benchmarks (bench_prisms.py, bench_volume.py): the layers'
cumulative heights, a timed child process with its peak memory, and Gmsh's exact sphere."""

import os
import subprocess
import time


def heights(h0, g, n):
    """Cumulative heights of n geometric layers h0 g^k (Gmsh's extrudeBoundaryLayer input)."""
    out, s = [], 0.0
    for k in range(n):
        s += h0 * g ** k
        out.append(s)
    return out


def run_process(cmd, work):
    """Runs cmd (output to files in work); returns (exit code, stderr, wall s, peak RSS MiB)."""
    out_path, err_path = os.path.join(work, "stdout.txt"), os.path.join(work, "stderr.txt")
    with open(out_path, "w") as out, open(err_path, "w") as err:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=out, stderr=err)
        # wait4 reaps the child with its own resource usage (ru_maxrss in KiB on Linux).
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
    return os.waitstatus_to_exitcode(status), open(err_path).read(), wall, usage.ru_maxrss / 1024.0


def gmsh_sphere(gmsh, h, r=1.0):
    """A sphere of radius r at the origin in Gmsh's built-in kernel: 8 octant patches, size h."""
    geo = gmsh.model.geo
    c = geo.addPoint(0, 0, 0, h)
    px, py, pz, mx, my, mz = [geo.addPoint(r * x, r * y, r * z, h) for x, y, z in
                              [(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0), (0, 0, -1)]]
    arcs = {}
    for p, q in [(px, py), (py, mx), (mx, my), (my, px), (px, pz), (pz, mx), (mx, mz), (mz, px),
                 (py, pz), (pz, my), (my, mz), (mz, py)]:
        arcs[(p, q)] = geo.addCircleArc(p, c, q)

    def edge(p, q):
        return arcs[(p, q)] if (p, q) in arcs else -arcs[(q, p)]

    patches = []
    for p, q, d in [(px, py, pz), (py, mx, pz), (mx, my, pz), (my, px, pz),
                    (py, px, mz), (mx, py, mz), (my, mx, mz), (px, my, mz)]:
        loop = geo.addCurveLoop([edge(p, q), edge(q, d), edge(d, p)])
        patches.append(geo.addSurfaceFilling([loop], sphereCenterTag=c))
    return patches
