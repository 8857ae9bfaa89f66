// SPDX-License-Identifier: MIT
// The 3D wall law (wall_metric_3d.h) on exact references (surface3d/analytic.h): the normal size
// h0 + (g - 1) d of DESIGN.md's eq. (6) discussion along the wall normal, the radial direction as
// the smallest size's, the sizes along the wall, isotropic h_max far away, scale invariance.
#include "modules/metric/wall_metric_3d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "tests/published_data.h"

using namespace plaf;
using Eigen::Vector3d;

namespace {

// h0 = 1e-3, g = 1.2, h_wall_max = 0.05, h_max = 0.5: h_perp reaches h_wall_max at
// d = (0.05 - 1e-3) / 0.2 = 0.245 and h_max at d = (0.5 - 1e-3) / 0.2 = 2.495.
WallLawParams params(double scale = 1) {
  WallLawParams w;
  w.h0 = 1e-3 * scale;
  w.growth = 1.2;
  w.delta = w.h0;
  w.h_max = 0.5 * scale;
  w.h_wall_max = 0.05 * scale;
  return w;
}

// The law of DESIGN.md (eq. (6) discussion): h0 + (g - 1) d, capped at h_max.
double law(double d, double scale = 1) { return std::min(1e-3 * scale + 0.2 * d, 0.5 * scale); }
// Sizes along the wall: h_wall_max, never below the normal size, capped at h_max.
double law_tangential(double d, double scale = 1) {
  return std::min(0.5 * scale, std::max(0.05 * scale, law(d, scale)));
}

std::shared_ptr<const ReferenceGeometry<3>> sphere(const Vector3d& center, double radius) {
  return make_sphere(center, radius, radius).reference;
}
std::shared_ptr<const ReferenceGeometry<3>> box(const Vector3d& lo, const Vector3d& hi) {
  return make_box(lo, hi, (hi - lo).minCoeff() / 2).reference;
}

// Unit directions spread over the sphere (a spiral), none along an axis.
std::vector<Vector3d> directions(int n) {
  std::vector<Vector3d> out;
  for (int i = 0; i < n; ++i) {
    const double z = 1 - (2 * i + 1.0) / n, phi = 2.399963229728653 * i;  // the golden angle
    const double r = std::sqrt(1 - z * z);
    out.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  return out;
}

// The smallest size's direction is (up to sign) `normal`; the size along it is `h_normal`, along
// any perpendicular `h_tangential`.
void check_metric(const Metric<3>& m, const Vector3d& normal, double h_normal, double h_tangential) {
  CHECK(m.size_along(normal) == doctest::Approx(h_normal).epsilon(1e-12));
  const Vector3d a = std::abs(normal.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  const Vector3d t1 = (a - normal * normal.dot(a)).normalized(), t2 = normal.cross(t1);
  for (const Vector3d& t : {t1, t2, Vector3d((t1 + t2).normalized())})
    CHECK(m.size_along(t) == doctest::Approx(h_tangential).epsilon(1e-12));
  if (h_normal < 0.999 * h_tangential) {
    const Metric<3>::Decomposition e = m.decompose();
    CHECK(e.sizes[0] == doctest::Approx(h_normal).epsilon(1e-12));
    CHECK(std::abs(e.directions.col(0).dot(normal)) == doctest::Approx(1.0).epsilon(1e-12));
  }
}

}  // namespace

TEST_CASE("wall metric 3D: on a sphere, h0 + (g-1) d along the radius, the radius the smallest size's direction") {
  const Vector3d c(0.3, -0.2, 0.1);
  const double radius = 0.7;
  const WallPowerLawField3 f(sphere(c, radius), params());
  // Outside at distances d, and inside (d up to 0.6 of the radius): the wall normal is radial.
  for (const Vector3d& u : directions(24))
    for (double d : {0.0, 1e-6, 1e-4, 1e-3, 0.01, 0.1, 0.245, 0.3, 1.0, 2.495, 3.0, 30.0, -1e-4, -0.1, -0.4}) {
      INFO("d = " << d << ", direction " << u.transpose());
      const Vector3d x = c + (radius + d) * u;
      const WallPowerLawField3::Sizes s = f.sizes(x);
      CHECK(std::abs(s.distance - std::abs(d)) <= 1e-14 * (1 + std::abs(d)));  // x's own rounding
      CHECK(s.normal == doctest::Approx(law(std::abs(d))).epsilon(1e-12));
      CHECK(s.tangential == doctest::Approx(law_tangential(std::abs(d))).epsilon(1e-12));
      CHECK(std::abs(s.normal_direction.dot(u)) == doctest::Approx(1.0).epsilon(1e-12));
      check_metric(f.evaluate(x), u, law(std::abs(d)), law_tangential(std::abs(d)));
    }
  // The layers of the linear law: layer k starts at d_k = h0 (g^k - 1) / (g - 1), height h0 g^k.
  for (int k = 0; 1e-3 * std::pow(1.2, k) <= 0.5; ++k) {
    const double dk = 1e-3 * (std::pow(1.2, k) - 1) / 0.2;
    CHECK(f.evaluate(c + (radius + dk) * Vector3d::UnitZ()).size_along(Vector3d::UnitZ()) ==
          doctest::Approx(1e-3 * std::pow(1.2, k)).epsilon(1e-12));
  }
}

TEST_CASE("wall metric 3D: the exponential law with growth distance delta is h0 g^(d/delta)") {
  WallLawParams w = params();
  w.exponential = true;
  w.delta = 0.004;
  const WallPowerLawField3 f(sphere(Vector3d::Zero(), 1), w);
  for (double d : {0.0, 0.002, 0.01, 0.03, 0.2})
    CHECK(f.sizes(Vector3d(0, 1 + d, 0)).normal ==
          doctest::Approx(std::min(1e-3 * std::pow(1.2, d / 0.004), 0.5)).epsilon(1e-12));
}

TEST_CASE("wall metric 3D: on a box, face normals, the direction from an edge or corner, sizes along the wall") {
  const Vector3d lo(-1, -2, -0.5), hi(1, 2, 0.5);
  const WallPowerLawField3 f(box(lo, hi), params());
  // Distances exact in binary, so that x - p is exact.
  for (double d : {0.0, 0x1p-20, 0x1p-14, 0x1p-10, 0x1p-6, 0x1p-3, 1.0, 4.0, 64.0}) {
    INFO("d = " << d);
    // Above the top face, and below it inside the box (the nearest face is the top one while
    // d < 0.5): the normal is +z.
    for (double side : {1.0, -1.0}) {
      if (side < 0 && d >= 0.5) continue;
      const Vector3d x(0.25, 0.5, 0.5 + side * d);
      const WallPowerLawField3::Sizes s = f.sizes(x);
      CHECK(s.distance == d);
      CHECK(s.normal == doctest::Approx(law(d)).epsilon(1e-12));
      CHECK(std::abs(s.normal_direction.z()) == 1.0);
      check_metric(f.evaluate(x), Vector3d::UnitZ(), law(d), law_tangential(d));
    }
    if (d == 0) continue;
    // Beside the edge x = 1, z = 0.5 (along y), at 30 degrees from the top face, and beyond the
    // corner hi along the diagonal: the normal is the direction from the edge or corner.
    const Vector3d from_edge(std::cos(M_PI / 6), 0, std::sin(M_PI / 6)), from_corner = Vector3d::Ones().normalized();
    for (const auto& [base, u] : {std::pair{Vector3d(1, 0.5, 0.5), from_edge}, std::pair{hi, from_corner}}) {
      const Vector3d x = base + d * u;
      const WallPowerLawField3::Sizes s = f.sizes(x);
      CHECK(s.distance == doctest::Approx(d).epsilon(1e-12));
      CHECK(s.normal_direction.dot(u) == doctest::Approx(1.0).epsilon(1e-12));
      check_metric(f.evaluate(x), u, law(d), law_tangential(d));
    }
  }
}

TEST_CASE("wall metric 3D: h_wall_max along the wall, isotropic where h_perp passes it, isotropic h_max far away") {
  const WallPowerLawField3 f(sphere(Vector3d::Zero(), 1), params());
  struct Golden {
    double d, normal, tangential;  // from the law: h0 + 0.2 d; max(0.05, .); both capped at 0.5
  };
  for (const Golden& g :
       {Golden{0, 1e-3, 0.05}, Golden{0.1, 0.021, 0.05}, Golden{0.245, 0.05, 0.05}, Golden{1, 0.201, 0.201},
        Golden{2.495, 0.5, 0.5}, Golden{10, 0.5, 0.5}, Golden{1e6, 0.5, 0.5}}) {
    INFO("d = " << g.d);
    const Metric<3> m = f.evaluate(Vector3d(0, 0, -1 - g.d));
    CHECK(m.min_size() == doctest::Approx(g.normal).epsilon(1e-12));
    CHECK(m.max_size() == doctest::Approx(g.tangential).epsilon(1e-12));
  }
  // What the surface mesh follows: the tangential size, isotropic.
  const WallSizesAlongWall3 along(f);
  for (double d : {0.0, 0.1, 1.0, 10.0}) {
    const Metric<3> m = along.evaluate(Vector3d(0, 1 + d, 0));
    CHECK(m.min_size() == doctest::Approx(law_tangential(d)).epsilon(1e-12));
    CHECK(m.max_size() == doctest::Approx(law_tangential(d)).epsilon(1e-12));
  }
}

TEST_CASE("wall metric 3D: the body and every length scaled by 1e-8 .. 1e8 give the same sizes scaled") {
  const Vector3d c(0.3, -0.2, 0.1), lo(-1, -2, -0.5), hi(1, 2, 0.5);
  const std::vector<Vector3d> points = {Vector3d(0.3, -0.2, 0.8 + 1e-5), Vector3d(1.3, 0.4, 0.2),
                                        Vector3d(0.25, 0.5, 0.5 + 1e-4), Vector3d(1.01, 0.5, 0.52),
                                        Vector3d(2, 2.5, 0.9), Vector3d(0.1, 0.2, 0.3), Vector3d(40, -30, 7)};
  for (bool on_box : {false, true}) {
    const WallPowerLawField3 unit(on_box ? box(lo, hi) : sphere(c, 0.7), params());
    for (double k : {1e-8, 1e-6, 1e6, 1e8}) {
      INFO((on_box ? "box" : "sphere") << " scaled by " << k);
      const WallPowerLawField3 scaled(on_box ? box(k * lo, k * hi) : sphere(k * c, k * 0.7), params(k));
      for (const Vector3d& x : points) {
        const WallPowerLawField3::Sizes a = unit.sizes(x), b = scaled.sizes(k * x);
        CHECK(b.distance == doctest::Approx(k * a.distance).epsilon(1e-9));
        CHECK(b.normal == doctest::Approx(k * a.normal).epsilon(1e-12));
        CHECK(b.tangential == doctest::Approx(k * a.tangential).epsilon(1e-12));
        CHECK(b.normal_direction.dot(a.normal_direction) == doctest::Approx(1.0).epsilon(1e-12));
      }
    }
  }
}

TEST_CASE("wall metric 3D: no wall is an error") {
  CHECK_THROWS_AS(WallPowerLawField3(nullptr, params()), MesherError);
}

TEST_CASE("wall metric 3D: behind a thin trailing edge the normal is the direction from the edge, across its whole fan") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // The E387's trailing edge turns by 175 degrees: the fan behind it reaches from the upper
  // side's normal to the lower side's, and the reference reports one side's normal at the edge.
  WingParams wp;
  wp.file = plaf::test::published("airfoils/e387.dat");
  wp.root = WingEnd::Symmetry;
  wp.tip = WingEnd::Symmetry;
  wp.span = 0.2;
  wp.corner_angle_deg = 70;
  const std::shared_ptr<const ReferenceGeometry<3>> wing = make_wing(wp, 0.05).reference;
  const WallPowerLawField3 f(wing, params());
  Vector3d n_edge;
  const Vector3d te = wing->project(Vector3d(1.5, 0, 0.1), n_edge);
  REQUIRE(te.x() == doctest::Approx(1.0).epsilon(1e-6));
  // Directions in the section plane from the upper side's normal (a little beyond the
  // perpendicular to the chord) round the back to the lower side's.
  int checked = 0;
  for (int k = 0; k <= 16; ++k) {
    const double phi = (85.0 - 170.0 * k / 16) * M_PI / 180;
    const Vector3d u(std::cos(phi), std::sin(phi), 0);
    for (double d : {1e-4, 0.01, 0.1}) {
      const Vector3d x = te + d * u;
      if ((wing->project(x) - te).norm() > 1e-9) continue;  // closest to a side, not the edge
      INFO("phi " << phi * 180 / M_PI << " deg, d " << d);
      const WallPowerLawField3::Sizes s = f.sizes(x);
      CHECK(std::abs(s.normal_direction.dot(u)) == doctest::Approx(1.0).epsilon(1e-9));
      check_metric(f.evaluate(x), u, law(d), law_tangential(d));
      ++checked;
    }
  }
  CHECK(checked >= 40);
}
