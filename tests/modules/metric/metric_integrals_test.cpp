// SPDX-License-Identifier: MIT
#include "modules/metric/metric_integrals.h"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace plaf;

namespace {

constexpr double pi = std::numbers::pi;

std::vector<Eigen::Vector2d> circle(double r, int n) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(r * std::cos(2 * pi * i / n), r * std::sin(2 * pi * i / n));
  return p;
}

// A metric whose size grows linearly away from x = 0: h(x) = h0 + g |x| along x, h_t along y.
class LinearWall final : public MetricField<2> {
 public:
  Metric<2> evaluate(const Point& x) const override {
    return Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Eigen::Vector2d(0.01 + 0.5 * std::abs(x.x()), 0.1));
  }
};


// A metric that counts its evaluations: size 0.01 + 0.1 x (a density varying 121-fold over the square).
class CountingField final : public MetricField<3> {
 public:
  mutable long calls = 0;
  Metric<3> evaluate(const Eigen::Vector3d& x) const override {
    ++calls;
    return Metric<3>::isotropic(0.01 + 0.1 * x.x());
  }
};

TEST_CASE("metric integrals: a surface's metric area refines where the density varies, within its evaluation budget") {
  // The unit square in z = 0 as 2 n^2 triangles.
  const int n = 10;
  std::vector<Eigen::Vector3d> p;
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) p.emplace_back(double(i) / n, double(j) / n, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      t.push_back({a, a + 1, a + n + 2});
      t.push_back({a, a + n + 2, a + n + 1});
    }
  // The exact integral of 1 / (0.01 + 0.1 x)^2 over [0, 1]: 10 (1/0.01 - 1/0.11).
  const double exact = 10 * (1 / 0.01 - 1 / 0.11);
  CountingField coarse, fine;
  const double at_centres = metric_surface_area(p, t, coarse, static_cast<long>(t.size()));
  const double refined = metric_surface_area(p, t, fine);
  CHECK(coarse.calls == static_cast<long>(t.size()));  // the centres only
  CHECK(fine.calls > coarse.calls);
  CHECK(fine.calls <= 148 * static_cast<long>(t.size()));  // depth 3's worst case
  CHECK(std::abs(refined - exact) < std::abs(at_centres - exact));
  CHECK(refined == doctest::Approx(exact).epsilon(0.1));
}

}  // namespace

TEST_CASE("metric integrals: a circle's metric length is its perimeter over the size, in any metric direction") {
  const SplineLoop loop(circle(2.0, 64), {}, "circle");
  CHECK(metric_length(loop, UniformMetricField<2>(Metric<2>::isotropic(0.1))) ==
        doctest::Approx(2 * pi * 2.0 / 0.1).epsilon(1e-4));
  // Sizes 0.1 along x and 0.4 along y: the length of an ellipse-like sum, by quadrature here.
  const UniformMetricField<2> aniso(Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Eigen::Vector2d(0.1, 0.4)));
  double expected = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * pi * (i + 0.5) / n;
    expected += 2.0 * std::hypot(std::sin(t) / 0.1, std::cos(t) / 0.4) * 2 * pi / n;
  }
  CHECK(metric_length(loop, aniso) == doctest::Approx(expected).epsilon(1e-4));
}

TEST_CASE("metric integrals: the metric area of a disk, an annulus and a wall band") {
  const UniformMetricField<2> h(Metric<2>::isotropic(0.05));
  const auto disk = [](const Eigen::Vector2d& x) { return x.norm() <= 1.0; };
  // The tree resolves the boundary to a few per cent of the area.
  CHECK(metric_measure<2>({-1, -1}, {1, 1}, disk, h) == doctest::Approx(pi / 0.0025).epsilon(0.02));
  const auto ring = [](const Eigen::Vector2d& x) { return x.norm() >= 1.0 && x.norm() <= 2.0; };
  CHECK(metric_measure<2>({-2, -2}, {2, 2}, ring, h) == doctest::Approx(3 * pi / 0.0025).epsilon(0.02));
  // A region the root cell's samples (its centre and corners) all miss is still found.
  const auto off = [](const Eigen::Vector2d& x) { return (x - Eigen::Vector2d(1, 1)).norm() <= 0.5; };
  CHECK(metric_measure<2>({-2, -2}, {2, 2}, off, h) == doctest::Approx(pi * 0.25 / 0.0025).epsilon(0.03));
  // A size growing linearly from a wall: integral over [-1, 1] x [0, 1] of 1 / ((0.01 + 0.5|x|) 0.1)
  // = 2 * 10 * ln(1 + 50) / 0.5; the tree refines towards the wall.
  const double band = 2 * 10 * std::log(51.0) / 0.5;
  const auto all = [](const Eigen::Vector2d&) { return true; };
  CHECK(metric_measure<2>({-1, 0}, {1, 1}, all, LinearWall()) == doctest::Approx(band).epsilon(0.1));
  // A density given directly, in 3D: the unit ball's volume.
  const double ball = region_integral<3>(
      {-1, -1, -1}, {1, 1, 1}, [](const Eigen::Vector3d& x) { return x.norm() <= 1; },
      [](const Eigen::Vector3d&) { return 1.0; });
  CHECK(ball == doctest::Approx(4 * pi / 3).epsilon(0.03));
}

TEST_CASE("metric integrals: a surface's metric area uses the metric in its tangent plane") {
  // The unit square in the plane z = x (tilted 45 degrees), two triangles: area sqrt 2.
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 0, 1}, {1, 1, 1}, {0, 1, 0}};
  const std::vector<std::array<int, 3>> t = {{0, 1, 2}, {0, 2, 3}};
  CHECK(metric_surface_area(p, t, UniformMetricField<3>(Metric<3>::isotropic(0.1))) ==
        doctest::Approx(std::sqrt(2.0) / 0.01));
  // Sizes 0.1 along y, 1 along z and 0.5 along x: in the plane, y keeps 0.1 and the direction
  // (1, 0, 1)/sqrt 2 has 1/h^2 = (1/0.25 + 1) / 2 = 2.5.
  const UniformMetricField<3> aniso(
      Metric<3>::from_directions(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0.1, 1.0)));
  CHECK(metric_surface_area(p, t, aniso) == doctest::Approx(std::sqrt(2.0) * 10 * std::sqrt(2.5)));
}
