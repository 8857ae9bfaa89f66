// SPDX-License-Identifier: MIT
// 2D boundary geometry: closed loops of cubic splines with corners (paper Sec. II.B: "the
// geometry is specified by clockwise loops of cubic splines, with corners allowed").
//
// Conventions (written once, here):
// - The domain lies to the LEFT of every loop: body loops run clockwise, the farfield loop
//   counter-clockwise. normal(t) is the unit LEFT normal (tangent rotated by +90 degrees), so it
//   points into the domain.
// - A loop interpolates its points p_0..p_{n-1} (closed: p_n = p_0 is implied, not stored).
//   Parameter t in [0, n): t = i at point i, chord-length parametrised cubic pieces in between.
// - Between corners the spline is C2 (one cubic interpolant per corner-to-corner segment, with
//   not-a-knot ends); at corners it is only C0. A loop without corners is periodic C2.
// - Turning angle at point i: the signed angle from chord (p_{i-1}, p_i) to chord (p_i, p_{i+1});
//   positive = left turn. Along a clockwise body, a right turn (negative) is a convex corner.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace plaf {
inline namespace geometry {

class SplineLoop {
 public:
  // points: at least 3 distinct points, no repeated closing point; corners: point indices
  // (sorted, unique). Throws InputError naming `name` for degenerate input.
  SplineLoop(std::vector<Eigen::Vector2d> points, std::vector<int> corners, std::string name);

  const std::string& name() const { return name_; }
  int num_points() const { return static_cast<int>(points_.size()); }
  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  const std::vector<int>& corners() const { return corners_; }
  // Parameter range [0, period()), period() = num_points().
  double period() const { return static_cast<double>(points_.size()); }

  Eigen::Vector2d point(double t) const;
  Eigen::Vector2d derivative(double t) const;  // d point / dt
  Eigen::Vector2d tangent(double t) const;     // unit
  Eigen::Vector2d normal(double t) const;      // unit left normal (into the domain)
  double curvature(double t) const;            // signed: > 0 turning left
  // Arc length from t0 to t1 >= t0 (may wrap past the period), Gauss quadrature per piece.
  double arc_length(double t0, double t1) const;
  double length() const { return arc_length(0.0, period()); }
  // The t at arc length s from t0 along the loop (Newton on arc_length; s >= 0).
  double parameter_at(double t0, double s) const;

  // Signed area (> 0 counter-clockwise) of the spline polygon of the points.
  double signed_area() const;

  struct Closest {
    double t;
    Eigen::Vector2d point;
    double distance;
  };
  // Exact closest point on the spline (not the polygon): candidate pieces from a bounding-box
  // tree over the pieces, then Newton on each candidate piece.
  Closest closest_point(const Eigen::Vector2d& x) const;

 private:
  std::string name_;
  std::vector<Eigen::Vector2d> points_;
  std::vector<int> corners_;
  // Piece i (t in [i, i+1]): point = a_i + b_i u + c_i u^2 + d_i u^3, u = t - i.
  std::vector<std::array<Eigen::Vector2d, 4>> coeffs_;
  // Arc length from t = 0 to the start of piece i (size n + 1: the last entry is length()).
  std::vector<double> cumulative_length_;
  struct Tree;
  std::shared_ptr<const Tree> tree_;

  // The piece i and local u in [0, 1) of a parameter t (wrapped into [0, period())).
  std::pair<int, double> locate(double t) const;
  // Arc length from t = 0 to t = piece + u.
  double length_to(int piece, double u) const;
  Closest closest_point_on_piece(int piece, const Eigen::Vector2d& x) const;
};

// Indices whose |turning angle| exceeds threshold_deg (radians internally).
std::vector<int> detect_corners(const std::vector<Eigen::Vector2d>& points, double threshold_deg);
double turning_angle(const std::vector<Eigen::Vector2d>& points, int i);

}  // namespace geometry
}  // namespace plaf
