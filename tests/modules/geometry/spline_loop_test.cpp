// SPDX-License-Identifier: MIT
#include "modules/geometry/spline_loop.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "modules/base/error.h"

using namespace plaf;
using Eigen::Vector2d;

namespace {

// n points on the circle of radius r about c, starting at angle 0, clockwise when asked.
std::vector<Vector2d> circle(int n, double r, const Vector2d& c, bool clockwise) {
  std::vector<Vector2d> p(n);
  for (int k = 0; k < n; ++k) {
    const double a = (clockwise ? -2.0 : 2.0) * M_PI * k / n;
    p[k] = c + r * Vector2d(std::cos(a), std::sin(a));
  }
  return p;
}

// Max | |p(t) - c| - r | over 32 samples per piece, pieces [first, last).
double max_radial_error(const SplineLoop& s, const Vector2d& c, double r, int first, int last) {
  double err = 0;
  for (int i = first; i < last; ++i)
    for (int k = 0; k < 32; ++k) err = std::max(err, std::abs((s.point(i + k / 32.0) - c).norm() - r));
  return err;
}

// NACA 0012 with the closed-TE thickness law y = 0.6 (0.2969 sqrt x - 0.1260 x - 0.3516 x^2
// + 0.2843 x^3 - 0.1036 x^4) (the formula docs/data.md checks naca0012_sharp.dat against),
// cosine spacing, clockwise from the TE: TE -> lower -> LE -> upper; the TE (index 0) is a corner.
std::vector<Vector2d> naca0012_clockwise(int intervals) {
  const auto y = [](double x) {
    return 0.6 * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x - 0.1036 * x * x * x * x);
  };
  std::vector<Vector2d> p;
  for (int k = intervals; k >= 0; --k) {  // lower surface, TE -> LE
    const double x = 0.5 * (1.0 - std::cos(M_PI * k / intervals));
    p.emplace_back(x, -y(x));
  }
  for (int k = 1; k < intervals; ++k) {  // upper surface, LE -> TE (TE not repeated)
    const double x = 0.5 * (1.0 - std::cos(M_PI * k / intervals));
    p.emplace_back(x, y(x));
  }
  return p;
}

bool is_corner(const SplineLoop& s, int i) {
  return std::binary_search(s.corners().begin(), s.corners().end(), i);
}

}  // namespace

TEST_CASE("spline: a periodic circle interpolant converges at 4th order") {
  // Chord-length cubic interpolation error is O(h^4) (de Boor, A Practical Guide to Splines).
  for (double scale : {1e-6, 1.0, 1e6}) {
    const double r = 2.5 * scale;
    const Vector2d c(1.0 * scale, -3.0 * scale);
    std::vector<double> err;
    for (int n : {16, 32, 64, 128}) {
      const SplineLoop s(circle(n, r, c, false), {}, "circle");
      err.push_back(max_radial_error(s, c, r, 0, n) / r);
    }
    for (size_t k = 0; k + 1 < err.size(); ++k) {
      const double rate = std::log2(err[k] / err[k + 1]);
      CAPTURE(scale);
      CAPTURE(k);
      CHECK(rate >= 3.5);
      CHECK(rate <= 4.5);
    }
  }
}

TEST_CASE("spline: a half circle between two corners converges at 4th order with not-a-knot ends") {
  // Clockwise half disc: the arc from (-r, 0) over the top to (r, 0), then the diameter back.
  const double r = 1.5;
  const Vector2d c(0.25, 0.5);
  std::vector<double> err;
  for (int m : {16, 32, 64, 128}) {
    std::vector<Vector2d> p;
    for (int k = 0; k <= m; ++k) {
      const double a = M_PI - M_PI * k / m;
      p.push_back(c + r * Vector2d(std::cos(a), std::sin(a)));
    }
    const SplineLoop s(p, {0, m}, "half disc");
    err.push_back(max_radial_error(s, c, r, 0, m) / r);
    // The corner-to-corner run of one piece is the straight diameter, traversed uniformly.
    for (double u : {0.0, 0.25, 0.5, 0.75}) {
      const Vector2d expected = c + r * Vector2d(1.0 - 2.0 * u, 0.0);
      CHECK((s.point(m + u) - expected).norm() <= 1e-14 * r);
      CHECK(s.curvature(m + u) == 0.0);
    }
    CHECK(s.signed_area() < 0);
  }
  for (size_t k = 0; k + 1 < err.size(); ++k) CHECK(std::log2(err[k] / err[k + 1]) >= 3.5);
}

