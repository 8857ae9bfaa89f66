// SPDX-License-Identifier: MIT
#include "modules/mesh/curve_mesh.h"

#include <doctest/doctest.h>

#include <cmath>

#include "modules/metric/wall_metric.h"

using namespace plaf;
using Eigen::Vector2d;

namespace {

Geometry2D one_loop(SplineLoop loop) {
  Geometry2D g;
  g.loops.push_back({std::move(loop), "wall", BoundaryKind::Wall});
  return g;
}

SplineLoop circle(double r, int n) {
  std::vector<Vector2d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(r * std::cos(-2 * M_PI * i / n), r * std::sin(-2 * M_PI * i / n));
  return SplineLoop(p, {}, "circle");
}

}  // namespace

TEST_CASE("surface: a circle under a uniform metric gets round(2 pi R / h) elements of unit metric length") {
  for (int q = 1; q <= 4; ++q) {
    const double r = 1.0, h = 0.1;
    const UniformMetricField<2> m(Metric<2>::isotropic(h));
    const CurvedFront<2> f = mesh_curves(one_loop(circle(r, 128)), m, q);
    REQUIRE(f.loops.size() == 1);
    CHECK(f.loops[0].size() == static_cast<std::size_t>(std::lround(2 * M_PI * r / h)));  // 63
    CHECK(f.nodes.size() == f.loops[0].size() * q);
    const CurveMeshStats s = curve_mesh_stats(f, one_loop(circle(r, 128)), m);
    CHECK(s.unit_fraction == 1.0);
    CHECK(s.metric_length_min > 0.99);
    CHECK(s.metric_length_max < 1.01);
    // Every node lies on the circle, high-order nodes included.
    for (const Vector2d& p : f.nodes) CHECK(p.norm() == doctest::Approx(r).epsilon(1e-6));
  }
}

TEST_CASE("surface: high-order nodes divide the arc length between linear nodes uniformly") {
  const SplineLoop loop = circle(2.0, 64);
  const UniformMetricField<2> m(Metric<2>::isotropic(0.5));
  const CurvedFront<2> f = mesh_curves(one_loop(loop), m, 3);
  const FrontLoop& l = f.loops[0];
  for (std::size_t e = 0; e < l.size(); ++e) {
    const NodeId* el = f.element(l, e);
    // Gmsh line order: start, end, interior. The arc lengths start-i1, i1-i2, i2-end are equal.
    auto arc = [&](NodeId a, NodeId b) {
      double tb = f.params[b];
      if (tb < f.params[a]) tb += loop.period();
      return loop.arc_length(f.params[a], tb);
    };
    const double a0 = arc(el[0], el[2]), a1 = arc(el[2], el[3]), a2 = arc(el[3], el[1]);
    CHECK(a1 == doctest::Approx(a0).epsilon(1e-10));
    CHECK(a2 == doctest::Approx(a0).epsilon(1e-10));
    CHECK(3 * a0 == doctest::Approx(arc(el[0], el[1])).epsilon(1e-10));
  }
}

TEST_CASE("surface: corners are linear nodes and each side gets its own rounded count") {
  // A 2 x 1 rectangle (clockwise) with h = 0.3: sides of metric length 6.67 and 3.33 -> 7 and 3.
  const SplineLoop rect({{0, 0}, {0, 1}, {2, 1}, {2, 0}}, {0, 1, 2, 3}, "rect");
  const UniformMetricField<2> m(Metric<2>::isotropic(0.3));
  const CurvedFront<2> f = mesh_curves(one_loop(rect), m, 2);
  const FrontLoop& l = f.loops[0];
  CHECK(l.size() == 3 + 7 + 3 + 7);
  int corners = 0;
  for (std::size_t e = 0; e < l.size(); ++e)
    if (l.corner[e]) {
      ++corners;
      const Vector2d p = f.nodes[f.element(l, e)[0]];
      CHECK((std::abs(p.x()) < 1e-14 || std::abs(p.x() - 2) < 1e-14));
      CHECK((std::abs(p.y()) < 1e-14 || std::abs(p.y() - 1) < 1e-14));
    }
  CHECK(corners == 4);
  // A segment shorter than 1/sqrt 2 in the metric still gets one element (and is reported).
  const UniformMetricField<2> coarse(Metric<2>::isotropic(2.0));
  const CurvedFront<2> fc = mesh_curves(one_loop(rect), coarse, 1);
  CHECK(fc.loops[0].size() == 4);
  CHECK(curve_mesh_stats(fc, one_loop(rect), coarse).short_segments == 2);  // the two sides of length 1 (metric 0.5)
}

TEST_CASE("surface: segments are split in log-rounded counts, keeping every element within [1/sqrt 2, sqrt 2]") {
  // Sides of metric length L give n = floor(L) or floor(L) + 1 as L is below or above
  // sqrt(n (n + 1)): L = 1.45 (> sqrt 2) -> 2 elements of 0.725; L = 2.4 (< sqrt 6) -> 2 of 1.2.
  for (const auto& [side, count] : std::vector<std::pair<double, std::size_t>>{{1.45, 2}, {2.4, 2}, {2.5, 3}}) {
    const SplineLoop sq({{0, 0}, {0, side}, {side, side}, {side, 0}}, {0, 1, 2, 3}, "square");
    const UniformMetricField<2> m(Metric<2>::isotropic(1.0));
    const CurvedFront<2> f = mesh_curves(one_loop(sq), m, 1);
    CHECK(f.loops[0].size() == 4 * count);
    const CurveMeshStats s = curve_mesh_stats(f, one_loop(sq), m);
    CHECK(s.unit_fraction == 1.0);
  }
}
