// SPDX-License-Identifier: MIT
// The 3D fill of the domain around prism layers (issue 15): the layers' linear outer front, a
// farfield (farfield3d.h) and, on each symmetry plane the layers stand on, the plane's region
// between the farfield's cut and the layers' rim, filled with TetGen's tetrahedra
// (tetgen_fill.h). What the `tetgen` fill plugin runs (plugins.h).
//
//  1. The layers' outer front must be all triangles (grow_layers_3d.h). TetGen meets its chords
//     (the vertices); where it is still curved (a part whose closing layer failed: columns that
//     stopped curved, layers.events) the tetrahedra on it take its curved triangles in the
//     assembly (assemble_hybrid_3d keeps the outer front's nodes), so the mesh stays conforming,
//     and the quality stage certifies them as every cell. The paper fills from a linear front
//     (Sec. II.C); a curved face under an isotropic tetrahedron as tall as its edges is the robust
//     choice where no straight closing cell is valid. In the assembly the fill bends with it
//     (modules/mesh/bend_fill3d.h), a tetrahedron still inverted is untangled by its nodes and
//     points off the boundary (modules/mesh/untangle3d.h); one that stays inverted fails the run.
//  2. Symmetry planes: the layer mesh's boundary tags of kind symmetry, each on an axis-aligned
//     plane (their facets' nodes fitted); the outer front's open edges (its rim) must lie on
//     them. The farfield is then a box cut to the bodies' side of every plane.
//  3. Each plane's region (the farfield's cut loop outside, the rim loops inside) is meshed with
//     the 2D advancing front (advancing_front_2d.h) in the plane's coordinates, in the run's
//     metric restricted to the plane, intersected with a graded isotropic field: from each loop
//     node's mean edge length, growing by `grading` per unit distance, at most the farfield's h
//     (so the triangles start at the loops' sizes and follow the metric, anisotropic where it
//     is, away from them). Its triangles carry the plane's tag.
//  4. TetGen fills the region with the front preserved (no Steiner point on any of it), one hole
//     point inside the layers of every connected outer front (the centroid of a prism under one
//     of its triangles), and sizes (switch m): at a node of the front its mean edge length.
//  5. The fill is optimised in the run's metric (optimize_3d.h: splits, collapses, swaps and
//     moves toward unit edges, TetGen's slivers swapped away), every front frozen but the
//     symmetry planes' own nodes (inside their loops), which slide within their plane.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"
#include "volume/farfield3d.h"
#include "volume/optimize_3d.h"
#include "volume/tetgen_fill.h"

namespace plaf::volume {

// The edge of a regular tetrahedron of this volume: the longest farfield edge (fill.farfield.h)
// whose tetrahedra can stay within fill.max_volume.
inline double largest_edge_within(double volume) { return std::cbrt(6 * std::sqrt(2.0) * volume); }

struct HybridFillParams {
  FarfieldParams3 farfield;  // h = 0: the metric's largest size at the farfield, at most a quarter of its extent
  TetFillParams tet;         // node_sizes are set here
  Optimize3Params optimize;  // step 5
  double grading = 0.25;     // growth of the symmetry planes' sizes per unit distance from their loops
  // Called once the farfield is built, before the planes and TetGen mesh anything, with the
  // tetrahedra predicted inside it (6 sqrt 2 per unit of the integral of 1/h^3, h the metric's
  // largest size, at most the farfield's h and within tet.max_volume: TetGen's
  // tetrahedra are isotropic and sized from the boundary's edges; the bodies' and layers' volume
  // is not taken out, so an upper estimate); may throw to stop the run (the size budget, budget.h).
  std::function<void(double tetrahedra)> size_check;
  // Told the share of the fill done and what, after TetGen and after each optimisation pass (the
  // run's progress; the shares measured on the sphere and wing configs). May be empty.
  std::function<void(double fraction, const std::string& what)> progress;
};

// The size ratio across the layers' outer front: per outer triangle, the height of the fill's
// tetrahedron on it over the height of the layer cell under it; its median, 95th percentile and
// largest over the triangles that have both.
struct FrontRatio {
  std::size_t triangles = 0;
  double p50 = 0, p95 = 0, max = 0;
};

struct HybridFill {
  FillResult<3> fill;  // boundary: the farfield's and the planes' triangles, tagged
  TetFillStats stats;       // TetGen's tetrahedra, before step 5
  Optimize3Stats optimize;  // step 5
  FrontRatio front_ratio_before, front_ratio_after;  // TetGen's, and after step 5
  FarfieldParams3 farfield;  // as resolved (h, cuts)
  std::size_t farfield_triangles = 0, plane_triangles = 0, holes = 0;
  std::size_t curved_front_triangles = 0;  // step 1: the outer front's triangles still curved
};

// Throws MesherError when the outer front holds quadrilaterals, a symmetry plane is
// not axis-aligned, a rim edge lies on no plane, or a fill fails; ConfigError (naming the key)
// for a farfield that cannot enclose the layers.
HybridFill fill_around_layers(const LayerResult<3>& layers, const MetricField<3>& metric, const HybridFillParams& params);

}  // namespace plaf::volume