TEST_CASE("spline: tangent, normal and curvature of a circle follow the orientation") {
  // At angle a on a circle run clockwise the tangent is (sin a, -cos a); rotated by +90 degrees
  // it gives the left normal (cos a, sin a), the outward radial direction: for a clockwise body
  // the normal points away from the body, into the domain. The curve turns right, so the signed
  // curvature is -1/r. Run counter-clockwise, the normal points to the centre and curvature is +1/r.
  const double r = 3.0;
  const Vector2d c(-1.0, 2.0);
  const int n = 256;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> any_t(0.0, n);
  for (bool clockwise : {true, false}) {
    const SplineLoop s(circle(n, r, c, clockwise), {}, "circle");
    const double side = clockwise ? 1.0 : -1.0;
    CHECK(s.signed_area() * side < 0);
    for (int k = 0; k < 200; ++k) {
      const double t = any_t(rng);
      const Vector2d radial = (s.point(t) - c).normalized();
      CHECK(std::abs(s.tangent(t).norm() - 1.0) <= 1e-15);
      CHECK(std::abs(s.tangent(t).dot(radial)) <= 1e-5);
      CHECK(s.normal(t).dot(radial) * side >= 1.0 - 1e-9);
      // Curvature error of the cubic interpolant is O(h^2), h = 2 pi / 256.
      CHECK(s.curvature(t) * r * side == doctest::Approx(-1.0).epsilon(2e-3));
    }
  }
}

TEST_CASE("spline: circle arc length converges to 2 pi r and parameter_at inverts arc_length") {
  for (double scale : {1e-8, 1.0, 1e8}) {
    const double r = 0.7 * scale;
    const Vector2d c(scale, 2.0 * scale);
    std::vector<double> err;
    for (int n : {16, 32, 64, 128}) {
      const SplineLoop s(circle(n, r, c, true), {}, "circle");
      err.push_back(std::abs(s.length() - 2.0 * M_PI * r) / r);
    }
    for (size_t k = 0; k + 1 < err.size(); ++k) CHECK(std::log2(err[k] / err[k + 1]) >= 3.5);

    const int n = 64;
    const SplineLoop s(circle(n, r, c, true), {}, "circle");
    const double total = s.length();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> any_t(-n, 2.0 * n), any_s(0.0, 2.5 * total);
    for (int k = 0; k < 100; ++k) {
      const double t0 = any_t(rng), len = any_s(rng);
      const double t = s.parameter_at(t0, len);
      CHECK(t >= t0);
      CHECK(std::abs(s.arc_length(t0, t) - len) <= 1e-12 * total);
      // Additivity across the wrap, and a full turn is the length.
      const double tm = t0 + 0.37 * (t - t0);
      CHECK(std::abs(s.arc_length(t0, tm) + s.arc_length(tm, t) - s.arc_length(t0, t)) <= 1e-12 * total);
      CHECK(std::abs(s.arc_length(t0, t0 + n) - total) <= 1e-12 * total);
      CHECK(std::abs(s.parameter_at(t0, s.arc_length(t0, t0 + 0.3)) - (t0 + 0.3)) <= 1e-11 * n);
    }
  }
}

TEST_CASE("spline: arc length quadrature matches a fine composite Simpson rule on an airfoil") {
  const std::vector<Vector2d> p = naca0012_clockwise(60);
  const SplineLoop s(p, {0}, "naca0012");
  const int n = s.num_points();
  for (int i = 0; i < n; i += 7) {
    // Composite Simpson on |p'(u)| with 2000 intervals: error ~ 1e-13 relative on these pieces.
    const int m = 2000;
    double sum = 0;
    for (int k = 0; k <= m; ++k) {
      const double w = (k == 0 || k == m) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      // The end value is the left limit (t = i + 1 itself belongs to the next piece).
      sum += w * s.derivative(k < m ? i + k / double(m) : i + 1 - 1e-9).norm();
    }
    const double simpson = sum / (3.0 * m);
    CAPTURE(i);
    CHECK(std::abs(s.arc_length(i, i + 1) - simpson) <= 1e-11 * simpson);
  }
}

