// SPDX-License-Identifier: MIT
// Internal to the analytic wing (analytic.h): one end of a wing rounded as a half body of
// revolution about the section's camber line.
//
// At station s in [0, 1] the arcs from the leading edge (minimum x) to the trailing-edge
// corner(s) give points P1(s), P2(s) at the same normalised chord station
// x = x_le + s^2 (x_te - x_le) (the square makes the arcs' parameters smooth in s at the leading
// edge, where x is quadratic in the spline parameter); the cap is
// C(s, theta) = M + r (cos theta d + sin theta e), M = (P1 + P2) / 2, r = |P1 - P2| / 2,
// d = (P1 - P2) / (2 r), e = the outward span direction, theta in [0, pi]. At theta = 0, pi it
// meets the extrusion with the tangent e: tangent-continuous. The arc parameter as a function of s
// is tabulated (bisection on the monotone x) and interpolated by cubic Hermite pieces, so the cap
// is an exactly defined smooth surface with analytic derivatives.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "modules/geometry/spline_loop.h"
#include "surface3d/analytic_builder.h"

namespace plaf::analytic_detail {

class RoundedCap {
 public:
  // The cap of the wing section `loop` (kept by pointer: it must outlive the cap) at span station
  // z, bulging towards dir (+1 or -1 along z); t_le is the leading edge's parameter, t_a and t_b
  // the trailing-edge corners reached going forward and backward from it (equal modulo the
  // period for a sharp trailing edge).
  RoundedCap(const SplineLoop* loop, double t_le, double t_a, double t_b, double z, double dir, bool sharp);

  // A lower bound on the distance from p to the cap.
  double distance_bound(const Eigen::Vector3d& p) const { return box_.exteriorDistance(p); }

  // Spline parameter of arc 0 (leading edge to t_a) or 1 (leading edge to t_b) at fraction u.
  double arc_t(int arc, double u) const { return t_le_ + u * ((arc == 0 ? t_a_ : t_b_) - t_le_); }
  // The arc's spline parameter at station s, and its derivative.
  std::pair<double, double> station_t(int arc, double s) const;

  // The half circle at station s: centre m, radius r, directions d and e, and the derivatives of
  // m, d and r with respect to s.
  struct Section {
    Eigen::Vector3d m, d, e, dm, dd;
    double r, dr;
  };
  Section section(double s) const;
  static Eigen::Vector3d at(const Section& c, double theta) {
    return c.m + c.r * (std::cos(theta) * c.d + std::sin(theta) * c.e);
  }
  // Closest angle of the section's half circle to p.
  static double closest_theta(const Section& c, const Eigen::Vector3d& p) {
    const Eigen::Vector3d w = p - c.m;
    const double a = w.dot(c.d), b = w.dot(c.e);
    if (b <= 0) return a >= 0 ? 0.0 : M_PI;
    return std::atan2(b, a);
  }

  struct Foot {
    double s = 0, theta = 0;
    Eigen::Vector3d point;
    double distance = kInf;
  };
  // The closest point of the cap to p.
  Foot closest(const Eigen::Vector3d& p) const;

  // The outward unit normal at (s, theta).
  Eigen::Vector3d normal(double s, double theta) const;
  double z() const { return z_; }
  double dir() const { return dir_; }
  double max_radius() const;

 private:
  // Fills table_[arc] and slope_[arc]: the arc's fraction u at the stations m / kTable, and
  // du/ds there.
  void tabulate(int arc);
  // box_: a dense grid of the cap's points, padded by the largest grid spacing (the surface
  // never strays farther than that from its grid).
  void bound();

  static constexpr int kTable = 512;
  static constexpr int kSamples = 64;
  const SplineLoop* loop_;
  double t_le_, t_a_, t_b_, z_, dir_;
  bool sharp_;
  double x_le_ = 0;
  std::array<std::vector<double>, 2> table_, slope_;
  Eigen::AlignedBox3d box_;
};

}  // namespace plaf::analytic_detail
