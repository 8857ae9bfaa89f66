// SPDX-License-Identifier: MIT
#include "surface3d/curvature_metric.h"

#include <doctest/doctest.h>

#include <cmath>

#include "modules/base/error.h"

namespace plaf {
namespace {

class Sphere final : public ReferenceGeometry<3> {
 public:
  explicit Sphere(double r) : r_(r) {}
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return r_ * p.normalized(); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return x.normalized(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return project(p); }
  int num_curves() const override { return 0; }
  double scale() const override { return 4 * r_; }

 private:
  double r_;
};

// The cylinder x^2 + y^2 = r^2 along z.
class Cylinder final : public ReferenceGeometry<3> {
 public:
  explicit Cylinder(double r) : r_(r) {}
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override {
    const Eigen::Vector2d xy = p.head<2>().normalized() * r_;
    return {xy.x(), xy.y(), p.z()};
  }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return Eigen::Vector3d(x.x(), x.y(), 0).normalized(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return project(p); }
  int num_curves() const override { return 0; }
  double scale() const override { return 4 * r_; }

 private:
  double r_;
};

// The roof z = -|x|: two planes meeting at a convex ridge along y.
class Roof final : public ReferenceGeometry<3> {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override {
    const Eigen::Vector3d n = normal(p);
    Eigen::Vector3d q = p - n * n.dot(p);  // onto the plane of p's side (through the origin)
    if ((p.x() >= 0) != (q.x() >= 0)) q = Eigen::Vector3d(0, p.y(), 0);
    return q;
  }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override {
    return Eigen::Vector3d(x.x() >= 0 ? 1 : -1, 0, 1).normalized();
  }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return {0, p.y(), 0}; }
  int num_curves() const override { return 1; }
  double scale() const override { return 1; }
};

TEST_CASE("curvature metric: a sphere's sizes are factor x radius in every tangent direction") {
  const UniformMetricField<3> base(Metric<3>::isotropic(1.0));
  const Sphere sphere(2.0);
  const CurvatureMetricField field(base, sphere, 0.1, 1e-4);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0.3, -1.2, 1.5), Eigen::Vector3d(0, 0, -2.5)}) {
    const CurvatureMetricField::Curvature c = field.curvature(x, 0.25);
    CHECK(c.k1 == doctest::Approx(0.5).epsilon(0.02));
    CHECK(c.k2 == doctest::Approx(0.5).epsilon(0.02));
    const Metric<3> m = field.evaluate(x);
    const Eigen::Vector3d n = x.normalized();
    CHECK(m.size_along(c.d1) == doctest::Approx(0.2).epsilon(0.03));
    CHECK(m.size_along(c.d2) == doctest::Approx(0.2).epsilon(0.03));
    CHECK(m.size_along(n) == doctest::Approx(1.0).epsilon(0.03));  // the base's, across the surface
  }
}

TEST_CASE("curvature metric: the chord cap keeps an order-Q triangle within its tolerance of a sphere") {
  // Radius 2, factor 0.3 (sizes 0.6), chord tolerance 0.01: at Q1 a chord of 0.6 sags
  // 0.6^2 / 16 = 0.0225, so the cap sets h = sqrt(8 R tol) = 0.4 (sag 0.01); at Q2 the cap,
  // 2R (6 tol / R)^(1/3) = 1.24, is looser than the factor's 0.6, which stays.
  const UniformMetricField<3> base(Metric<3>::isotropic(1.0));
  const Sphere sphere(2.0);
  const Eigen::Vector3d x(0.3, -1.2, 1.5);
  const CurvatureMetricField::Curvature c = CurvatureMetricField(base, sphere, 0.3, 1e-4).curvature(x, 0.25);
  const CurvatureMetricField q1(base, sphere, 0.3, 1e-4, ChordCap{1, 0.01});
  const double h1 = q1.evaluate(x).size_along(c.d1);
  CHECK(h1 == doctest::Approx(0.4).epsilon(0.03));
  CHECK(h1 * h1 / (8 * 2.0) == doctest::Approx(0.01).epsilon(0.06));  // the chord's sag is the tolerance
  const CurvatureMetricField q2(base, sphere, 0.3, 1e-4, ChordCap{2, 0.01});
  CHECK(q2.evaluate(x).size_along(c.d1) == doctest::Approx(0.6).epsilon(0.03));
  // A tolerance looser than the radius leaves the factor's size; order 0 is off.
  CHECK(CurvatureMetricField(base, sphere, 0.3, 1e-4, ChordCap{1, 5.0}).evaluate(x).size_along(c.d1) ==
        doctest::Approx(0.6).epsilon(0.03));
  CHECK(CurvatureMetricField(base, sphere, 0.3, 1e-4, ChordCap{0, 0.01}).evaluate(x).size_along(c.d1) ==
        doctest::Approx(0.6).epsilon(0.03));
}

