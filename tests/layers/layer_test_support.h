// SPDX-License-Identifier: MIT
// Geometry helpers shared by the layer suites. Header-only; include it as
// "tests/layers/layer_test_support.h".
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "modules/geometry/geometry2d.h"

namespace plaf::test {

// A geometry of one wall loop tagged "wall" through `points` (clockwise: the domain outside),
// with corners at the given point indices.
inline Geometry2D body(std::vector<Eigen::Vector2d> points, std::vector<int> corners) {
  Geometry2D g;
  g.loops.push_back({SplineLoop(std::move(points), std::move(corners), "body"), "wall", BoundaryKind::Wall});
  return g;
}

}  // namespace plaf::test
