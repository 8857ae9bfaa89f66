// SPDX-License-Identifier: MIT
#include "modules/metric/metric.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "modules/base/error.h"
#include "modules/metric/extruded_metric.h"

using namespace plaf;
using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

Matrix2d rotation(double a) {
  Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return r;
}

double rel_diff(const Matrix2d& a, const Matrix2d& b) {
  return (a - b).norm() / b.norm();
}

}  // namespace

TEST_CASE("metric: sizes and directions round-trip, and size h along e means e^T M e = 1/h^2") {
  for (double scale : {1e-8, 1.0, 1e8}) {
    const Matrix2d r = rotation(0.3);
    const Vector2d h(0.01 * scale, 2.0 * scale);
    const Metric<2> m = Metric<2>::from_directions(r, h);
    const auto d = m.decompose();
    CHECK(d.sizes[0] == doctest::Approx(h[0]).epsilon(1e-12));
    CHECK(d.sizes[1] == doctest::Approx(h[1]).epsilon(1e-12));
    CHECK(std::abs(d.directions.col(0).dot(r.col(0))) == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(m.size_along(r.col(0)) == doctest::Approx(h[0]).epsilon(1e-12));
    CHECK(m.size_along(r.col(1)) == doctest::Approx(h[1]).epsilon(1e-12));
    // A vector of length 3 h0 along the first direction has metric length 3.
    CHECK(m.length(3 * h[0] * r.col(0)) == doctest::Approx(3.0).epsilon(1e-12));
    CHECK(m.min_size() == doctest::Approx(h[0]).epsilon(1e-12));
    CHECK(m.max_size() == doctest::Approx(h[1]).epsilon(1e-12));
  }
  Matrix3d r3 = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Metric<3> m3 = Metric<3>::from_directions(r3, Vector3d(1e-4, 1e-2, 1.0));
  for (int i = 0; i < 3; ++i) CHECK(m3.size_along(r3.col(i)) == doctest::Approx(std::pow(10.0, 2 * i - 4)));
}

TEST_CASE("metric: bad tensors and sizes are InputErrors") {
  CHECK_THROWS_AS(Metric<2>::isotropic(-1.0), InputError);
  CHECK_THROWS_AS(Metric<2>::isotropic(0.0), InputError);
  CHECK_THROWS_AS(Metric<2>::isotropic(std::nan("")), InputError);
  Matrix2d indefinite;
  indefinite << 1, 2, 2, 1;
  CHECK_THROWS_AS(Metric<2>::from_matrix(indefinite), InputError);
  Matrix2d asym;
  asym << 1, 0.5, 0, 1;
  CHECK_THROWS_AS(Metric<2>::from_matrix(asym), InputError);
}

TEST_CASE("metric: log-Euclidean and affine-invariant means") {
  // Commuting (isotropic) metrics: both means are the geometric mean of the sizes.
  const std::vector<Metric<2>> iso = {Metric<2>::isotropic(0.1), Metric<2>::isotropic(10.0)};
  const std::vector<double> half = {0.5, 0.5};
  CHECK(log_euclidean_mean<2>(iso, half).size_along(Vector2d::UnitX()) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(affine_invariant_mean<2>(iso, half).size_along(Vector2d::UnitX()) == doctest::Approx(1.0).epsilon(1e-12));
  // Weights 1:0 return the first metric.
  const std::vector<double> first = {1.0, 0.0};
  CHECK(rel_diff(log_euclidean_mean<2>(iso, first).matrix(), iso[0].matrix()) < 1e-12);

  // Non-commuting: the two-point affine-invariant mean is the matrix geometric mean
  // A # B = A^1/2 (A^-1/2 B A^-1/2)^1/2 A^1/2 (Bhatia, Positive Definite Matrices, 2007, ch. 4).
  const Metric<2> a = Metric<2>::from_directions(rotation(0.2), Vector2d(0.01, 1.0));
  const Metric<2> b = Metric<2>::from_directions(rotation(1.1), Vector2d(0.5, 0.05));
  Eigen::SelfAdjointEigenSolver<Matrix2d> ea(a.matrix());
  const Matrix2d as = ea.operatorSqrt(), ais = ea.operatorInverseSqrt();
  Eigen::SelfAdjointEigenSolver<Matrix2d> em(ais * b.matrix() * ais);
  const Matrix2d geo = as * em.operatorSqrt() * as;
  const std::vector<Metric<2>> ab = {a, b};
  CHECK(rel_diff(affine_invariant_mean<2>(ab, half).matrix(), geo) < 1e-10);
  // Affine invariance: mean(G^T A G, G^T B G) = G^T mean(A, B) G; the log-Euclidean mean is not.
  Matrix2d g;
  g << 2.0, 0.3, -0.4, 0.7;
  const std::vector<Metric<2>> gab = {Metric<2>::from_matrix(g.transpose() * a.matrix() * g),
                                      Metric<2>::from_matrix(g.transpose() * b.matrix() * g)};
  const std::vector<double> w = {0.3, 0.7};
  CHECK(rel_diff(affine_invariant_mean<2>(gab, w).matrix(),
                 g.transpose() * affine_invariant_mean<2>(ab, w).matrix() * g) < 1e-10);
  CHECK(rel_diff(log_euclidean_mean<2>(gab, w).matrix(), g.transpose() * log_euclidean_mean<2>(ab, w).matrix() * g) >
        1e-3);
}

TEST_CASE("metric: intersection is the smallest size in every direction of the common basis") {
  CHECK(intersect(Metric<2>::isotropic(0.1), Metric<2>::isotropic(0.3)).size_along(Vector2d::UnitY()) ==
        doctest::Approx(0.1));
  const Metric<2> a = Metric<2>::from_directions(rotation(0.0), Vector2d(0.01, 1.0));
  const Metric<2> b = Metric<2>::from_directions(rotation(0.0), Vector2d(1.0, 0.02));
  const Metric<2> c = intersect(a, b);
  CHECK(c.size_along(Vector2d::UnitX()) == doctest::Approx(0.01));
  CHECK(c.size_along(Vector2d::UnitY()) == doctest::Approx(0.02));
  // In general: the intersection's unit ball lies inside both, and it is symmetric in a, b.
  const Metric<2> p = Metric<2>::from_directions(rotation(0.4), Vector2d(0.01, 1.0));
  const Metric<2> q = Metric<2>::from_directions(rotation(1.3), Vector2d(0.2, 0.05));
  const Metric<2> pq = intersect(p, q), qp = intersect(q, p);
  CHECK(rel_diff(pq.matrix(), qp.matrix()) < 1e-10);
  for (int i = 0; i < 64; ++i) {
    const Vector2d v(std::cos(i * 0.1), std::sin(i * 0.1));
    CHECK(pq.length(v) >= std::max(p.length(v), q.length(v)) * (1 - 1e-12));
  }
}

TEST_CASE("metric: Gauss-Legendre rules integrate degree 2n-1 exactly") {
  for (int n = 1; n <= 16; ++n) {
    std::vector<double> x(n), w(n);
    gauss_legendre_01(n, x.data(), w.data());
    double s = 0;
    for (int i = 0; i < n; ++i) s += w[i] * std::pow(x[i], 2 * n - 1);
    CHECK(s == doctest::Approx(1.0 / (2 * n)).epsilon(1e-13));
  }
}

TEST_CASE("metric: metric length of a segment and of a curved edge") {
  const Metric<2> m = Metric<2>::from_directions(rotation(0.5), Vector2d(0.01, 0.5));
  const UniformMetricField<2> field(m);
  const Vector2d a(0.1, 0.2), b(0.6, -0.3);
  // Constant metric: exactly sqrt((b-a)^T M (b-a)).
  CHECK(metric_length<2>(field, a, b) == doctest::Approx(m.length(b - a)).epsilon(1e-13));
  // A quarter circle of radius 2 as an order-4 Lagrange edge (Gmsh order: ends, then interior)
  // under the metric of size 0.5: length ~ (pi/2 * 2) / 0.5 = 2 pi, interpolation error < 1e-4.
  const UniformMetricField<2> iso(Metric<2>::isotropic(0.5));
  const double t[5] = {0.0, 1.0, 0.25, 0.5, 0.75};
  double coords[10];
  for (int k = 0; k < 5; ++k) {
    coords[2 * k] = 2 * std::cos(t[k] * M_PI / 2);
    coords[2 * k + 1] = 2 * std::sin(t[k] * M_PI / 2);
  }
  CHECK(metric_length_curved<2>(iso, coords, 4) == doctest::Approx(2 * M_PI).epsilon(1e-4));
}

TEST_CASE("metric: the affine-invariant mean is congruence-invariant for far-apart anisotropic triples") {
  // Random triples of sizes 0.01..1 x 0.5..2.5 in random directions (a plain fixed-point
  // iteration oscillates on some of these): mean(G^T M_i G) = G^T mean(M_i) G.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Matrix2d g;
  g << 1.7, -0.4, 0.9, 0.3;
  double worst = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<Metric<2>> m, gm;
    for (int k = 0; k < 3; ++k) {
      m.push_back(Metric<2>::from_directions(rotation(M_PI * u(rng)), Vector2d(0.01 + 0.99 * u(rng), 0.5 + 2 * u(rng))));
      gm.push_back(Metric<2>::from_matrix(g.transpose() * m.back().matrix() * g));
    }
    const std::vector<double> w = {u(rng), u(rng), u(rng)};
    worst = std::max(worst, rel_diff(affine_invariant_mean<2>(gm, w).matrix(),
                                     g.transpose() * affine_invariant_mean<2>(m, w).matrix() * g));
  }
  CHECK(worst < 1e-9);
}

namespace {
// A 2D field with sizes (0.01 along y, 0.2 along x) for y < 1 and isotropic 0.3 beyond.
class Layered2 final : public plaf::MetricField<2> {
 public:
  plaf::Metric<2> evaluate(const Eigen::Vector2d& x) const override {
    if (x.y() >= 1) return plaf::Metric<2>::isotropic(0.3);
    return plaf::Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Eigen::Vector2d(0.2, 0.01));
  }
};
}  // namespace

