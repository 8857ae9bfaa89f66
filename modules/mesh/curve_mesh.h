// SPDX-License-Identifier: MIT
// The metric-conforming high-order surface mesh of 2D loops (paper Sec. II.B, first paragraph):
// "The location of linear (Q = 1) nodes along the spline is determined by equidistribution of
// metric-based length along the spline. High-order nodes are then added by uniformly subdividing
// the arc-length distance between adjacent linear nodes. Corner nodes are constrained to be
// Q = 1 nodes."
// On each corner-to-corner segment of a loop (the whole loop if it has no corner), the number of
// elements is the metric length L of the segment rounded in log space (n or n + 1 as L is below
// or above sqrt(n (n + 1)), at least 1), so every element of a segment with L >= 1/sqrt 2 has a
// metric length in [1/sqrt 2, sqrt 2].
#pragma once

#include <string>
#include <vector>

#include "modules/mesh/curved_front.h"
#include "modules/geometry/geometry2d.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace mesh {

CurvedFront<2> mesh_curves(const Geometry2D& geometry, const MetricField<2>& metric, int order);

struct CurveLoopStats {
  std::string tag;
  std::size_t elements = 0, nodes = 0;
  double metric_length_min = 0, metric_length_max = 0;
};

struct CurveMeshStats {
  std::vector<CurveLoopStats> loops;
  double metric_length_min = 0, metric_length_max = 0;
  double unit_fraction = 0;        // elements with metric length in [1/sqrt 2, sqrt 2]
  std::size_t short_segments = 0;  // corner-to-corner segments shorter than 1/sqrt 2 in the metric
};

// Metric lengths of the surface elements along the geometry's splines (what the surface mesh
// equidistributed). Measuring the order-Q Lagrange edges instead would add their tangent
// deviation from the spline, which a boundary-layer metric (normal size h0 ~ 1e-5 at the wall)
// weighs heavily: that is the curved edge's interpolation error, not the spacing.
CurveMeshStats curve_mesh_stats(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric);

}  // namespace mesh
}  // namespace plaf
