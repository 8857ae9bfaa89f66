// SPDX-License-Identifier: MIT
// The 2D layers' collision test: the new front of a loop may cross neither another loop's front
// nor itself. Fronts are compared as the polylines through all their nodes (linear and
// high-order), with exact predicates (predicates.h): rounding never hides a crossing nor invents
// one.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/curved_front.h"

namespace plaf::layers {

// One segment of a front's polyline, with the index of the front element it belongs to.
struct FrontSegment {
  Eigen::Vector2d a, b;
  std::size_t element;
  std::size_t index;  // position along its polyline
  bool mine;          // on the new front being checked (else an obstacle)
};

// Appends the polyline of loop l (order q, nodes x) to out.
void append_polyline(const FrontLoop& l, const std::vector<Eigen::Vector2d>& x, int q, bool mine,
                     std::vector<FrontSegment>& out);

// Elements of the new front (the `mine` segments, mine_count of them, first in segs) that cross
// an obstacle segment or a non-adjacent segment of the new front itself: a sweep over x,
// O((n + k) log n). Sorted, unique.
std::vector<std::size_t> front_crossings(std::vector<FrontSegment> segs, std::size_t mine_count);

}  // namespace plaf::layers
