// SPDX-License-Identifier: MIT
// The analytic wing's reference geometry (see wing_reference.h).
#include "surface3d/wing_reference.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "modules/base/error.h"

namespace plaf::analytic_detail {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

// Exact closest parameter of the loop to x restricted to [t0, t1] (t1 > t0, unwrapped): the
// global closest point when it lies in the range, else the best of a dense sampling refined by a
// bracketed root of (p(t) - x) . p'(t).
double closest_on_range(const SplineLoop& loop, const Vector2d& x, double t0, double t1) {
  const double P = loop.period();
  const SplineLoop::Closest g = loop.closest_point(x);
  double tg = g.t;
  while (tg < t0) tg += P;
  while (tg >= t0 + P) tg -= P;
  if (tg <= t1 || t1 - t0 >= P) return tg;
  const int samples = std::max(8, static_cast<int>(std::ceil((t1 - t0) * 16)));
  double best_t = t0, best_d = kInf;
  for (int k = 0; k <= samples; ++k) {
    const double t = t0 + (t1 - t0) * k / samples;
    const double d = (loop.point(t) - x).squaredNorm();
    if (d < best_d) best_d = d, best_t = t;
  }
  const double step = (t1 - t0) / samples;
  double lo = std::max(t0, best_t - step), hi = std::min(t1, best_t + step);
  const auto f = [&](double t) { return (loop.point(t) - x).dot(loop.derivative(t)); };
  double flo = f(lo), fhi = f(hi);
  if (flo < 0 && fhi > 0) {
    for (int iter = 0; iter < 200 && hi - lo > 4 * kEps * std::max(1.0, std::abs(hi)); ++iter) {
      const double mid = 0.5 * (lo + hi);
      const double fm = f(mid);
      if (fm == 0) {
        lo = hi = mid;
        break;
      }
      (fm < 0 ? lo : hi) = mid;
    }
    const double r = 0.5 * (lo + hi);
    if ((loop.point(r) - x).squaredNorm() < best_d) best_t = r;
  }
  return best_t;
}

}  // namespace

WingReference::WingReference(SplineLoop loop, double span, std::array<WingEnd, 2> ends, std::vector<int> te_corners)
    : loop_(std::move(loop)), span_(span), ends_(ends) {
  for (int c : loop_.corners()) {
    corner_t_.push_back(c);
    corner_convex_.push_back(turning_angle(loop_.points(), c) < 0);
  }
  if (ends_[0] == WingEnd::Rounded || ends_[1] == WingEnd::Rounded) make_caps(te_corners);
  Eigen::AlignedBox3d box;
  const double P = loop_.period();
  for (int k = 0; k < 16 * loop_.num_points(); ++k) {
    const Vector2d q = loop_.point(P * k / (16.0 * loop_.num_points()));
    box.extend(Vector3d(q.x(), q.y(), 0));
    box.extend(Vector3d(q.x(), q.y(), span_));
  }
  for (const auto& cap : caps_)
    if (cap) box.extend(Vector3d(box.min().x(), box.min().y(), cap->z() + cap->dir() * cap->max_radius()));
  scale_ = box.diagonal().norm();
}

void WingReference::make_caps(const std::vector<int>& te_corners) {
  // Leading edge: the minimum of x on the spline, near the leftmost point.
  const auto& pts = loop_.points();
  int i = 0;
  for (int k = 1; k < loop_.num_points(); ++k)
    if (pts[k].x() < pts[i].x()) i = k;
  double lo = i - 1.0, hi = i + 1.0;
  for (int iter = 0; iter < 100; ++iter) {
    const double mid = 0.5 * (lo + hi);
    (loop_.derivative(mid).x() < 0 ? lo : hi) = mid;
  }
  t_le_ = 0.5 * (lo + hi);
  const double P = loop_.period();
  if (t_le_ < 0) t_le_ += P;
  // The trailing-edge corners reached going forward (t_a) and backward (t_b) from it.
  t_a_ = kInf, t_b_ = -kInf;
  for (int c : te_corners) {
    double fwd = c, bwd = c;
    while (fwd <= t_le_) fwd += P;
    while (bwd >= t_le_) bwd -= P;
    t_a_ = std::min(t_a_, fwd);
    t_b_ = std::max(t_b_, bwd);
  }
  sharp_ = te_corners.size() == 1;
  for (int end = 0; end < 2; ++end)
    if (ends_[end] == WingEnd::Rounded)
      caps_[end] = std::make_unique<RoundedCap>(&loop_, t_le_, t_a_, t_b_, end == 0 ? 0.0 : span_,
                                                end == 0 ? -1.0 : 1.0, sharp_);
}