TEST_CASE("curvature metric: a cylinder is refined around, not along, and h_min caps a tight radius") {
  const UniformMetricField<3> base(Metric<3>::isotropic(0.5));
  const Cylinder cyl(0.05);
  const CurvatureMetricField field(base, cyl, 0.3, 0.02);
  const Eigen::Vector3d x(0.05, 0, 0.3);
  const CurvatureMetricField::Curvature c = field.curvature(x, 0.125);
  CHECK(std::abs(c.k1) == doctest::Approx(20).epsilon(0.05));  // 1 / 0.05, measured at a halved step
  CHECK(std::abs(c.k2) < 1e-6);
  CHECK(std::abs(c.d1.z()) < 1e-6);  // around the axis
  const Metric<3> m = field.evaluate(x);
  CHECK(m.size_along(Eigen::Vector3d::UnitY()) == doctest::Approx(0.02).epsilon(0.03));  // 0.3 x 0.05 < h_min
  CHECK(m.size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.5).epsilon(0.03));
}

TEST_CASE("curvature metric: a ridge is not curvature") {
  const UniformMetricField<3> base(Metric<3>::isotropic(0.2));
  const Roof roof;
  const CurvatureMetricField field(base, roof, 0.3, 1e-3);
  for (const double x : {0.0, 0.01, -0.03, 0.3}) {
    CAPTURE(x);
    const Metric<3> m = field.evaluate(Eigen::Vector3d(x, 0.1, -std::abs(x)));
    CHECK(m.min_size() == doctest::Approx(0.2).epsilon(1e-6));
  }
}

TEST_CASE("curvature metric: bad parameters are refused") {
  const UniformMetricField<3> base(Metric<3>::isotropic(0.2));
  const Roof roof;
  CHECK_THROWS_AS(CurvatureMetricField(base, roof, 0.0, 1e-3), ConfigError);
  CHECK_THROWS_AS(CurvatureMetricField(base, roof, 0.3, -1.0), ConfigError);
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

// The roof without its ridge declared as a curve: a crease finer than h_min is then curvature.
class UndeclaredRoof final : public ReferenceGeometry<3> {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return roof_.project(p); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return roof_.normal(x); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return roof_.project(p); }
  int num_curves() const override { return 0; }
  double scale() const override { return 1; }

 private:
  Roof roof_;
};

TEST_CASE("curvature metric: an unresolved crease off the feature curves gets the smallest size") {
  const UniformMetricField<3> base(Metric<3>::isotropic(0.2));
  const UndeclaredRoof roof;
  const CurvatureMetricField field(base, roof, 0.3, 1e-3);
  const Metric<3> m = field.evaluate(Eigen::Vector3d(0, 0.1, 0));
  CHECK(m.size_along(Eigen::Vector3d(1, 0, -1).normalized()) == doctest::Approx(1e-3).epsilon(1e-6));
  CHECK(m.size_along(Eigen::Vector3d::UnitY()) == doctest::Approx(0.2).epsilon(1e-6));
}

}  // namespace
}  // namespace plaf
