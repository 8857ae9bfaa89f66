// SPDX-License-Identifier: MIT
#include "modules/metric/wall_metric_3d.h"

#include <cmath>

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {

namespace {

// x within this x the reference's scale of the wall is on it (as in 2D, wall_metric.cpp).
constexpr double kOnWallRel = 1e-9;
// The closest point's accuracy, relative to the reference's scale (the spline closest point of
// a wing's section, spline_loop.h; the other references are exact to rounding).
constexpr double kClosestPointRel = 1e-12;

}  // namespace

WallPowerLawField3::WallPowerLawField3(std::shared_ptr<const ReferenceGeometry<3>> wall, const WallLawParams& params)
    : wall_(std::move(wall)), p_(params) {
  if (!wall_) throw MesherError("wall_power_law metric: no wall (the geometry gave no reference)");
  if (p_.delta <= 0) p_.delta = p_.h0;
}

WallPowerLawField3::Sizes WallPowerLawField3::sizes(const Eigen::Vector3d& x) const {
  if (!x.allFinite()) throw MesherError("wall_power_law metric: evaluated at a non-finite point");
  // 1. The closest wall point, the reference's normal there, and the direction from it to x.
  Eigen::Vector3d wall_normal;
  const Eigen::Vector3d p = wall_->project(x, wall_normal);
  const Eigen::Vector3d offset = x - p;
  Sizes s;
  s.distance = offset.norm();
  s.normal_direction = wall_normal;
  const double scale = wall_->scale();
  // The metric depends on the normal's line only (n n^T), so the offset's direction serves
  // outside the body (the closest point's normal cone: one face's normal on a face, anything
  // between the faces' normals behind a ridge or corner, up to 175 degrees from the reported
  // normal behind a thin trailing edge) and inside it alike (-n under a face). Only where the
  // offset is within the closest point's accuracy of the normal's line is the normal used.
  if (s.distance > kOnWallRel * scale) {
    const Eigen::Vector3d u = offset / s.distance;
    const double tol = kClosestPointRel * scale / s.distance;
    if ((u - wall_normal).norm() > tol && (u + wall_normal).norm() > tol) s.normal_direction = u;
  }
  // 2. Sizes, as in 2D (wall_metric.h).
  s.normal = normal_size(s.distance);
  s.tangential = wall_tangential_size(p_, p_.h_wall_max, s.normal);
  return s;
}

Metric<3> WallPowerLawField3::evaluate(const Eigen::Vector3d& x) const {
  const Sizes s = sizes(x);
  // Two unit tangents completing the normal to an orthonormal frame.
  const Eigen::Vector3d& n = s.normal_direction;
  const Eigen::Vector3d a = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix3d r;
  r.col(0) = (a - n * n.dot(a)).normalized();
  r.col(1) = n.cross(r.col(0));
  r.col(2) = n;
  return Metric<3>::from_directions(r, Eigen::Vector3d(s.tangential, s.tangential, s.normal));
}

}  // namespace metric
}  // namespace plaf
