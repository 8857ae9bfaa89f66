// SPDX-License-Identifier: MIT
// The analytic ellipsoid (see analytic.h): closest point by a safeguarded Newton iteration on the
// Lagrange multiplier, and an initial triangulation from a cube lattice mapped to the ellipsoid.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "surface3d/analytic_builder.h"

namespace plaf {

using analytic_detail::kEps;
using analytic_detail::kInf;
using analytic_detail::MeshBuilder;
using analytic_detail::num;
using Eigen::Vector3d;

namespace {

// The closest point of the ellipsoid sum (x_i / e_i)^2 = 1 to y (both relative to the centre).
// Stationary points are x_i = e_i^2 y_i / (e_i^2 + t); the closest one has the largest multiplier
// t, the root of F(t) = sum (e_i y_i / (e_i^2 + t))^2 - 1 on (-min e_i^2, inf) over the components
// with y_i != 0 (F decreases there from +inf to -1). When that root lies below -e_k^2 for the
// smallest axis k with y_k = 0 (points inside, near the plane y_k = 0), the closest point leaves
// that plane: t = -e_k^2 and x_k follows from the constraint.

// The root t of F for q = |y| (componentwise): Newton steps, bisection when a step leaves the
// bracket, down to rounding; -inf when q = 0 (no component constrains t).
double largest_multiplier(const Vector3d& e, const Vector3d& q) {
  double m = kInf;
  for (int i = 0; i < 3; ++i)
    if (q[i] > 0) m = std::min(m, e[i] * e[i]);
  if (!(m < kInf)) return -kInf;
  const auto F = [&](double s, double* dF) {
    double f = -1, d = 0;
    for (int i = 0; i < 3; ++i) {
      if (q[i] == 0) continue;
      const double w = e[i] * q[i] / (e[i] * e[i] + s);
      f += w * w;
      d -= 2 * w * w / (e[i] * e[i] + s);
    }
    *dF = d;
    return f;
  };
  double lo = -m, hi = std::max(0.0, e.maxCoeff() * q.norm());
  double t = hi;
  for (int iter = 0; iter < 300; ++iter) {
    double d = 0;
    const double f = F(t, &d);
    if (f == 0) break;
    if (f > 0)
      lo = t;
    else
      hi = t;
    double next = d < 0 ? t - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 4 * kEps * std::max(std::abs(t), m) || hi - lo <= 4 * kEps * std::max(std::abs(lo), m)) {
      t = next;
      break;
    }
    t = next;
  }
  return t;
}

// The stationary point x_i = e_i^2 q_i / (e_i^2 + t) of multiplier t. Components whose
// denominator e_i^2 + t is tiny carry a large relative error (the cancellation in e_i^2 + t):
// they are rescaled together so the constraint holds, keeping their mutual ratios (exact when
// their axes are equal).
Vector3d point_at_multiplier(const Vector3d& e, const Vector3d& q, double t) {
  Vector3d x = Vector3d::Zero();
  double rest = 1, stiff = 0;
  std::array<bool, 3> is_stiff{};
  for (int i = 0; i < 3; ++i) {
    if (q[i] == 0) continue;
    const double den = e[i] * e[i] + t;
    x[i] = e[i] * e[i] * q[i] / den;
    const double w = (x[i] / e[i]) * (x[i] / e[i]);
    is_stiff[i] = den < 1e-3 * e[i] * e[i];
    if (is_stiff[i])
      stiff += w;
    else
      rest -= w;
  }
  if (stiff > 0) {
    const double lambda = std::sqrt(std::max(0.0, rest) / stiff);
    for (int i = 0; i < 3; ++i)
      if (is_stiff[i]) x[i] *= lambda;
  }
  return x;
}

Vector3d ellipsoid_closest(const Vector3d& e, const Vector3d& y) {
  const Vector3d q = y.cwiseAbs();
  int kmin = 0;
  for (int i = 1; i < 3; ++i)
    if (e[i] < e[kmin]) kmin = i;
  const double t = largest_multiplier(e, q);
  const double ek2 = e[kmin] * e[kmin];
  Vector3d x = Vector3d::Zero();
  if (q[kmin] == 0 && t < -ek2) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      if (i == kmin || q[i] == 0) continue;
      x[i] = e[i] * e[i] * q[i] / (e[i] * e[i] - ek2);
      sum += (x[i] / e[i]) * (x[i] / e[i]);
    }
    x[kmin] = e[kmin] * std::sqrt(std::max(0.0, 1 - sum));
  } else {
    x = point_at_multiplier(e, q, t);
  }
  // Final exact normalisation (a relative change of a few ulps).
  const double g = std::sqrt((x.cwiseQuotient(e)).squaredNorm());
  if (g > 0) x /= g;
  for (int i = 0; i < 3; ++i)
    if (y[i] < 0) x[i] = -x[i];
  return x;
}

