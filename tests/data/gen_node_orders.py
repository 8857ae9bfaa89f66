#!/usr/bin/env python3
"""Writes node_orders.txt: reference coordinates of every node of every Lagrange cell plaf uses,
in Gmsh's order (from Gmsh's own API) and in VTK's order (from VTK's own cells), mapped to plaf's
reference cells (lagrange.h). Run by hand with Debian's python3-gmsh and python3-vtk9:
    /usr/bin/python3 tests/data/gen_node_orders.py > tests/data/node_orders.txt
The unit tests compare plaf's orders with this table."""
import gmsh
import vtk

GMSH = {  # (plaf name, order): gmsh type
    ("line", 1): 1, ("line", 2): 8, ("line", 3): 26, ("line", 4): 27,
    ("triangle", 1): 2, ("triangle", 2): 9, ("triangle", 3): 21, ("triangle", 4): 23,
    ("quadrilateral", 1): 3, ("quadrilateral", 2): 10, ("quadrilateral", 3): 36, ("quadrilateral", 4): 37,
    ("tetrahedron", 1): 4, ("tetrahedron", 2): 11, ("tetrahedron", 3): 29, ("tetrahedron", 4): 30,
    ("prism", 1): 6, ("prism", 2): 13, ("prism", 3): 90, ("prism", 4): 91,
}
VTK = {"line": vtk.vtkLagrangeCurve, "triangle": vtk.vtkLagrangeTriangle,
       "quadrilateral": vtk.vtkLagrangeQuadrilateral, "tetrahedron": vtk.vtkLagrangeTetra,
       "prism": vtk.vtkLagrangeWedge}


def to_plaf(name, x):
    # Gmsh: line and quad on [-1,1], prism w on [-1,1]; VTK uses [0,1] everywhere.
    if name in ("line", "quadrilateral"):
        return [(c + 1) / 2 for c in x]
    if name == "prism":
        return [x[0], x[1], (x[2] + 1) / 2]
    return x


def n_nodes(name, q):
    return {"line": q + 1, "triangle": (q + 1) * (q + 2) // 2, "quadrilateral": (q + 1) ** 2,
            "tetrahedron": (q + 1) * (q + 2) * (q + 3) // 6, "prism": (q + 1) ** 2 * (q + 2) // 2}[name]


def gmsh_prism(q):
    """Gmsh 4.8 cannot report order-3/4 prism properties, so mesh the reference prism (unit
    right triangle x [0,1]) as one element at order q and read its node coordinates."""
    gmsh.model.add(f"prism{q}")
    geo = gmsh.model.geo
    p = [geo.addPoint(0, 0, 0, 10), geo.addPoint(1, 0, 0, 10), geo.addPoint(0, 1, 0, 10)]
    lines = [geo.addLine(p[0], p[1]), geo.addLine(p[1], p[2]), geo.addLine(p[2], p[0])]
    for ln in lines:
        geo.mesh.setTransfiniteCurve(ln, 2)
    s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    geo.extrude([(2, s)], 0, 0, 1, [1], recombine=True)
    geo.synchronize()
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(q)
    types, tags, nodes = gmsh.model.mesh.getElements(3)
    assert len(tags) == 1 and len(tags[0]) == 1
    return types[0], [list(gmsh.model.mesh.getNode(k)[0]) for k in nodes[0]]


gmsh.initialize()
gmsh.option.setNumber("General.Verbosity", 0)
dims = {"line": 1, "triangle": 2, "quadrilateral": 2, "tetrahedron": 3, "prism": 3}
for (name, q) in GMSH:
    if name == "prism":
        t, pts = gmsh_prism(q)
        nn = len(pts)
    else:
        t = gmsh.model.mesh.getElementType({"quadrilateral": "Quadrangle"}.get(name, name.capitalize()), q)
        ename, dim, order, nn, coords, _ = gmsh.model.mesh.getElementProperties(t)
        pts = [to_plaf(name, list(coords[i * dim:(i + 1) * dim])) for i in range(nn)]
    assert nn == n_nodes(name, q), (name, q)
    print(f"gmsh {name} {q} {t} {nn} " + " ".join(" ".join(f"{round(c * q)}" for c in p) for p in pts))
gmsh.finalize()

for (name, q) in GMSH:
    cell = VTK[name]()
    n = n_nodes(name, q)
    cell.GetPointIds().SetNumberOfIds(n)
    cell.GetPoints().SetNumberOfPoints(n)
    for i in range(n):
        cell.GetPointIds().SetId(i, i)
    if name == "quadrilateral":
        cell.SetOrder(q, q)
    elif name == "prism":
        cell.SetOrder(q, q, q, n)
    cell.Initialize()
    pc = cell.GetParametricCoords()
    dim = dims[name]
    pts = [[pc[3 * i + d] for d in range(dim)] for i in range(n)]
    print(f"vtk {name} {q} {cell.GetCellType()} {n} " + " ".join(" ".join(f"{round(c * q)}" for c in p) for p in pts))
