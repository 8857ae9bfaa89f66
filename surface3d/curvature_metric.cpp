// SPDX-License-Identifier: MIT
#include "surface3d/curvature_metric.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "modules/base/error.h"

namespace plaf {

namespace {

// Two unit tangents completing n to a right-handed frame.
void tangent_frame(const Eigen::Vector3d& n, Eigen::Vector3d& t1, Eigen::Vector3d& t2) {
  const Eigen::Vector3d a = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  t1 = (a - n * n.dot(a)).normalized();
  t2 = n.cross(t1);
}

}  // namespace

CurvatureMetricField::CurvatureMetricField(const MetricField<3>& base, const ReferenceGeometry<3>& reference,
                                           double factor, double h_min, ChordCap chord)
    : base_(base), ref_(reference), factor_(factor), h_min_(h_min), chord_(chord) {
  if (!(factor > 0)) throw ConfigError("curvature metric: the factor must be positive");
  if (!(h_min > 0)) throw ConfigError("curvature metric: the smallest size must be positive");
}

CurvatureMetricField::Curvature CurvatureMetricField::curvature(const Eigen::Vector3d& x, double step) const {
  Curvature c;
  // Points and normals come from one search each (ReferenceGeometry<3>::project with normal).
  const Eigen::Vector3d x0 = ref_.project(x, c.normal);
  Eigen::Vector3d t[2];
  tangent_frame(c.normal, t[0], t[1]);
  // S t_i: the normal's derivative along t_i, by central differences at a step small enough that
  // the normal turns by less than ~20 degrees (cos 20 = 0.94) across it.
  Eigen::Vector3d st[2];
  for (int i = 0; i < 2; ++i) {
    double e = step;
    st[i].setZero();
    for (int halving = 0; halving < 40; ++halving) {
      Eigen::Vector3d np, nm;
      const Eigen::Vector3d xp = ref_.project(x0 + e * t[i], np), xm = ref_.project(x0 - e * t[i], nm);
      const double dist = (xp - xm).norm();
      if (!(dist > 0)) break;
      st[i] = (np - nm) / dist;
      if ((np - nm).norm() < 0.35) break;  // ~20 degrees: resolved
      e *= 0.5;
      if (e < 0.25 * h_min_) {
        // Unresolved at a quarter of the smallest size: a ridge when a feature curve passes within
        // the step (the curves are kept by the remesher; across them there is no curvature to
        // resolve), else a radius tighter than any size asked for (h_min then caps the size).
        if (near_curve(x0, 4 * e)) st[i].setZero();
        break;
      }
    }
  }
  Eigen::Matrix2d a;
  a << t[0].dot(st[0]), t[0].dot(st[1]), t[1].dot(st[0]), t[1].dot(st[1]);
  a = 0.5 * (a + a.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(a);
  const Eigen::Vector2d k = es.eigenvalues();
  const int big = std::abs(k(0)) >= std::abs(k(1)) ? 0 : 1;
  c.k1 = k(big);
  c.k2 = k(1 - big);
  c.d1 = (t[0] * es.eigenvectors()(0, big) + t[1] * es.eigenvectors()(1, big)).normalized();
  c.d2 = c.normal.cross(c.d1);
  return c;
}

bool CurvatureMetricField::near_curve(const Eigen::Vector3d& x, double distance) const {
  for (int c = 0; c < ref_.num_curves(); ++c)
    if ((ref_.project_to_curve(x, c) - x).norm() <= distance) return true;
  return false;
}

Metric<3> CurvatureMetricField::evaluate(const Point& x) const {
  const Metric<3> base = base_.evaluate(x);
  const Curvature c = curvature(x, 0.25 * base.min_size());
  // Sizes along d1, d2 from the curvature; along the normal the base's largest size, so that the
  // intersection keeps the base there.
  const double big = base.max_size();
  // (h_min may exceed the base's size somewhere: the base's largest size wins there.)
  const double cap = std::max(big, h_min_);
  // The chord cap: h = 2R ((Q+1)! tol / R)^(1/(Q+1)) where tol < R (a looser one leaves the
  // circle's size to the factor).
  auto chord = [&](double r) {
    if (chord_.order <= 0 || !(chord_.tolerance > 0) || chord_.tolerance >= r) return cap;
    double fact = 1;
    for (int i = 2; i <= chord_.order + 1; ++i) fact *= i;
    return 2 * r * std::pow(fact * chord_.tolerance / r, 1.0 / (chord_.order + 1));
  };
  auto size = [&](double k) {
    const double ak = std::max(std::abs(k), 1e-300);
    return std::min(std::max(std::min(factor_ / ak, chord(1 / ak)), h_min_), cap);
  };
  Eigen::Matrix3d dirs;
  dirs.col(0) = c.d1;
  dirs.col(1) = c.d2;
  dirs.col(2) = c.normal;
  const Metric<3> curv = Metric<3>::from_directions(dirs, Eigen::Vector3d(size(c.k1), size(c.k2), big));
  return intersect(base, curv);
}

}  // namespace plaf
