// SPDX-License-Identifier: MIT
#include "modules/geometry/geometry2d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/metric/metric.h"
#include "tests/published_data.h"

using namespace plaf;
using Eigen::Vector2d;

namespace {

// A published contour in the data root (tests/published_data.h).
std::string airfoil(const std::string& file) {
  return plaf::test::published("airfoils/" + file);
}

AirfoilsParams bodies(const std::vector<std::string>& files) {
  AirfoilsParams a;
  for (std::size_t k = 0; k < files.size(); ++k)
    a.bodies.push_back({airfoil(files[k]), k == 0 ? "wall" : "wall_" + std::to_string(k + 1), {}});
  return a;
}

// The area enclosed by the spline itself (not the polygon of its points), by Green's theorem
// A = 1/2 \oint (x y' - y x') dt: on a cubic piece the integrand has degree 5, so 3 Gauss
// points per piece integrate it exactly.
double spline_area(const SplineLoop& s) {
  double gx[3], gw[3];
  gauss_legendre_01(3, gx, gw);
  double twice = 0;
  for (int i = 0; i < s.num_points(); ++i)
    for (int g = 0; g < 3; ++g) {
      const Vector2d p = s.point(i + gx[g]), d = s.derivative(i + gx[g]);
      twice += gw[g] * (p[0] * d[1] - p[1] * d[0]);
    }
  return 0.5 * twice;
}

std::vector<Vector2d> corner_points(const SplineLoop& s) {
  std::vector<Vector2d> out;
  for (int c : s.corners()) out.push_back(s.points()[c]);
  return out;
}

bool contains(const std::vector<Vector2d>& points, const Vector2d& x) {
  return std::find(points.begin(), points.end(), x) != points.end();
}

std::string config_error(const AirfoilsParams& a) {
  try {
    build_airfoils_geometry(a);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("geometry: the farfield circle is counter-clockwise with area pi r^2 at scales 1e-6 to 1e6") {
  constexpr int n = 256;  // farfield_circle's default
  for (const double r : {1e-6, 1e-2, 1.0, 20.0, 1e6}) {
    INFO("r = " << r);
    const Vector2d c(0.3 * r, -1.7 * r);
    const SplineLoop s = farfield_circle(c, r);
    REQUIRE(s.num_points() == n);
    CHECK(s.corners().empty());  // a periodic C2 spline
    // Polygon: the regular n-gon inscribed in the circle has area (n/2) r^2 sin(2 pi / n).
    CHECK(s.signed_area() > 0);
    CHECK(s.signed_area() == doctest::Approx(0.5 * n * r * r * std::sin(2 * M_PI / n)).epsilon(1e-12));
    // Spline: a periodic cubic interpolant of a circle sampled at angle steps h = 2 pi / n deviates
    // radially by at most (5/384) h^4 r = 4.7e-9 r (the interpolation error bound for f'''' = r),
    // so the area is pi r^2 (1 +- 2 x 4.7e-9).
    CHECK(spline_area(s) == doctest::Approx(M_PI * r * r).epsilon(1e-8));
    // The domain lies to the left: the left normal points to the centre.
    for (double t = 0.25; t < n; t += 16.5) CHECK(s.normal(t).dot(c - s.point(t)) > 0);
  }
}

TEST_CASE("geometry: the farfield rectangle is counter-clockwise with area w h and its 4 vertices as corners") {
  // Binary-exact centre and sizes: the shoelace sum of w h is exact.
  const SplineLoop s = farfield_rectangle(Vector2d(0.5, -2.0), 3.0, 1.5);
  CHECK(s.signed_area() == 4.5);
  CHECK(spline_area(s) == doctest::Approx(4.5).epsilon(1e-14));  // straight sides between corners
  const std::vector<Vector2d> corners = corner_points(s);
  REQUIRE(corners.size() == 4);
  for (const Vector2d& v : {Vector2d(-1.0, -2.75), Vector2d(2.0, -2.75), Vector2d(2.0, -1.25), Vector2d(-1.0, -1.25)})
    CHECK(contains(corners, v));
  // Over scales 1e-6 .. 1e6 with sizes that are not binary fractions.
  for (const double scale : {1e-6, 1e-3, 1.0, 1e3, 1e6}) {
    INFO("scale = " << scale);
    const double w = 40.1 * scale, h = 17.3 * scale;
    const SplineLoop r = farfield_rectangle(Vector2d(-3.3, 7.9) * scale, w, h);
    CHECK(r.signed_area() == doctest::Approx(w * h).epsilon(1e-14));
    CHECK(r.length() == doctest::Approx(2 * (w + h)).epsilon(1e-13));
  }
}

TEST_CASE("geometry: the farfield is centred on the bodies' bounding box unless a center is given") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // E387 (docs/data.md): x from the min-x point 0.00044 to the TE 1.0, y in [-0.01502, 0.08247].
  const Vector2d body_min(0.00044, -0.01502), body_max(1.0, 0.08247);
  const Vector2d mid = 0.5 * (body_min + body_max);
  AirfoilsParams a = bodies({"e387.dat"});
  const Geometry2D circle = build_airfoils_geometry(a);
  CHECK(circle.body_min == body_min);
  CHECK(circle.body_max == body_max);
  REQUIRE(circle.loops.size() == 2);
  const GeometryLoop& far = circle.loops.back();
  CHECK(far.tag == "farfield");
  CHECK(far.kind == BoundaryKind::Farfield);
  Vector2d mean = Vector2d::Zero();
  for (const Vector2d& p : far.loop.points()) mean += p / far.loop.num_points();
  CHECK((mean - mid).norm() < 1e-12 * a.farfield.radius);  // equally spaced angles sum to zero
  for (const Vector2d& p : far.loop.points())
    CHECK((p - mid).norm() == doctest::Approx(a.farfield.radius).epsilon(1e-14));

  a.farfield.shape = "rectangle";
  a.farfield.size = {30.0, 12.0};
  const Geometry2D boxed = build_airfoils_geometry(a);
  const SplineLoop& rect = boxed.loops.back().loop;
  Vector2d lo = rect.points()[0], hi = lo;
  for (const Vector2d& p : rect.points()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  CHECK(((lo + hi) / 2 - mid).norm() < 1e-14);
  CHECK((hi - lo - Vector2d(30.0, 12.0)).norm() < 1e-13);

  a.farfield.has_center = true;
  a.farfield.center = {3.0, -1.0};
  const Geometry2D moved = build_airfoils_geometry(a);
  CHECK(moved.loops.back().loop.points()[0] == Vector2d(-12.0, -7.0));  // it starts at its lower left
}

TEST_CASE("geometry: a farfield that does not enclose every body is a ConfigError") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // E387's TE (1, 0) is 0.5009 from the bounding-box centre (0.50022, 0.033725), its LE 0.4998.
  struct Case {
    const char* what;
    const char* shape;
    double radius;
    std::array<double, 2> size;
    bool has_center;
    std::array<double, 2> center;
    bool encloses;
  };
  const Case cases[] = {
      {"circle 0.6 about the centre", "circle", 0.6, {40, 40}, false, {0, 0}, true},
      {"circle 0.45 about the centre", "circle", 0.45, {40, 40}, false, {0, 0}, false},
      {"circle 20 about a far centre", "circle", 20, {40, 40}, true, {30, 0}, false},
      {"rectangle 1.2 x 0.2", "rectangle", 20, {1.2, 0.2}, false, {0, 0}, true},
      {"rectangle narrower than the chord", "rectangle", 20, {0.9, 10}, false, {0, 0}, false},
      {"rectangle lower than the thickness", "rectangle", 20, {10, 0.09}, false, {0, 0}, false},
  };
  for (const Case& k : cases) {
    INFO(k.what);
    AirfoilsParams a = bodies({"e387.dat"});
    a.farfield.shape = k.shape;
    a.farfield.radius = k.radius;
    a.farfield.size = k.size;
    a.farfield.has_center = k.has_center;
    a.farfield.center = k.center;
    const std::string e = config_error(a);
    if (k.encloses) {
      CHECK(e == "no error");
    } else {
      CHECK(e.find("geometry.farfield") != std::string::npos);
      CHECK(e.find("e387.dat") != std::string::npos);
    }
  }
}

TEST_CASE("geometry: body loops are clockwise whatever the file's orientation, the farfield counter-clockwise") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat", "airfoils/rae2822.dat", "airfoils/naca0012.dat");
  // docs/data.md: the E387, RAE 2822 and NACA 0012 files run counter-clockwise (clockwise files:
  // airfoil_io_test); the E387 polygon encloses 0.0573 (3 digits).
  const Geometry2D e387 = build_airfoils_geometry(bodies({"e387.dat"}));
  CHECK(e387.loops[0].loop.signed_area() == doctest::Approx(-0.0573).epsilon(1e-3));
  for (const auto& files :
       std::vector<std::vector<std::string>>{{"e387.dat"}, {"rae2822.dat"}, {"naca0012.dat"}}) {
    const Geometry2D g = build_airfoils_geometry(bodies(files));
    REQUIRE(g.loops.size() == files.size() + 1);
    for (std::size_t k = 0; k < files.size(); ++k) {
      INFO(files[k]);
      CHECK(g.loops[k].kind == BoundaryKind::Wall);
      CHECK(g.loops[k].tag == (k == 0 ? "wall" : "wall_" + std::to_string(k + 1)));
      CHECK(g.loops[k].loop.signed_area() < 0);
      CHECK(spline_area(g.loops[k].loop) < 0);
    }
    CHECK(g.loops.back().loop.signed_area() > 0);
  }
}

TEST_CASE("geometry: a corner given as [x, y] becomes a corner at the nearest contour point") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // E387 polygon turning angles (from the file's coordinates): 176.1 degrees at the TE (1, 0),
  // 39.4 and 52.5 at the two points around the smooth LE, (0.00044, 0.00234) and
  // (0.00091, -0.00286); every other point turns by less than 17 degrees.
  const Vector2d te(1.0, 0.0), le_upper(0.00044, 0.00234), le_lower(0.00091, -0.00286);
  AirfoilsParams a = bodies({"e387.dat"});
  a.corner_angle_deg = 70;
  CHECK(corner_points(build_airfoils_geometry(a).loops[0].loop) == std::vector<Vector2d>{te});