Vector3d WingReference::project_to_curve(const Vector3d& p, int curve) const {
  if (curve < 0 || curve >= num_curves())
    throw MesherError("wing: no feature curve " + std::to_string(curve) + " (it has " + std::to_string(num_curves()) +
                      ")");
  Vector3d best = Vector3d::Zero();
  double best_d = kInf;
  for (const CurvePiece& c : curves_[curve]) {
    Vector3d q;
    if (c.kind == CurvePiece::Span) {
      const Vector2d xy = loop_.point(c.t0);
      q = Vector3d(xy.x(), xy.y(), std::clamp(p.z(), c.z0, c.z1));
    } else if (c.kind == CurvePiece::Contour) {
      const Vector2d xy = loop_.point(closest_on_range(loop_, p.head<2>(), c.t0, c.t1));
      q = Vector3d(xy.x(), xy.y(), c.z0);
    } else {
      const RoundedCap::Section s = caps_[c.end]->section(1.0);
      q = RoundedCap::at(s, RoundedCap::closest_theta(s, p));
    }
    if ((q - p).norm() < best_d) best_d = (q - p).norm(), best = q;
  }
  return best;
}

Vector3d WingReference::Foot::normal(const WingReference& w) const {
  switch (part) {
    case Side:
      return w.side_normal(t);
    case Flat:
      return Vector3d(0, 0, end == 0 ? -1 : 1);
    case Cap:
      return w.caps_[end]->normal(s, theta);
    case Base:
      return w.side_normal(w.t_a_ + 0.5);
  }
  return Vector3d::UnitZ();
}

Vector3d WingReference::side_normal(double t) const {
  const double P = loop_.period();
  for (double c : corner_t_) {
    double d = std::fmod(t - c, P);
    if (d < 0) d += P;
    if (d < 1e-9 || P - d < 1e-9) {
      const Vector2d n = (loop_.normal(c - 1e-9) + loop_.normal(c + 1e-9)).normalized();
      return Vector3d(n.x(), n.y(), 0);
    }
  }
  const Vector2d n = loop_.normal(t);
  return Vector3d(n.x(), n.y(), 0);
}

bool WingReference::inside(const Vector2d& xy, const SplineLoop::Closest& c) const {
  const Vector2d w = xy - c.point;
  Vector2d n = loop_.normal(c.t);
  for (double t : corner_t_)
    if (std::abs(c.t - t) < 1e-9 || std::abs(c.t - t - loop_.period()) < 1e-9)
      n = loop_.normal(t - 1e-9) + loop_.normal(t + 1e-9);
  return w.dot(n) < 0;
}

WingReference::Foot WingReference::locate(const Vector3d& p) const {
  const Vector2d xy = p.head<2>();
  const SplineLoop::Closest c = loop_.closest_point(xy);
  Foot best;
  best.part = Foot::Side;
  best.t = c.t;
  best.point = Vector3d(c.point.x(), c.point.y(), std::clamp(p.z(), 0.0, span_));
  best.distance = (p - best.point).norm();
  const bool in = c.distance > 0 && inside(xy, c);
  for (int end = 0; end < 2; ++end) {
    const double z = end == 0 ? 0.0 : span_;
    if (ends_[end] == WingEnd::Flat && in && std::abs(p.z() - z) < best.distance) {
      best.part = Foot::Flat;
      best.end = end;
      best.point = Vector3d(p.x(), p.y(), z);
      best.distance = std::abs(p.z() - z);
    } else if (ends_[end] == WingEnd::Rounded && caps_[end]->distance_bound(p) < best.distance) {
      const RoundedCap::Foot f = caps_[end]->closest(p);
      if (f.distance < best.distance) {
        best.part = Foot::Cap;
        best.end = end;
        best.s = f.s;
        best.theta = f.theta;
        best.point = f.point;
        best.distance = f.distance;
      }
      if (!sharp_) {
        // The flat half disc closing the blunt base under the cap's last half circle.
        const RoundedCap::Section s = caps_[end]->section(1.0);
        const Vector3d w = p - s.m;
        const double a = w.dot(s.d), b = w.dot(s.e);
        const Vector3d n = s.d.cross(s.e);
        if (b >= 0 && a * a + b * b <= s.r * s.r && std::abs(w.dot(n)) < best.distance) {
          best.part = Foot::Base;
          best.end = end;
          best.point = p - w.dot(n) * n;
          best.distance = std::abs(w.dot(n));
        }
      }
    }
  }
  return best;
}

}  // namespace plaf::analytic_detail
