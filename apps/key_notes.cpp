// SPDX-License-Identifier: MIT
// A line of description per configuration key (keys.h): the one place keys are described; the
// headers of the parsers point here. Types, defaults, ranges, allowed words and the types that
// read a key come from the parsers (recorded, apps/keys.cpp); a note gives a default only where
// the recorded one says less than the truth (computed from other keys, or the key is required).
// The order of the sections is the reference's reading order.
#include "apps/keys.h"

namespace plaf {

const std::vector<KeyNote>& key_notes() {
  static const std::vector<KeyNote> notes = {
      // ---- the run's own values (modules/pipeline/run_config.h)
      {"name", "output base name: NAME.msh, NAME.vtu, NAME.report.json, NAME.png", "the config file's stem", true},
      {"order", "geometry order Q of the curved cells (surface, layers; the fill too with output.uniform_order)"},

      // ---- geometry: what to mesh (the type decides the run's dimension)
      {"geometry", "what to mesh; `type:` chooses the plugin, a 3D type makes a 3D run"},
      {"geometry.type", "the geometry plugin: 2D annulus or airfoils (spline loops), 3D analytic bodies or a surface file"},
      // annulus (modules/mesh/annulus.h)
      {"geometry.r_inner", "annulus: inner radius (the wall)"},
      {"geometry.r_outer", "annulus: outer radius (the farfield), larger than r_inner"},
      {"geometry.angle_deg", "annulus: sector angle in degrees (360: the full annulus; a sector's sides are tagged side)"},
      {"geometry.cells", "annulus: quadrilaterals, or each split into two triangles"},
      // airfoils (modules/geometry/geometry2d.h)
      {"geometry.bodies", "airfoils: the bodies, one map each: file, naca or circle; name, corners", "required"},
      {"geometry.bodies[].file", "a Selig or Lednicer coordinate file (airfoil_io.h); sharp or blunt trailing edges",
       "one of file, naca, circle"},
      {"geometry.bodies[].circle", "a circle instead of a file: a periodic spline through 256 points, no corner"},
      {"geometry.bodies[].circle.center", "the circle's centre [x, y]"},
      {"geometry.bodies[].circle.radius", "the circle's radius", "required"},
      {"geometry.bodies[].name", "the body's boundary tag (not farfield)", "wall, wall_2, ..."},
      {"geometry.bodies[].corners", "extra corners: the contour points nearest these [x, y]"},
      {"geometry.corner_angle_deg",
       "airfoils: turning angle above which a contour point is a corner; wing: the same for the section's points"},
      {"geometry.farfield", "airfoils: the farfield loop around the bodies"},
      {"geometry.farfield.shape", "a circle or an axis-aligned rectangle"},
      {"geometry.farfield.radius", "the circle's radius"},
      {"geometry.farfield.size", "the rectangle's width and height [w, h]"},
      {"geometry.farfield.center", "the farfield's centre [x, y]", "the bodies' bounding-box centre"},
      // a NACA section, wherever an airfoil file is (modules/pipeline/naca_config.h)
      {"geometry.naca",
       "a generated NACA 4- or 5-digit section instead of a file: its designation, quoted (\"0012\"), or a map "
       "(digits, trailing_edge, intervals)"},
      {"geometry.naca.digits", "the designation, 4 or 5 digits, quoted so YAML keeps the leading zeros", "required"},
      {"geometry.naca.trailing_edge", "closed (sharp, a4 = -0.1036) or the standard open (blunt) trailing edge"},
      {"geometry.naca.intervals", "cosine-spaced intervals per surface"},
      // 3D bodies (surface3d/plugins.h)
      {"geometry.center", "sphere, ellipsoid: the centre [x, y, z]"},
      {"geometry.radius", "sphere: the radius"},
      {"geometry.semi_axes", "ellipsoid: the semi-axes [a, b, c] along x, y, z"},
      {"geometry.lo", "box: the lowest corner [x, y, z]"},
      {"geometry.hi", "box: the highest corner [x, y, z], above lo in every coordinate"},
      {"geometry.file",
       "wing: the section's airfoil file (Selig or Lednicer); surface_file: a .stl .obj .off .ply (triangulated) "
       "or .fmt .p3d (Plot3D) surface",
       "required (wing: file or naca)"},
      {"geometry.chord", "wing: the chord"},
      {"geometry.span", "wing: the span, along +z from z = 0"},
      {"geometry.root", "wing: the end at z = 0 (symmetry: open, on the plane z = 0)"},
      {"geometry.tip", "wing: the end at z = span"},
      {"geometry.weld_rel", "surface_file: merge points closer than this times the bounding-box diagonal"},
      {"geometry.symmetry_planes", "surface_file: planes on which open boundaries are allowed, tagged symmetry"},
      {"geometry.symmetry_planes[].normal", "the plane's normal [nx, ny, nz]", "required"},
      {"geometry.symmetry_planes[].offset", "the plane is normal . x = offset"},
      {"geometry.self_intersections",
       "surface_file: repair (folded sliver caps behind crossing pairs get their long edge flipped, then check), "
       "check (any crossing pair is an error) or skip (not tested)"},
      {"geometry.slivers",
       "surface_file: repair (a CAD tessellation's needles and caps thinner than 1e-3 of their longest edge, lying "
       "in the surface around them, get their short edge collapsed or long edge flipped, with a repair line saying "
       "how far the surface moved; slivers.h) or keep"},
      {"geometry.inner_components",
       "surface_file: bodies nested inside another (the flow never meets them) are dropped with a repair line, or "
       "an error"},
      {"geometry.reference",
       "surface_file: what nodes are projected onto: the flat facets, or smooth cubic patches through the vertices "
       "with the feature curves kept sharp (smooth_reference.h; not yet the default: slow and folding on the pyHyp "
       "BWB)"},

      // ---- metric (modules/metric/metric_fields.h, wall_metric.h, wall_metric_3d.h)
      {"metric", "the metric field the meshes follow; `type:` chooses the plugin"},
      {"metric.type", "uniform (one metric everywhere), wall_power_law (the paper's eq. 6 boundary-layer metric) or "
                      "background (a metric on a background mesh)"},
      {"metric.h", "uniform: the isotropic size (give h or sizes)"},
      {"metric.sizes", "uniform: anisotropic sizes [h1, h2] (2D, h1 at angle_deg from x) or [hx, hy, hz] (3D)",
       "none (isotropic h)"},
      {"metric.angle_deg", "uniform, 2D: the direction of h1 from the x axis, in degrees"},
      {"metric.file",
       "background: an ASCII Gmsh MSH 4.1 .msh with a tensor $NodeData view, or a libMeshb .mesh, of the run's dimension",
       "required"},
      {"metric.sol", "background: the .sol of a .mesh file (required with a .mesh)"},
      {"metric.mean", "background: how the metric is interpolated between the nodes"},
      {"metric.h0", "wall_power_law: the first layer's height at the wall"},
      {"metric.growth", "wall_power_law: the layers' growth factor g (> 1): layer k is h0 g^k thick"},
      {"metric.law", "wall_power_law: h_perp = h0 + (g - 1) d (geometric layers), or h0 g^(d/delta) (eq. 6 as printed)"},
      {"metric.delta", "wall_power_law: the exponential law's growth distance", "h0", true},
      {"metric.h_max", "wall_power_law: the isotropic size far from the walls; every size is capped by it"},
      {"metric.h_wall_max", "wall_power_law: the largest size along a wall"},
      {"metric.curvature_factor",
       "wall_power_law, 2D: size along a wall = this x its radius of curvature (3D: surface.curvature_factor)"},
      {"metric.h_corner",
       "wall_power_law, 2D: size along a wall at a corner, growing by g away from it (3D: the surface keeps "
       "ridges and corners)"},
      {"metric.intersect",
       "further metric sections, each with its own type and keys: the run's metric is their intersection with "
       "this one (the smallest size any asks for, along every direction)"},
      {"metric.intersect[].type", "the item's metric plugin; its keys are those of a metric section", "required"},

      // ---- surface (3D: surface3d/plugins.h)
      {"surface", "3D only: the surface mesh: features, remeshing to the metric, order-Q nodes, each triangle certified"},
      {"surface.type", "the surface plugin"},
      {"surface.ridge_angle_deg", "dihedral deviation in degrees above which an edge is a ridge"},
      {"surface.corner_defect_deg", "angle defect in degrees above which a vertex is a cone corner"},
      {"surface.curve_turn_deg", "turn in degrees of a feature curve that makes a corner"},
      {"surface.remesh", "remesh to the metric (false: the input's triangles, curved)"},
      {"surface.iterations", "remeshing rounds"},
      {"surface.curvature_factor",
       "sizes at most this x the radius of curvature, and at most the size whose order-Q chord error is half of "
       "fidelity_tol (curvature_metric.h; 0: off)"},
      {"surface.curvature_h_min", "the smallest size curvature asks for, below the metric's smallest size",
       "the metric's size / 20"},
      {"surface.max_triangles", "give up (an error) beyond this many triangles"},
      {"surface.fidelity_tol",
       "the run fails when the surface's two-sided distance to the body exceeds this x the body's bounding-box "
       "diagonal (fidelity.h)"},
      {"surface.fidelity_rounds",
       "while over fidelity_tol, remesh at finer sizes around the samples farther than half of it (and at half the "
       "sizes where remeshed faces still cross each other), at most this many times"},
      {"surface.gradation",
       "how fast curvature sizes may grow between neighbours (graded_metric.h: beta, > 1; 0: off)"},
      {"surface.min_scaled_jacobian",
       "a curved triangle below it has its high-order nodes pulled toward its flat triangle until it reaches it"},

      // ---- extrude (modules/mesh/extrude_front.h)
      {"extrude",
       "a 2D section (geometry airfoils) extruded between the symmetry planes z = 0 and z = span: the run is 3D, "
       "geometry and metric are the section's, layers and fill the 3D stages"},
      {"extrude.span", "the planes' distance", "required"},
      {"extrude.rows", "rows of order-Q triangles along z (even: a station at mid-span, where the layer table measures)"},
      {"extrude.hz", "the metric's size along z", "the section metric's largest size at (x, y)"},

      // ---- layers (layers/plugins.h)
      {"layers", "prismatic layers grown from the walls (quadrilaterals in 2D, prisms in 3D); absent: none"},
      {"layers.type", "the layer plugin: extrude grows them, none grows none"},
      {"layers.max", "the number of layers (0: none, the surface mesh alone)"},
      {"layers.stop_when_linear", "stop after the first linear front"},
      {"layers.f_atten", "curvature attenuation fraction per layer (the paper's Fig. 5)"},
      {"layers.corner_angle_deg", "turning angle in degrees of a front corner (convex: a fan; concave: merged normals)"},
      {"layers.fan_angle_deg", "the largest angle between a fan's normals, in degrees"},
      {"layers.fan_fades",
       "3D: a ridge's fan may end where the ridge fades (a trailing edge into a rounded tip); false: that ridge "
       "keeps one merged normal along its length"},
      {"layers.height", "a layer's height: the metric's size along the normal, or a unit metric length"},
      {"layers.smooth_normals",
       "smooth the columns' directions of each layer (2D: one Laplacian pass; 3D: relaxed toward the neighbours' "
       "after the first layer)"},
      {"layers.isotropic_stop",
       "stop a node's column where the metric is isotropic there (node), or the loop when it is so at any or all "
       "nodes",
       "3D: node; 2D: all with stop_when_linear, else off"},
      {"layers.min_coverage",
       "the share of the wall whose columns must reach their stop rule; below it (or with the first layer over 4 x "
       "the metric's height on 1 % of the columns) the run fails, exit 2"},
      {"layers.local_stops",
       "3D: where a cell cannot be valid even at 1/16 of the metric's height, stop its columns there and grow the "
       "rest (false: stop the whole surface, as 2D does)"},
      {"layers.proximity",
       "3D: the share of its half of the gap to a facing wall a column's stack may fill (0: off)"},
      {"layers.high_order_heights",
       "a high-order node's height: its own metric height, or its element's vertex heights interpolated (default: "
       "the layer core's choice, interpolated in 2D and 3D)"},

      // ---- fill (volume/plugins.h)
      {"fill", "the domain between the layers' outer front (or the surface mesh) and the farfield, in linear cells; "
               "absent: none"},
      {"fill.type", "advancing_front: 2D, the metric advancing front; tetgen: 3D, TetGen's tetrahedra (needs layers)"},
      {"fill.max_triangles", "advancing_front: give up (an error) beyond this many triangles"},
      {"fill.optimize_passes", "rounds of metric optimisation after the fill, the fronts kept (0: none)"},
      {"fill.max_radius_edge", "tetgen: TetGen's quality bound q, 0 (off) or at least 1.1"},
      {"fill.max_volume", "tetgen: no tetrahedron larger (TetGen's switch a, kept by the optimiser; 0: none)"},
      {"fill.farfield", "tetgen: the farfield around the layers (a box when there are symmetry planes)"},
      {"fill.farfield.shape", "a sphere or an axis-aligned box"},
      {"fill.farfield.radius", "the sphere's radius (0: 10 x the layers' bounding-box diagonal)"},
      {"fill.farfield.size", "the box's edge lengths [a, b, c] (0: 20 x that diagonal)"},
      {"fill.farfield.center", "the farfield's centre [x, y, z]", "the layers' bounding-box centre"},
      {"fill.farfield.h",
       "the farfield's triangle size (0: the metric's largest size there, at most a quarter of the radius or half "
       "the size)"},

      // ---- limits (modules/pipeline/budget.h)
      {"limits",
       "the size budget: each stage predicts its element count from the metric and stops with an error naming "
       "the key to raise beyond these (defaults fit a 24 GB, 2-core machine)"},
      {"limits.surface_elements", "curve elements (2D) or surface triangles (3D)"},
      {"limits.cells", "cells of the mesh (layers and fill)"},
      {"limits.nodes", "nodes of the mesh, high-order ones too"},

      // ---- validity (modules/elements/validity.h)
      {"validity", "the certification of the curved cells (Bezier bounds of det J)"},
      {"validity.rel_tol", "the Bezier bounds are refined until within this share"},
      {"validity.max_depth", "the subdivision depth limit"},

      // ---- output (modules/pipeline/run_config.h, modules/io/picture3d.h)
      {"output", "what is written, and the pictures"},
      {"output.dir", "the output folder, relative to the working directory, not the config's folder (plaf run --out wins)"},
      {"output.formats", "the files written: NAME.msh (Gmsh 4.1), NAME_msh22.msh (Gmsh 2.2: msh22), NAME.cgns (CGNS: cgns), NAME.vtu "
       "(VTK Lagrange cells), NAME.report.json, NAME.png"},
      {"output.msh",
       "the .msh encoding (4.1 and 2.2): ascii, binary (several times smaller and faster), or auto: binary above "
       "100000 nodes"},
      {"output.vtu",
       "the .vtu encoding: ascii, binary (zlib-compressed appended data, as ParaView writes), or auto: binary "
       "above 100000 nodes"},
      {"output.histogram_bins", "bins of the report's metric edge-length histogram"},
      {"output.picture_width", "the PNG's width in pixels"},
      {"output.picture_height", "the PNG's height in pixels"},
      {"output.cut", "3D: the plane of the picture's cut (default: the first symmetry plane, else the bounding box's "
                     "mid-plane across its shortest side)"},
      {"output.cut.point", "a point of the plane [x, y, z]"},
      {"output.cut.normal", "the plane's normal [x, y, z]"},
      {"output.cuts", "3D: more cut planes, a picture each (NAME.cut<k>.png), needs png in formats"},
      {"output.cuts[].point", "a point of the plane [x, y, z]", "required"},
      {"output.cuts[].normal", "the plane's normal [x, y, z]", "required"},
      {"output.cuts[].radius", "a zoom panel of this half-width around the point (0: none)"},
      {"output.cuts[].label", "the picture's title"},
      {"output.view", "3D: the shaded view of the outer front looks along this [x, y, z]"},
      {"output.uniform_order",
       "2D: the fill's triangles written at order Q (straight sided, edges shared with the layers' cells), so the "
       "mesh has one order"},
      {"output.split_quads",
       "2D: each layer quadrilateral split into two triangles in reference space along its shorter diagonal (the "
       "paper's Fig. 12)"},
      {"output.zooms", "inset panels of the picture"},
      {"output.zooms[].label", "the panel's title"},
      {"output.zooms[].box", "[x_min, x_max, y_min, y_max] (3D: in the cut plane's (u, v), picture3d.h)", "required"},

      // ---- a study file (apps/study.h)
      {"study:name", "output base name", "the file's stem", true},
      {"study:order", "the runs' order Q"},
      {"study:f_atten", "the f_atten sweep, each in (0, 1]"},
      {"study:h0_factors", "the h0 sweep: factors of each case's h0"},
      {"study:cases", "the cases, each a 2D section with its 3D partners", "required"},
      {"study:cases[].name", "the case's name", "required"},
      {"study:cases[].geometry", "the 2D section: a run configuration's geometry section of type airfoils", "required"},
      {"study:cases[].metric", "a run configuration's metric section of type wall_power_law (h0 is swept)", "required"},
      {"study:cases[].layers", "a run configuration's layers section (f_atten is swept)", "required"},
      {"study:cases[].extrude", "the extrusion partner: a run configuration's extrude section"},
      {"study:cases[].sphere", "the sphere partner (a section of one circle body)"},
      {"study:cases[].h0_factors", "this case's h0 sweep", "the study's h0_factors", true},
      {"study:cases[].output", "the case's pictures"},
      {"study:cases[].output.zooms", "zoom boxes as output.zooms, in (x, y) (the 3D cut's (u, v))"},
  };
  return notes;
}

}  // namespace plaf