  // (-0.01, 0) is 0.01070 from le_upper and 0.01128 from le_lower; (1.2, 0.1) is nearest to the
  // TE, which is a corner already and stays one corner.
  a.bodies[0].corners = {{-0.01, 0.0}, {1.2, 0.1}};
  const std::vector<Vector2d> c = corner_points(build_airfoils_geometry(a).loops[0].loop);
  CHECK(c.size() == 2);
  CHECK(contains(c, te));
  CHECK(contains(c, le_upper));

  // Random requests: each becomes the contour point of least distance.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-0.3, 1.3), uy(-0.4, 0.4);
  for (int trial = 0; trial < 20; ++trial) {
    const Vector2d x(ux(rng), uy(rng));
    a.bodies[0].corners = {{x[0], x[1]}};
    const SplineLoop s = build_airfoils_geometry(a).loops[0].loop;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vector2d& p : s.points()) nearest = std::min(nearest, (p - x).norm());
    bool found = false;
    for (const Vector2d& p : corner_points(s)) found = found || (p != te && (p - x).norm() == nearest);
    INFO("request (" << x[0] << ", " << x[1] << ")");
    CHECK((found || (te - x).norm() == nearest));
  }

  // With the default 30 degree threshold the two LE points are corners by their turning angle.
  a.bodies[0].corners.clear();
  a.corner_angle_deg = 30;
  const std::vector<Vector2d> d = corner_points(build_airfoils_geometry(a).loops[0].loop);
  CHECK(d.size() == 3);
  for (const Vector2d& p : {te, le_upper, le_lower}) CHECK(contains(d, p));
}