TEST_CASE("spline: closest_point agrees with brute-force sampling on an airfoil") {
  const SplineLoop s(naca0012_clockwise(50), {0}, "naca0012");
  const int n = s.num_points();
  // Brute force: 400 samples per piece.
  constexpr int per_piece = 400;
  std::vector<Vector2d> samples;
  double max_step = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < per_piece; ++k) {
      samples.push_back(s.point(i + k / double(per_piece)));
      if (samples.size() > 1) max_step = std::max(max_step, (samples.back() - samples[samples.size() - 2]).norm());
    }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> any_t(0.0, n), offset(-0.03, 0.03), far_x(-5.0, 6.0), far_y(-5.0, 5.0);
  for (int q = 0; q < 150; ++q) {
    const double t = any_t(rng);
    const Vector2d x = q % 2 ? Vector2d(far_x(rng), far_y(rng)) : Vector2d(s.point(t) + offset(rng) * s.normal(t));
    const SplineLoop::Closest c = s.closest_point(x);
    double brute = std::numeric_limits<double>::infinity();
    for (const Vector2d& y : samples) brute = std::min(brute, (y - x).norm());
    CAPTURE(x);
    CHECK(c.distance <= brute + 1e-12);
    CHECK(brute - c.distance <= max_step);
    CHECK((s.point(c.t) - c.point).norm() <= 1e-14);
    CHECK(std::abs((x - c.point).norm() - c.distance) <= 1e-15);
    // Away from the TE corner the spline is C1, so x - p is normal to it.
    if ((c.point - s.points()[0]).norm() > 1e-9 && c.distance > 1e-9)
      CHECK(std::abs((x - c.point).dot(s.tangent(c.t))) <= 1e-10 * c.distance);
  }
}

TEST_CASE("spline: closest_point on a 20000-point circle matches the analytic distance") {
  // The interpolation error at n = 20000 is ~ r (2 pi / n)^4 / 100, below 1e-13 r; brute force
  // would cost 20000 pieces per query, the tree visits a handful.
  const double r = 2.0;
  const Vector2d c(0.5, -0.5);
  const int n = 20000;
  const SplineLoop s(circle(n, r, c, true), {}, "big circle");
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), radius(0.5 * r, 3.0 * r);
  for (int q = 0; q < 2000; ++q) {
    const double a = angle(rng), rho = radius(rng);
    const Vector2d x = c + rho * Vector2d(std::cos(a), std::sin(a));
    const SplineLoop::Closest cp = s.closest_point(x);
    CHECK(std::abs(cp.distance - std::abs(rho - r)) <= 1e-12 * r);
    // Clockwise from angle 0: t = n (2 pi - a) / (2 pi) modulo n.
    const double t_expected = std::fmod(n * (2.0 * M_PI - a) / (2.0 * M_PI), double(n));
    const double dt = std::abs(cp.t - t_expected);
    CHECK(std::min(dt, n - dt) <= 1e-6);
  }
}

TEST_CASE("spline: turning angles and corner detection") {
  for (double scale : {1e-8, 1.0, 1e8}) {
    // A clockwise square turns right by 90 degrees at each vertex.
    const std::vector<Vector2d> square = {Vector2d(0, 0) * scale, Vector2d(0, 1) * scale, Vector2d(1, 1) * scale,
                                          Vector2d(1, 0) * scale};
    for (int i = 0; i < 4; ++i) CHECK(turning_angle(square, i) == doctest::Approx(-M_PI / 2).epsilon(1e-14));
    CHECK(detect_corners(square, 30.0) == std::vector<int>{0, 1, 2, 3});
    // A counter-clockwise regular hexagon turns left by 60 degrees.
    const std::vector<Vector2d> hexagon = circle(6, scale, Vector2d(scale, 0), false);
    for (int i = 0; i < 6; ++i) CHECK(turning_angle(hexagon, i) == doctest::Approx(M_PI / 3).epsilon(1e-12));
    CHECK(detect_corners(hexagon, 30.0).size() == 6);
    CHECK(detect_corners(hexagon, 70.0).empty());
    // A 64-gon turns by 360/64 = 5.6 degrees.
    CHECK(detect_corners(circle(64, scale, Vector2d::Zero(), true), 30.0).empty());
  }
}

