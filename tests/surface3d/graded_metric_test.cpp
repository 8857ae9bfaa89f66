// SPDX-License-Identifier: MIT
#include "surface3d/graded_metric.h"

#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "modules/base/error.h"

namespace plaf {
namespace {

// A size jump: `fine` inside the disc of radius 0.05 about the origin (in z = 0), 1 elsewhere,
// anisotropic inside when asked (the fine size across x, ten times it along y).
class Jump final : public MetricField<3> {
 public:
  Jump(double fine, bool aniso) : fine_(fine), aniso_(aniso) {}
  Metric<3> evaluate(const Point& x) const override {
    if (x.head<2>().norm() > 0.05) return Metric<3>::isotropic(1);
    return Metric<3>::from_directions(Eigen::Matrix3d::Identity(),
                                      Eigen::Vector3d(fine_, aniso_ ? 10 * fine_ : fine_, 1));
  }

 private:
  double fine_;
  bool aniso_;
};

// A regular grid of n x n squares on [-1, 1]^2 in z = 0, each split in two triangles.
void grid(int n, std::vector<Eigen::Vector3d>& p, std::vector<std::array<int, 3>>& t) {
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) p.emplace_back(-1 + 2.0 * i / n, -1 + 2.0 * j / n, 0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
}

double max_eig(const Metric<3>& g, const Metric<3>& m) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> es(g.matrix(), m.matrix(), Eigen::EigenvaluesOnly);
  return es.eigenvalues().maxCoeff();
}

TEST_CASE("gradation: sizes grow from a fine spot by at most 1 + ln beta per unit edge, the fine sizes kept") {
  for (const bool aniso : {false, true}) {
    CAPTURE(aniso);
    std::vector<Eigen::Vector3d> p;
    std::vector<std::array<int, 3>> t;
    grid(80, p, t);
    const double beta = 1.5, fine = 0.002;
    GradedMetricField g(std::make_unique<Jump>(fine, aniso), p, t, beta);
    const Jump raw(fine, aniso);
    CHECK(g.corrected_points() > 0);
    // Along every edge the grown metric of one end asks for no smaller size than the other's.
    double worst = 0;
    for (const auto& tri : t)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d a = p[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
        const Eigen::Vector3d b = p[static_cast<std::size_t>(tri[static_cast<std::size_t>((k + 1) % 3)])];
        const Metric<3> ma = g.evaluate(a), mb = g.evaluate(b);
        worst = std::max(worst, max_eig(GradedMetricField::grown(ma, b - a, std::log(beta)), mb));
        // Never coarser than the raw field.
        CHECK(max_eig(raw.evaluate(a), ma) <= 1 + 1e-9);
      }
    CHECK(worst <= 1 + 1e-5);
    // Inside the spot the raw sizes stand.
    const Metric<3> at0 = g.evaluate(Eigen::Vector3d(0, 0, 0));
    CHECK(at0.size_along(Eigen::Vector3d::UnitX()) == doctest::Approx(fine).epsilon(1e-9));
    CHECK(at0.size_along(Eigen::Vector3d::UnitY()) == doctest::Approx(aniso ? 10 * fine : fine).epsilon(1e-9));
    // Away from it the size follows the grid's growth law: the spot's edge (0.05) plus ln beta
    // per unit distance at most, and strictly below the raw size 1 near the spot.
    const double hx = g.evaluate(Eigen::Vector3d(0.3, 0, 0)).size_along(Eigen::Vector3d::UnitX());
    CHECK(hx < 1);
    CHECK(hx <= fine + std::log(beta) * 0.3 + 1e-9);
    CHECK(hx >= fine + std::log(beta) * (0.3 - 0.05 - 2.0 / 80) * 0.5);
    // Far away the raw size again.
    CHECK(g.evaluate(Eigen::Vector3d(1, 1, 0)).max_size() == doctest::Approx(1.0));
  }
}

TEST_CASE("gradation: bad beta and an empty support are errors") {
  std::vector<Eigen::Vector3d> p;
  std::vector<std::array<int, 3>> t;
  grid(2, p, t);
  CHECK_THROWS_AS(GradedMetricField(std::make_unique<Jump>(0.1, false), p, t, 1.0), ConfigError);
  CHECK_THROWS_AS(GradedMetricField(std::make_unique<Jump>(0.1, false), p, {}, 1.5), MesherError);
}

}  // namespace
}  // namespace plaf