TEST_CASE("geometry: a point offset by d along a body's normal is within d of the body (exact closest point)") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat", "airfoils/rae2822.dat", "airfoils/naca0012.dat", "airfoils/naca0012_sharp.dat");
  // The foot p(t) is on the spline, so the distance from x = p(t) + d n(t) is at most d, to
  // rounding (coordinates O(1): 1e-14). Regression input, verbatim: a point where the closest
  // point's Newton iteration, converged to rounding, fell back to bisection in a stale bracket
  // (2e-9 relative too large on the E387).
  struct Regression {
    int body;  // 0: RAE 2822, 1: NACA 0012 (blunt TE), 2: NACA 0012 (sharp TE), 3: E387
    Vector2d x;
    double d;
  };
  const Regression regressions[] = {
      {3, {0.99812107702980757, 0.0023747230634142305}, 0.0021083378660756787},
  };
  std::vector<SplineLoop> loops;
  for (const char* file : {"rae2822.dat", "naca0012.dat", "naca0012_sharp.dat"})
    loops.push_back(build_airfoils_geometry(bodies({file})).loops[0].loop);
  AirfoilsParams e387 = bodies({"e387.dat"});
  e387.corner_angle_deg = 70;  // as configs/e387.yaml
  loops.push_back(build_airfoils_geometry(e387).loops[0].loop);
  REQUIRE(loops.size() == 4);
  for (const Regression& r : regressions) {
    INFO("body " << r.body);
    CHECK(loops[static_cast<std::size_t>(r.body)].closest_point(r.x).distance <= r.d + 1e-14);
  }
  std::mt19937 rng(30);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int above = 0;
  for (int i = 0; i < 40000; ++i) {
    const SplineLoop& s = loops[static_cast<std::size_t>(i % 4)];
    const double t = u01(rng) * s.period(), d = 0.01 * u01(rng);
    const Vector2d x = s.point(t) + d * s.normal(t);
    const SplineLoop::Closest c = s.closest_point(x);
    above += c.distance > d + 1e-14 ? 1 : 0;
    CHECK((s.point(c.t) - c.point).norm() < 1e-14);
    CHECK(std::abs((x - c.point).norm() - c.distance) < 1e-15);
  }
  CHECK(above == 0);
}