TEST_CASE("spline: C0 at corners and C2 in the chord-length parameter between them") {
  // A nonuniformly sampled ellipse with corners at 5 and 23, and the airfoil with its TE corner.
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<Vector2d> ellipse;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    const double a = -2.0 * M_PI * (k + jitter(rng)) / n;
    ellipse.emplace_back(2.0 * std::cos(a), std::sin(a));
  }
  const SplineLoop loops[] = {SplineLoop(ellipse, {5, 23}, "ellipse"), SplineLoop(naca0012_clockwise(30), {0}, "naca")};
  for (const SplineLoop& s : loops) {
    const int np = s.num_points();
    for (int i = 0; i < np; ++i) {
      const auto& p = s.points();
      const double h_left = (p[i] - p[(i + np - 1) % np]).norm(), h_right = (p[(i + 1) % np] - p[i]).norm();
      const double eps = 1e-9, delta = 1e-6;
      const double ti = i == 0 ? np : i;  // approach point i from the piece before it
      CAPTURE(s.name());
      CAPTURE(i);
      CHECK((s.point(ti - eps) - p[i]).norm() <= 1e-8 * h_left);
      CHECK((s.point(i) - p[i]).norm() == 0.0);
      // One-sided derivatives in the chord parameter s: d/ds = (d/du) / h.
      const Vector2d d1_left = s.derivative(ti - eps) / h_left, d1_right = s.derivative(i) / h_right;
      const Vector2d d2_left = (s.derivative(ti - eps) - s.derivative(ti - eps - delta)) / (delta * h_left * h_left);
      const Vector2d d2_right = (s.derivative(i + delta) - s.derivative(i)) / (delta * h_right * h_right);
      if (is_corner(s, i)) {
        CHECK(d1_left.normalized().dot(d1_right.normalized()) < 1.0 - 1e-6);  // the tangent jumps
      } else {
        CHECK((d1_left - d1_right).norm() <= 1e-7 * d1_right.norm());
        CHECK((d2_left - d2_right).norm() <= 1e-4 * (d2_left.norm() + d2_right.norm()) + 1e-6);
      }
    }
  }
}

TEST_CASE("spline: a polygon whose vertices are all corners is the polygon itself") {
  const std::vector<Vector2d> tri = {Vector2d(0, 0), Vector2d(0, 3), Vector2d(4, 0)};
  const SplineLoop s(tri, {0, 1, 2}, "triangle");
  CHECK(s.length() == doctest::Approx(12.0).epsilon(1e-14));
  CHECK((s.point(1.5) - Vector2d(2, 1.5)).norm() <= 1e-15);
  CHECK(s.curvature(2.3) == 0.0);
  CHECK(s.signed_area() == doctest::Approx(-6.0).epsilon(1e-15));
  CHECK(s.parameter_at(0.0, 4.0) == doctest::Approx(1.0 + 1.0 / 5.0).epsilon(1e-14));
  const SplineLoop::Closest c = s.closest_point(Vector2d(-1, -1));
  CHECK(c.point.norm() <= 1e-15);
  CHECK(c.distance == doctest::Approx(std::sqrt(2.0)).epsilon(1e-15));
}

TEST_CASE("spline: degenerate input throws InputError naming the loop") {
  const auto message = [](auto make) {
    try {
      make();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::vector<Vector2d> two = {Vector2d(0, 0), Vector2d(1, 0)};
  CHECK(message([&] { SplineLoop(two, {}, "wing"); }).find("wing: a spline loop needs at least 3 points") == 0);
  const std::vector<Vector2d> repeated = {Vector2d(0, 0), Vector2d(1, 0), Vector2d(1, 0), Vector2d(0, 1)};
  CHECK(message([&] { SplineLoop(repeated, {}, "flap"); }) == "flap: points 1 and 2 coincide");
  const std::vector<Vector2d> closed = {Vector2d(0, 0), Vector2d(1, 0), Vector2d(0, 1), Vector2d(0, 0)};
  CHECK(message([&] { SplineLoop(closed, {}, "slat"); }) == "slat: points 3 and 0 coincide");
  const std::vector<Vector2d> nan = {Vector2d(0, 0), Vector2d(1, std::nan("")), Vector2d(0, 1)};
  CHECK(message([&] { SplineLoop(nan, {}, "main"); }) == "main: point 1 is not finite");
  const std::vector<Vector2d> tri = {Vector2d(0, 0), Vector2d(0, 1), Vector2d(1, 0)};
  CHECK(message([&] { SplineLoop(tri, {2, 1}, "body"); }).find("body: corner indices") == 0);
  CHECK(message([&] { SplineLoop(tri, {3}, "body"); }).find("body: corner indices") == 0);
}
