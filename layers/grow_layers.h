// SPDX-License-Identifier: MIT
// Implements the prismatic layers of K. J. Fidkowski, "Anisotropic Metric-Based Curved Meshing
// Using Prismatic Layers" (PLAF), Sec. II.A-B, Fig. 4 and 5, in 2D: curved quadrilaterals of
// order Q grown layer by layer along the normals of a curved front.
//
// One layer, for every body loop of the front:
//  1. normals at every node, linear and high-order: the spline normal on the first layer, the
//     average of the adjacent panel normals afterwards (Sec. II.B);
//  2. corners by the turning angle at linear nodes: a right turn (convex) beyond the threshold
//     gets a fan of extra normals dividing the corner angle, each pair of adjacent normals
//     bounding one element whose outer edges come from intersecting perpendiculars at the normal
//     end points, high-order nodes uniform in the bilinear quad (Fig. 4); a left turn (concave)
//     gets the merged normal described in grow_layers.cpp;
//  3. heights: the metric's size along the normal, h = 1/sqrt(n^T M n), at the front node (or the
//     distance to unit metric length along the normal); high-order nodes uniform along it;
//  4. curvature attenuation (Fig. 5): the new front's high-order nodes move toward their linear
//     positions by at most f_atten times the local height; the displacement is propagated
//     linearly into the element; a front is linear when no move was clipped;
//  5. every new element is certified (validity.h), and the new front may cross neither another
//     loop's front nor itself (a collision, found by a sweep over x); where either fails the
//     layer is shrunk there (heights halved) and retried, and a loop that still fails stops
//     growing (reported in LayerResult::events).
// A straight element, and any element next to a concave corner, grows a straight top.
#pragma once

#include <string>
#include <vector>

#include "modules/mesh/front.h"
#include "modules/geometry/geometry2d.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"

namespace plaf::layers {

struct LayerParams {
  int max_layers = 24;
  bool stop_when_linear = false;
  double f_atten = 0.2;
  double corner_angle_deg = 30.0;  // |turning angle| above which a linear node is a corner
  double fan_angle_deg = 45.0;     // largest angle between adjacent normals of a convex fan
  bool integrate_height = false;   // unit metric length along the normal instead of the size
  bool smooth_normals = false;     // one Laplacian pass over the normals of each new layer
  // Where the metric is isotropic at a front node (a layer would be as tall as the metric's size
  // in every direction): stop that node alone ("node"; its elements stay in the front, and
  // transition triangles join them to the moving neighbours), stop the loop when it is so at
  // every node ("all") or at any node ("any"), or never ("off").
  std::string isotropic_stop = "off";
  int shrink_attempts = 4;
  // End with a linear front (for the fill): a loop whose front is still curved when it stops
  // gets a closing layer with straight tops (see grow_layers.cpp).
  bool close_linear = false;
};

struct LayerStats {
  int layer = 0;                     // 1-based
  std::size_t cells = 0;             // quadrilaterals
  std::size_t transition_cells = 0;  // triangles next to stopped nodes (isotropic_stop: node)
  double max_clipped_rel = 0;        // largest attenuation move still needed / height (0 if linear)
  bool linear = false;               // the new front is linear
  std::size_t shrinks = 0;           // invalid cells and front crossings that made heights halve
  std::size_t first_cell = 0;        // this layer's cells in LayerResult::mesh block order
};

struct LayerResult {
  HybridMesh<2> mesh;    // quadrilaterals (block 0) and transition triangles (block 1, if any) of
                         // order Q; boundary: the wall loops (the caller tags the outer front)
  CurvedFront<2> outer;  // the outermost front (same orientation as the input loops)
  std::vector<LayerStats> layers;
  int linear_after = -1;            // 1-based index of the first layer with a linear front, -1 if none
  std::vector<std::string> events;  // what stopped or shrank growth, one line each
};

// Curvature attenuation of one new front element (Fig. 5): moves the interior top nodes
// tops[1..Q-1] toward their linear positions a + (k/Q)(b - a) by at most f_atten * heights[k].
// Returns the largest needed move over its height among the clipped nodes (0 when none was
// clipped, i.e. the element is now linear).
double attenuate(std::vector<Eigen::Vector2d>& tops, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const std::vector<double>& heights, double f_atten);

// Grows layers from the wall loops of `front` (loops of kind Wall); other loops are ignored.
LayerResult grow_layers(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric,
                        const LayerParams& params);

}  // namespace plaf::layers