class EllipsoidReference final : public ReferenceGeometry<3> {
 public:
  EllipsoidReference(const Vector3d& c, const Vector3d& e) : c_(c), e_(e) {}
  Vector3d project(const Vector3d& p) const override { return c_ + ellipsoid_closest(e_, p - c_); }
  Vector3d normal(const Vector3d& x) const override {
    const Vector3d f = ellipsoid_closest(e_, x - c_);
    return f.cwiseQuotient(e_.cwiseProduct(e_)).normalized();
  }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    throw MesherError("ellipsoid: no feature curve " + std::to_string(curve) + " (an ellipsoid has none); point " +
                      num(p.x()) + " " + num(p.y()) + " " + num(p.z()));
  }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * e_.norm(); }

 private:
  Vector3d c_, e_;
};

// The cube lattice's map: cube coordinates w in [-1, 1]^3 to the unit sphere point w / |w|,
// scaled by the semi-axes.
Vector3d cube_to_ellipsoid(const Vector3d& center, const Vector3d& semi_axes, const Vector3d& w) {
  return center + semi_axes.cwiseProduct(w.normalized());
}

// Divisions per axis of the cube lattice: the length of the longest quarter ellipse arc an axis's
// divisions map to, over h, so the triangles stay roughly uniform (~h) whatever the axis ratios.
std::array<int, 3> lattice_divisions(const Vector3d& center, const Vector3d& semi_axes, double h) {
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) {
    double len = 0;
    for (int other = 1; other <= 2; ++other) {
      const int b = (a + other) % 3;
      double l = 0;
      Vector3d prev;
      for (int m = 0; m <= 64; ++m) {
        Vector3d w = Vector3d::Zero();
        w[a] = std::tan(M_PI / 4 * (-1 + 2.0 * m / 64));
        w[b] = 1;
        const Vector3d p = cube_to_ellipsoid(center, semi_axes, w);
        if (m > 0) l += (p - prev).norm();
        prev = p;
      }
      len = std::max(len, l);
    }
    n[a] = std::max(1, static_cast<int>(std::lround(len / h)));
  }
  return n;
}

}  // namespace

AnalyticBody make_ellipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& semi_axes, double h) {
  if (!center.allFinite()) throw ConfigError("ellipsoid: the centre must be finite");
  if (!semi_axes.allFinite() || !(semi_axes.minCoeff() > 0))
    throw ConfigError("ellipsoid: semi-axes must be positive, got " + num(semi_axes.x()) + " " + num(semi_axes.y()) +
                      " " + num(semi_axes.z()));
  analytic_detail::check_h("ellipsoid", h, 2 * semi_axes.maxCoeff());
  AnalyticBody body;
  body.reference = std::make_unique<EllipsoidReference>(center, semi_axes);
  // A cube lattice mapped to the ellipsoid, with equal-angle spacing of the cube coordinates
  // (w = tan(pi/4 u)).
  const std::array<int, 3> n = lattice_divisions(center, semi_axes, h);
  MeshBuilder mb;
  analytic_detail::build_cube(mb, n, [&](int i, int j, int k) {
    const Vector3d u(-1 + 2.0 * i / n[0], -1 + 2.0 * j / n[1], -1 + 2.0 * k / n[2]);
    Vector3d w;
    for (int a = 0; a < 3; ++a) w[a] = std::tan(M_PI / 4 * u[a]);
    return cube_to_ellipsoid(center, semi_axes, w);
  });
  mb.end_patch(false);  // the map keeps the cube's orientation
  body.initial = mb.build("ellipsoid");
  return body;
}

}  // namespace plaf
