// SPDX-License-Identifier: MIT
// The metric-based advancing front of K. J. Fidkowski's PLAF (Sec. II.C, eq. 1, Fig. 6 and 7):
// fills the region bounded by linear fronts with linear triangles sized by a metric field.
//
// The greedy algorithm, in the metric at each front node:
//  1. the outer angle at every front node is the ellipse angle (eq. 1) between its two front
//     edges: the angle between them after mapping by M^(1/2), the map under which the metric
//     ellipse of the node becomes a circle (tan(theta) = (a/b) tan(phi) along the ellipse's axes);
//  2. the node of minimum outer angle is taken (a heap with lazy deletion);
//  3. the angle is split into n_new + 1 equal sub-angles, n_new = max(0, floor(3 dtheta/pi - 0.5));
//  4. a new point is placed along each inner sub-angle direction at unit metric length (first
//     with the node's metric, then corrected with the metric integrated along the segment);
//  5. an existing front node within `merge_radius` (metric) of a new point replaces it when the
//     triangle it makes is valid (this merges fronts, or splits one); a new point is kept only
//     if it keeps `clearance` (metric) from every front edge;
//  6. the triangles of the fan are formed one at a time, each checked with exact predicates
//     (predicates.h): counter-clockwise, no front edge crossed or touched, no front node inside,
//     inside the free angle at its three corners, and not a sliver (a least shape quality in
//     the metric); then the angle at the node is closed;
//  7. repeat until no front remains.
// Where the greedy step finds no valid triangle for an edge (a narrow gap, a crowded corner),
// the edge takes the front node of the constrained-Delaunay choice in the node's metric (the
// valid apex whose circumcircle reaches least far to the left of the edge); such a node always
// exists while the front bounds a region, so the fill cannot get stuck on a valid front.
//
// All searches go through a loose quadtree of the front edges, updated as the front moves: a
// step costs O(log N + k) for k nearby edges, the fill O(N log N).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"

namespace plaf::volume {

struct AdvancingFrontParams {
  std::size_t max_triangles = 20000000;  // a MesherError beyond this
  double merge_radius = 0.65;            // metric distance to a new point under which a front node replaces it
  double clearance = 0.45;               // least metric distance of a new point to any other front edge
  // Least shape quality 4 sqrt(3) A / sum l^2 (in the metric of the edge's start) of a greedy
  // triangle; the Delaunay fallback goes below it only when no better apex is valid.
  double min_quality = 0.05;
  // Longest metric length (integrated along the edge) of a new edge of a greedy triangle.
  double max_length = 2.0;
};

struct AdvancingFrontStats {
  std::size_t steps = 0;            // front nodes taken (the greedy loop)
  std::size_t new_points = 0;
  std::size_t merges = 0;           // an existing front node used instead of a new point
  std::size_t delaunay_apexes = 0;  // edges closed by the constrained-Delaunay fallback
  std::size_t max_front = 0;        // largest number of front edges at once
};

// The fill (linear_front.h's FillResult: the input nodes, same ids, then the new ones; the
// triangles counter-clockwise) and what it did.
struct AdvancingFrontResult : FillResult<2> {
  AdvancingFrontStats stats;
};

// Fills the region of `front` (linear_front.h: its loops' orientation, simplicity and node
// numbering; the result's nodes are front.nodes, same ids, then the new ones). Throws MesherError when the loops cross or touch, are oriented
// so that they bound no region, or the fill exceeds max_triangles.
AdvancingFrontResult advancing_front_fill(const LinearFront<2>& front, const MetricField<2>& metric,
                                          const AdvancingFrontParams& params = {});

}  // namespace plaf::volume