TEST_CASE("metric: an extruded section's metric keeps the section's sizes in the plane, and along z hz or its largest size") {
  const Layered2 section;
  const plaf::ExtrudedMetricField fixed(section, 0.05), own(section, 0);
  const Eigen::Vector3d near(0.3, 0.5, 7), far(0.3, 2, -1);
  CHECK(fixed.evaluate(near).size_along(Eigen::Vector3d::UnitY()) == doctest::Approx(0.01));
  CHECK(fixed.evaluate(near).size_along(Eigen::Vector3d::UnitX()) == doctest::Approx(0.2));
  CHECK(fixed.evaluate(near).size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.05));
  // hz <= 0: the section's largest size, so the 3D metric is isotropic exactly where the 2D one is.
  CHECK(own.evaluate(near).size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.2));
  CHECK(own.evaluate(far).size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.3));
  CHECK(own.evaluate(far).max_size() == doctest::Approx(own.evaluate(far).min_size()));
  CHECK_FALSE(fixed.evaluate(far).max_size() == doctest::Approx(fixed.evaluate(far).min_size()));
}

TEST_CASE("metric: a bad tensor says what is wrong with it: not finite, zero, not symmetric, not positive definite") {
  const auto err = [](const Eigen::Matrix2d& m) -> std::string {
    try {
      plaf::Metric<2>::from_matrix(m);
    } catch (const plaf::InputError& e) {
      return e.what();
    }
    return "no error";
  };
  Eigen::Matrix2d m;
  m << 1, 0, 0, NAN;
  CHECK(err(m) == "metric tensor is not finite");
  CHECK(err(Eigen::Matrix2d::Zero()) == "metric tensor is zero (not positive definite)");
  m << 1, 0.5, 0.4, 1;
  CHECK(err(m) == "metric tensor is not symmetric");
  m << 1, 0, 0, -1;
  CHECK(err(m) == "metric tensor is not positive definite");
  m << 2, 0, 0, 1;
  CHECK(err(m) == "no error");
}