TEST_CASE("geometry: Geometry2D as the 2D reference: closest loop, normal into the domain, curves, scale") {
  // A clockwise body circle of radius 1 inside the counter-clockwise farfield circle of radius 10,
  // both about the origin: the domain is the annulus between them.
  std::vector<Vector2d> body;
  for (int i = 0; i < 256; ++i) {
    const double a = -2 * M_PI * i / 256;  // clockwise
    body.push_back({std::cos(a), std::sin(a)});
  }
  Geometry2D g;
  g.loops.push_back({SplineLoop(body, {}, "wall"), "wall", BoundaryKind::Wall});
  g.loops.push_back({farfield_circle({0, 0}, 10), "farfield", BoundaryKind::Farfield});
  const ReferenceGeometry<2>& ref = g;
  CHECK(ref.num_curves() == 2);
  CHECK(ref.scale() == doctest::Approx(std::sqrt(2.0) * 20).epsilon(1e-6));
  for (const double angle : {0.3, 2.0, 4.5}) {
    const Vector2d u(std::cos(angle), std::sin(angle));
    // Near the body: its point, and the normal pointing away from it (into the domain).
    Vector2d n;
    const Vector2d p = ref.project(2.0 * u, n);
    CHECK((p - u).norm() < 1e-6);  // the spline through 256 points of the unit circle
    CHECK(n.dot(u) > 1 - 1e-9);
    CHECK((ref.normal(p) - n).norm() < 1e-12);
    CHECK((ref.project(2.0 * u) - p).norm() < 1e-15);
    // Near the farfield: its point, and its normal pointing inward (into the domain).
    const Vector2d q = ref.project(9.0 * u, n);
    CHECK((q - 10.0 * u).norm() < 1e-4);
    CHECK(n.dot(u) < -1 + 1e-9);
    // A chosen curve, whichever is closer.
    CHECK((ref.project_to_curve(2.0 * u, 1) - 10.0 * u).norm() < 1e-4);
    CHECK((ref.project_to_curve(9.0 * u, 0) - u).norm() < 1e-6);
  }
  CHECK_THROWS_AS(ref.project_to_curve({0, 0}, 2), Error);
}
