// SPDX-License-Identifier: MIT
// The rounded wing end (see rounded_cap.h): the tabulated arc parameters, the half-circle
// sections with their derivatives, and the closest point by sampling the stations and then
// Illinois regula falsi on the derivative of the distance.
#include "surface3d/rounded_cap.h"

#include <algorithm>

namespace plaf::analytic_detail {

using Eigen::Vector2d;
using Eigen::Vector3d;

RoundedCap::RoundedCap(const SplineLoop* loop, double t_le, double t_a, double t_b, double z, double dir, bool sharp)
    : loop_(loop), t_le_(t_le), t_a_(t_a), t_b_(t_b), z_(z), dir_(dir), sharp_(sharp) {
  x_le_ = loop_->point(t_le_).x();
  for (int arc = 0; arc < 2; ++arc) tabulate(arc);
  bound();
}

void RoundedCap::tabulate(int arc) {
  const double x_end = loop_->point(arc == 0 ? t_a_ : t_b_).x();
  std::vector<double>& u = table_[arc];
  u.assign(kTable + 1, 0.0);
  u[kTable] = 1;
  for (int m = 1; m < kTable; ++m) {
    const double s = static_cast<double>(m) / kTable;
    const double target = x_le_ + s * s * (x_end - x_le_);
    double lo = 0, hi = 1;
    for (int iter = 0; iter < 60; ++iter) {
      const double mid = 0.5 * (lo + hi);
      (loop_->point(arc_t(arc, mid)).x() < target ? lo : hi) = mid;
    }
    u[m] = 0.5 * (lo + hi);
  }
  std::vector<double>& du = slope_[arc];
  du.assign(kTable + 1, 0.0);
  const double ds = 1.0 / kTable;
  du[0] = (-3 * u[0] + 4 * u[1] - u[2]) / (2 * ds);
  du[kTable] = (3 * u[kTable] - 4 * u[kTable - 1] + u[kTable - 2]) / (2 * ds);
  for (int m = 1; m < kTable; ++m) du[m] = (u[m + 1] - u[m - 1]) / (2 * ds);
}

void RoundedCap::bound() {
  constexpr int kRows = 4 * kSamples, kCols = 16;
  double pad = 0;
  std::vector<Vector3d> row_prev;
  for (int m = 0; m <= kRows; ++m) {
    const Section c = section(static_cast<double>(m) / kRows);
    std::vector<Vector3d> row;
    for (int k = 0; k <= kCols; ++k) {
      row.push_back(at(c, M_PI * k / kCols));
      box_.extend(row.back());
      if (k > 0) pad = std::max(pad, (row[k] - row[k - 1]).norm());
      if (m > 0) pad = std::max(pad, (row[k] - row_prev[k]).norm());
    }
    row_prev = std::move(row);
  }
  box_.min().array() -= pad;
  box_.max().array() += pad;
}

std::pair<double, double> RoundedCap::station_t(int arc, double s) const {
  s = std::clamp(s, 0.0, 1.0);
  const double ds = 1.0 / kTable;
  const int m = std::min(static_cast<int>(s * kTable), kTable - 1);
  const double w = s * kTable - m;
  const std::vector<double>& u = table_[arc];
  const std::vector<double>& du = slope_[arc];
  const double h00 = (1 + 2 * w) * (1 - w) * (1 - w), h10 = w * (1 - w) * (1 - w);
  const double h01 = w * w * (3 - 2 * w), h11 = w * w * (w - 1);
  const double g00 = 6 * w * w - 6 * w, g10 = 3 * w * w - 4 * w + 1, g01 = -g00, g11 = 3 * w * w - 2 * w;
  const double val = h00 * u[m] + h10 * ds * du[m] + h01 * u[m + 1] + h11 * ds * du[m + 1];
  const double der = (g00 * u[m] + g10 * ds * du[m] + g01 * u[m + 1] + g11 * ds * du[m + 1]) / ds;
  const double span = (arc == 0 ? t_a_ : t_b_) - t_le_;
  return {arc_t(arc, val), der * span};
}

RoundedCap::Section RoundedCap::section(double s) const {
  const auto [t1, dt1] = station_t(0, s);
  const auto [t2, dt2] = station_t(1, s);
  const Vector2d p1 = loop_->point(t1);
  const Vector2d p2 = (sharp_ && s >= 1) ? p1 : loop_->point(t2);
  const Vector2d dp1 = loop_->derivative(t1) * dt1, dp2 = loop_->derivative(t2) * dt2;
  Section c;
  const Vector2d w = p1 - p2, dw = dp1 - dp2;
  const double len = w.norm();
  c.m = Vector3d(0.5 * (p1.x() + p2.x()), 0.5 * (p1.y() + p2.y()), z_);
  c.dm = Vector3d(0.5 * (dp1.x() + dp2.x()), 0.5 * (dp1.y() + dp2.y()), 0);
  c.e = Vector3d(0, 0, dir_);
  c.r = 0.5 * len;
  if (len > 0) {
    const Vector2d d = w / len;
    c.d = Vector3d(d.x(), d.y(), 0);
    c.dr = 0.5 * d.dot(dw);
    const Vector2d dd = (dw - d * d.dot(dw)) / len;
    c.dd = Vector3d(dd.x(), dd.y(), 0);
  } else {
    c.d = Vector3d::UnitY();
    c.dr = 0.5 * dw.norm();
    c.dd = Vector3d::Zero();
  }
  return c;
}

RoundedCap::Foot RoundedCap::closest(const Vector3d& p) const {
  const auto eval = [&](double s) {
    const Section c = section(s);
    const double th = closest_theta(c, p);
    Foot f{s, th, at(c, th), 0};
    f.distance = (p - f.point).norm();
    return f;
  };
  // g(s) = half the derivative of the squared distance (envelope theorem over theta).
  const auto g = [&](double s) {
    const Section c = section(s);
    const double th = closest_theta(c, p);
    const Vector3d dir = std::cos(th) * c.d + std::sin(th) * c.e;
    const Vector3d cs = c.dm + c.dr * dir + c.r * std::cos(th) * c.dd;
    return -(p - at(c, th)).dot(cs);
  };
  Foot best;
  int best_m = 0;
  for (int m = 0; m <= kSamples; ++m) {
    const Foot f = eval(static_cast<double>(m) / kSamples);
    if (f.distance < best.distance) best = f, best_m = m;
  }
  double lo = static_cast<double>(std::max(0, best_m - 1)) / kSamples;
  double hi = static_cast<double>(std::min(kSamples, best_m + 1)) / kSamples;
  for (const double s : {lo, hi}) {
    const Foot f = eval(s);
    if (f.distance < best.distance) best = f;
  }
  double glo = g(lo), ghi = g(hi);
  if (glo < 0 && ghi > 0) {
    // Illinois regula falsi with a bisection fallback: converges to the root to rounding.
    int side = 0;
    for (int iter = 0; iter < 200 && hi - lo > 2 * kEps; ++iter) {
      double s = (lo * ghi - hi * glo) / (ghi - glo);
      if (!(s > lo && s < hi) || iter % 8 == 7) s = 0.5 * (lo + hi);
      const double gs = g(s);
      if (gs == 0) {
        lo = hi = s;
        break;
      }
      if (gs < 0) {
        lo = s, glo = gs;
        if (side == -1) ghi *= 0.5;
        side = -1;
      } else {
        hi = s, ghi = gs;
        if (side == 1) glo *= 0.5;
        side = 1;
      }
    }
    const Foot f = eval(0.5 * (lo + hi));
    if (f.distance <= best.distance) best = f;
  }
  return best;
}

Vector3d RoundedCap::normal(double s, double theta) const {
  // Away from the degenerate leading and trailing edges the normal is C_s x C_theta; at them
  // the limit from inside is used.
  s = std::clamp(s, 1e-7, 1 - 1e-7);
  const Section c = section(s);
  const Vector3d dir = std::cos(theta) * c.d + std::sin(theta) * c.e;
  const Vector3d cs = c.dm + c.dr * dir + c.r * std::cos(theta) * c.dd;
  const Vector3d ct = c.r * (-std::sin(theta) * c.d + std::cos(theta) * c.e);
  Vector3d n = cs.cross(ct);
  if (!(n.norm() > 0)) return dir;
  n.normalize();
  return n.dot(dir) < 0 ? Vector3d(-n) : n;
}

double RoundedCap::max_radius() const {
  double r = 0;
  for (int m = 0; m <= kSamples; ++m) r = std::max(r, section(static_cast<double>(m) / kSamples).r);
  return r;
}

}  // namespace plaf::analytic_detail
