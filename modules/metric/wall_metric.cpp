// SPDX-License-Identifier: MIT
#include "modules/metric/wall_metric.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {

WallLawParams parse_wall_law_params(const ConfigNode& m, int dim) {
  if (dim == 3) {
    if (m.has("curvature_factor"))
      throw ConfigError(m.where("curvature_factor") +
                        ": not a 3D wall_power_law key: sizes along curved walls come from the surface section's "
                        "curvature_factor (surface: {curvature_factor: ...})");
    if (m.has("h_corner"))
      throw ConfigError(m.where("h_corner") +
                        ": not a 3D wall_power_law key: the sizes along a 3D wall are h_wall_max, and the surface "
                        "stage keeps its ridges and corners");
  }
  WallLawParams w;
  w.h0 = m.get_positive("h0", w.h0);
  w.growth = m.get_in_range("growth", w.growth, 1.0, 10.0, Bounds::OpenLow);  // > 1: layers grow
  w.exponential = m.get_choice("law", "linear", {"linear", "exponential"}) == "exponential";
  w.delta = m.get_positive("delta", w.h0);
  w.h_max = m.get_positive("h_max", w.h_max);
  w.h_wall_max = m.get_positive("h_wall_max", w.h_wall_max);
  if (dim == 2) {  // 3D refuses them above
    w.curvature_factor = m.get_positive("curvature_factor", w.curvature_factor);
    w.h_corner = m.get_positive("h_corner", w.h_corner);
  }
  if (w.h0 > w.h_max) throw ConfigError(m.where("h0") + ": must not exceed h_max");
  return w;
}

double wall_normal_size(const WallLawParams& p, double d) {
  const double delta = p.delta > 0 ? p.delta : p.h0;
  const double h = p.exponential ? p.h0 * std::pow(p.growth, d / delta) : p.h0 + (p.growth - 1) * d;
  return std::min(h, p.h_max);
}

double wall_tangential_size(const WallLawParams& p, double h_wall, double h_perp) {
  return std::min(p.h_max, std::max(h_wall, h_perp));
}

WallPowerLawField::WallPowerLawField(std::vector<SplineLoop> walls, const WallLawParams& params)
    : walls_(std::move(walls)), p_(params) {
  if (walls_.empty()) throw InputError("wall_power_law metric: the geometry has no wall");
  for (const SplineLoop& w : walls_) {
    for (int c : w.corners()) corners_.push_back(w.points()[c]);
    length_scale_ = std::max(length_scale_, w.length());
  }
  if (p_.delta <= 0) p_.delta = p_.h0;
}

double WallPowerLawField::normal_size(double d) const { return wall_normal_size(p_, d); }

WallPowerLawField::Sizes WallPowerLawField::sizes(const Eigen::Vector2d& x) const {
  if (!x.allFinite()) throw MesherError("wall_power_law metric: evaluated at a non-finite point");
  // 1. The closest wall point over all walls.
  const SplineLoop* wall = nullptr;
  SplineLoop::Closest best{0, x, std::numeric_limits<double>::infinity()};
  for (const SplineLoop& w : walls_) {
    const SplineLoop::Closest c = w.closest_point(x);
    if (c.distance < best.distance) {
      best = c;
      wall = &w;
    }
  }
  if (!wall) throw MesherError("wall_power_law metric: no wall point found from a finite point");
  Sizes s;
  s.distance = best.distance;
  // The normal: at a smooth closest point x - p is along the wall normal, so use the exact spline
  // normal with the sign of x - p (the closest point's own rounding, ~1e-12 of the geometry,
  // would otherwise tilt the direction of a tiny x - p arbitrarily). At a corner the normals of
  // the two sides differ and x - p points into the corner's fan: use it, unless x is on the wall.
  const Eigen::Vector2d wall_normal = wall->normal(best.t);
  const double on_wall = 1e-9 * length_scale_;
  bool at_corner = false;
  for (int c : wall->corners()) {
    const double dt = std::abs(best.t - c);
    at_corner = at_corner || std::min(dt, wall->period() - dt) < 1e-9;
  }
  if (best.distance <= on_wall)
    s.normal_direction = wall_normal;
  else if (at_corner)
    s.normal_direction = (x - best.point) / best.distance;
  else
    s.normal_direction = (x - best.point).dot(wall_normal) >= 0 ? wall_normal : Eigen::Vector2d(-wall_normal);

  // 2. Sizes.
  s.normal = normal_size(best.distance);
  const double kappa = std::abs(wall->curvature(best.t));
  double h_par = kappa > 0 ? std::min(p_.h_wall_max, p_.curvature_factor / kappa) : p_.h_wall_max;
  for (const Eigen::Vector2d& c : corners_)
    h_par = std::min(h_par, p_.h_corner + (p_.growth - 1) * (best.point - c).norm());
  s.tangential = wall_tangential_size(p_, h_par, s.normal);
  return s;
}

Metric<2> WallPowerLawField::evaluate(const Eigen::Vector2d& x) const {
  const Sizes s = sizes(x);
  Eigen::Matrix2d r;
  r.col(0) = Eigen::Vector2d(-s.normal_direction[1], s.normal_direction[0]);
  r.col(1) = s.normal_direction;
  return Metric<2>::from_directions(r, Eigen::Vector2d(s.tangential, s.normal));
}

}  // namespace metric
}  // namespace plaf
