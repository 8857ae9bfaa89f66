// SPDX-License-Identifier: MIT
#include "modules/metric/wall_metric.h"

#include <doctest/doctest.h>

#include <cmath>

#include "modules/geometry/geometry2d.h"

using namespace plaf;
using Eigen::Vector2d;

namespace {

// The square [-1,1]^2 as a clockwise body loop with its 4 corners: straight sides, so wall
// distances are exact.
SplineLoop square_body() {
  std::vector<Vector2d> p = {{-1, -1}, {-1, 1}, {1, 1}, {1, -1}};
  return SplineLoop(p, {0, 1, 2, 3}, "square");
}

WallLawParams params() {
  WallLawParams w;
  w.h0 = 1e-3;
  w.growth = 1.2;
  w.h_max = 0.5;
  w.h_wall_max = 0.05;
  w.h_corner = 0.01;
  return w;
}

}  // namespace

TEST_CASE("wall metric: the linear law gives h0 + (g-1) d normal to the wall, hence layers h0 g^k") {
  const WallPowerLawField f({square_body()}, params());
  for (double d : {0.0, 1e-4, 1e-3, 0.01, 0.1, 0.5}) {
    // Below the middle of the bottom side: the closest wall point is (0, -1), the normal -y.
    const Vector2d x(0.0, -1.0 - d);
    const auto s = f.sizes(x);
    CHECK(s.distance == doctest::Approx(d).scale(1.0).epsilon(1e-12));
    CHECK(s.normal == doctest::Approx(std::min(1e-3 + 0.2 * d, 0.5)).epsilon(1e-12));
    CHECK(s.normal_direction.y() == doctest::Approx(-1.0));
    const Metric<2> m = f.evaluate(x);
    CHECK(m.size_along(Vector2d(0, 1)) == doctest::Approx(s.normal).epsilon(1e-10));
    CHECK(m.size_along(Vector2d(1, 0)) == doctest::Approx(s.tangential).epsilon(1e-10));
  }
  // Layer k starts at d_k = h0 (g^k - 1)/(g - 1) and has height h0 g^k (geometric layers).
  for (int k = 0; k < 30; ++k) {
    const double dk = 1e-3 * (std::pow(1.2, k) - 1) / 0.2;
    if (1e-3 * std::pow(1.2, k) > 0.5) break;
    CHECK(f.normal_size(dk) == doctest::Approx(1e-3 * std::pow(1.2, k)).epsilon(1e-12));
  }
}

TEST_CASE("wall metric: the exponential law with growth distance delta is h0 g^(d/delta)") {
  WallLawParams w = params();
  w.exponential = true;
  w.delta = 0.004;
  const WallPowerLawField f({square_body()}, w);
  for (double d : {0.0, 0.002, 0.01, 0.03})
    CHECK(f.sizes(Vector2d(0.0, -1.0 - d)).normal ==
          doctest::Approx(std::min(1e-3 * std::pow(1.2, d / 0.004), 0.5)).epsilon(1e-12));
}

TEST_CASE("wall metric: tangential size from curvature, corners and the far-field cap") {
  const WallPowerLawField f({square_body()}, params());
  // Mid-side: straight wall (R infinite) at distance 1 from the corners: min(h_wall_max, h_corner + 0.2).
  CHECK(f.sizes(Vector2d(0.0, -1.0)).tangential == doctest::Approx(0.05));
  // Near a corner, along the wall at distance s = 0.05 from it: h_corner + (g - 1) s.
  CHECK(f.sizes(Vector2d(0.95, -1.0)).tangential == doctest::Approx(0.01 + 0.2 * 0.05));
  // Far away: isotropic h_max.
  const Metric<2> far = f.evaluate(Vector2d(0.0, -30.0));
  CHECK(far.min_size() == doctest::Approx(0.5));
  CHECK(far.max_size() == doctest::Approx(0.5));
  // A circle of radius 0.1 (clockwise body): h_par = min(h_wall_max, c R) = 0.25 * 0.1, up to the
  // spline's curvature error, second order in the spacing: (2 pi / 256)^2 = 6e-4 at most.
  std::vector<Vector2d> c;
  for (int i = 0; i < 256; ++i) c.emplace_back(0.1 * std::cos(-2 * M_PI * i / 256), 0.1 * std::sin(-2 * M_PI * i / 256));
  const WallPowerLawField fc({SplineLoop(c, {}, "circle")}, params());
  CHECK(fc.sizes(Vector2d(0.1, 0.0)).tangential == doctest::Approx(0.025).epsilon(6e-4));
}

TEST_CASE("wall metric: a point a rounding error off a curved wall keeps the wall's directions") {
  // Regression: x - p of ~1e-12 (the closest point's own rounding) once set the "normal".
  std::vector<Vector2d> c;
  for (int i = 0; i < 64; ++i) c.emplace_back(std::cos(-2 * M_PI * i / 64), 0.3 * std::sin(-2 * M_PI * i / 64));
  const SplineLoop loop(c, {}, "ellipse");
  const WallPowerLawField f({loop}, params());
  for (double t = 0.05; t < 64; t += 0.37)
    for (double eps : {0.0, 3e-12, -3e-12, 1e-9}) {
      const Vector2d x = loop.point(t) + eps * loop.tangent(t) + std::abs(eps) * loop.normal(t);
      const auto s = f.sizes(x);
      CHECK(f.evaluate(x).size_along(loop.tangent(t)) == doctest::Approx(s.tangential).epsilon(1e-6));
      CHECK(std::abs(s.normal_direction.dot(loop.normal(t))) == doctest::Approx(1.0).epsilon(1e-9));
    }
}
