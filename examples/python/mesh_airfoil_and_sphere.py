#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""plaf from Python: a NACA 0012 (2D, order 3, layers and an advancing-front fill) and a sphere
(3D, order 2, prism layers and a TetGen fill), each meshed in memory, written as MSH 4.1 and CGNS,
and the airfoil drawn with matplotlib when it is installed.

    PYTHONPATH=build/python python3 examples/python/mesh_airfoil_and_sphere.py [OUT_DIR]
(after `cmake --install`, plaf is on the interpreter's path and PYTHONPATH is not needed)
"""
import os
import sys

import plaf

out = sys.argv[1] if len(sys.argv) > 1 else "out/python_example"
os.makedirs(out, exist_ok=True)

airfoil = {
    "name": "naca0012",
    "order": 3,
    "geometry": {"type": "airfoils", "bodies": [{"naca": {"digits": "0012", "trailing_edge": "sharp"}}],
                 "farfield": {"shape": "circle", "radius": 20}},
    "metric": {"type": "wall_power_law", "h0": 0.002, "growth": 1.2, "h_max": 2.0, "h_wall_max": 0.04,
               "curvature_factor": 0.3, "h_corner": 0.005},
    "layers": {"max": 40, "stop_when_linear": True},
    "fill": {},
}
sphere = {
    "name": "sphere",
    "order": 2,
    "geometry": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
    "metric": {"type": "wall_power_law", "h0": 1e-4, "growth": 1.25, "h_max": 5.0, "h_wall_max": 0.3},
    "layers": {"type": "extrude", "max": 30, "isotropic_stop": "all"},
    "fill": {"type": "tetgen", "farfield": {"shape": "sphere", "radius": 20}},
}

for config in (airfoil, sphere):
    m = plaf.run(config)
    r = m.report
    print(f"{m!r}: valid {m.ok}, min scaled Jacobian {r['scaled_jacobian']['min']:.3g}, "
          f"cells {r['cells']['by_type']}")
    for name, blocks in m.boundary.items():
        print(f"  boundary {name}: " + ", ".join(f"{len(a)} {t}" for t, a in blocks.items()))
    m.write(os.path.join(out, config["name"] + ".msh"), binary=True)
    m.write(os.path.join(out, config["name"] + ".cgns"))
    if config is airfoil:
        airfoil_mesh = m

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no picture")
    sys.exit(0)

# Each cell's boundary through its vertices (corner nodes come first in Gmsh's order); the curved
# edges are drawn straight here (plaf's own NAME.png draws them curved).
fig, ax = plt.subplots(figsize=(8, 5))
xy = airfoil_mesh.points[:, :2]
for key, cells in airfoil_mesh.cells.items():
    corners = 4 if key.startswith("quadrilateral") else 3
    for c in cells:
        ring = list(c[:corners]) + [c[0]]
        ax.plot(xy[ring, 0], xy[ring, 1], lw=0.3, color="tab:blue" if corners == 4 else "tab:orange")
ax.set_xlim(-0.1, 1.1)
ax.set_ylim(-0.3, 0.3)
ax.set_aspect("equal")
ax.set_title("NACA 0012, order 3: layers (blue) and fill (orange)")
fig.savefig(os.path.join(out, "naca0012.png"), dpi=150)
print("picture:", os.path.join(out, "naca0012.png"))
