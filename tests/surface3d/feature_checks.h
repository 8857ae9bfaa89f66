// SPDX-License-Identifier: MIT
// Feature assertions shared by the surface3d suites (doctest CHECKs). Header-only; include it as
// "tests/surface3d/feature_checks.h".
#pragma once

#include <doctest/doctest.h>

#include "modules/geometry/tri_surface.h"
#include "surface3d/features.h"

namespace plaf::test {

// The features a box's surface must carry, whoever set them (make_box, detect_features, or the
// remesher keeping them): its 12 edges as convex ridge curves, each open between two of its 8
// vertices, which are convex corners; nothing concave, no boundary, no other corner.
inline void check_box_features(const TriSurface& s) {
  const FeatureReport r = count_features(s);
  CHECK(r.curves == 12);
  CHECK(r.corners_convex == 8);
  CHECK(r.corners_concave + r.corners_saddle + r.corners_boundary == 0);
  CHECK(r.ridges_concave == 0);
  CHECK(r.boundary_edges == 0);
  const auto curves = feature_curves(s);
  REQUIRE(curves.size() == 12);
  for (const auto& path : curves) {
    REQUIRE(path.size() >= 2);
    CHECK(path.front() != path.back());
    CHECK(s.mesh.property(s.vertex_feature, path.front()) == VertexFeature::ConvexCorner);
    CHECK(s.mesh.property(s.vertex_feature, path.back()) == VertexFeature::ConvexCorner);
  }
}

}  // namespace plaf::test
