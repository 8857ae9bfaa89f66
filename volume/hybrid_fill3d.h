// SPDX-License-Identifier: MIT
// The 3D fill of the domain around prism layers (issue 15): the layers' linear outer front, a
// farfield (farfield3d.h) and, on each symmetry plane the layers stand on, the plane's region
// between the farfield's cut and the layers' rim, filled with TetGen's tetrahedra
// (tetgen_fill.h). What the `tetgen` fill plugin runs (plugins.h).
//
//  1. The layers' outer front must be linear (their closing layer makes it so when it can) and
//     all triangles (grow_layers_3d.h).
//  2. Symmetry planes: the layer mesh's boundary tags of kind symmetry, each on an axis-aligned
//     plane (their facets' nodes fitted); the outer front's open edges (its rim) must lie on
//     them. The farfield is then a box cut to the bodies' side of every plane.
//  3. Each plane's region (the farfield's cut loop outside, the rim loops inside) is meshed with
//     the 2D advancing front (advancing_front_2d.h) in the plane's coordinates, sized by a graded
//     isotropic field: from each loop node's mean edge length, growing by `grading` per unit
//     distance, at most the farfield's h. Its triangles carry the plane's tag.
//  4. TetGen fills the region with the front preserved (no Steiner point on any of it), one hole
//     point inside the layers of every connected outer front (the centroid of a prism under one
//     of its triangles), and sizes (switch m): at a node of the front its mean edge length.
#pragma once

#include <functional>
#include <optional>

#include <string>
#include <vector>

#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"
#include "volume/farfield3d.h"
#include "volume/tetgen_fill.h"

namespace plaf::volume {

struct HybridFillParams {
  FarfieldParams3 farfield;  // h = 0: the metric's largest size at the farfield, at most a quarter of its extent
  TetFillParams tet;         // node_sizes are set here
  double grading = 0.25;     // growth of the symmetry planes' sizes per unit distance from their loops
  // Called once the farfield is built, before the planes and TetGen mesh anything, with the
  // tetrahedra predicted inside it (6 sqrt 2 per unit of the integral of 1/h^3, h the metric's
  // largest size: TetGen's tetrahedra are isotropic; the bodies' and layers' volume is not taken
  // out, so an upper estimate); may throw to stop the run (the size budget, budget.h).
  std::function<void(double tetrahedra)> size_check;
};

struct HybridFill {
  FillResult<3> fill;  // boundary: the farfield's and the planes' triangles, tagged
  TetFillStats stats;
  FarfieldParams3 farfield;  // as resolved (h, cuts)
  std::size_t farfield_triangles = 0, plane_triangles = 0, holes = 0;
};

// Throws MesherError when the outer front is curved or holds quadrilaterals, a symmetry plane is
// not axis-aligned, a rim edge lies on no plane, or a fill fails; ConfigError (naming the key)
// for a farfield that cannot enclose the layers.
// A vertex of the first outer-front triangle still curved (the fill needs a linear front: a part
// whose closing layer failed, layers.events), or none.
std::optional<Eigen::Vector3d> curved_outer_point(const LayerResult<3>& layers);

HybridFill fill_around_layers(const LayerResult<3>& layers, const MetricField<3>& metric, const HybridFillParams& params);

}  // namespace plaf::volume
