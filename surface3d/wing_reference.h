// SPDX-License-Identifier: MIT
// Internal to the analytic wing (analytic.h): the exact reference geometry of a straight wing, an
// extruded spline loop (the section, z from 0 to span) with flat, rounded (rounded_cap.h) or
// symmetry ends. The closest point is the nearest of the side (the loop's closest point, z
// clamped), a flat end (inside the section), a rounded cap and, under a blunt trailing edge's
// rounded cap, the flat half disc closing its base. Feature curves are lists of pieces (spanwise
// ridge lines, end contour arcs, the half circle closing a blunt base), filled in by the mesh
// builder; project_to_curve takes the nearest piece.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "modules/geometry/reference.h"
#include "modules/geometry/spline_loop.h"
#include "surface3d/analytic.h"
#include "surface3d/analytic_builder.h"
#include "surface3d/rounded_cap.h"

namespace plaf::analytic_detail {

struct CurvePiece {
  enum Kind { Span, Contour, HalfCircle } kind;
  double t0 = 0, t1 = 0;  // Span: corner parameter t0; Contour: the range [t0, t1] (unwrapped)
  double z0 = 0, z1 = 0;  // Span: [z0, z1]; Contour: z0
  int end = 0;            // HalfCircle: the end (0 root, 1 tip)
};

class WingReference final : public ReferenceGeometry<3> {
 public:
  // ends: root (z = 0) and tip (z = span); te_corners: the section's trailing-edge corners (one
  // for a sharp trailing edge, two for a blunt one).
  WingReference(SplineLoop loop, double span, std::array<WingEnd, 2> ends, std::vector<int> te_corners);

  const SplineLoop& loop() const { return loop_; }
  double span() const { return span_; }
  WingEnd end(int e) const { return ends_[e]; }
  const RoundedCap* cap(int e) const { return caps_[e].get(); }
  double t_le() const { return t_le_; }
  double t_a() const { return t_a_; }
  double t_b() const { return t_b_; }
  bool sharp() const { return sharp_; }
  const std::vector<double>& corner_t() const { return corner_t_; }
  const std::vector<bool>& corner_convex() const { return corner_convex_; }
  std::vector<std::vector<CurvePiece>>& curves() { return curves_; }

  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return locate(p).point; }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return locate(x).normal(*this); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int curve) const override;
  int num_curves() const override { return static_cast<int>(curves_.size()); }
  double scale() const override { return scale_; }

 private:
  struct Foot {
    enum Part { Side, Flat, Cap, Base } part = Side;
    Eigen::Vector3d point;
    double distance = kInf;
    double t = 0;             // Side: the loop parameter
    int end = 0;              // Flat, Cap, Base
    double s = 0, theta = 0;  // Cap
    Eigen::Vector3d normal(const WingReference& w) const;
  };

  // The leading edge t_le_ (the minimum of x on the spline), the trailing-edge corners t_a_, t_b_
  // reached going forward and backward from it, and the rounded caps.
  void make_caps(const std::vector<int>& te_corners);
  // Outward normal of the extrusion at loop parameter t (at a corner: the mean of both sides).
  Eigen::Vector3d side_normal(double t) const;
  // Whether 2D point xy lies inside the section (c: its closest loop point).
  bool inside(const Eigen::Vector2d& xy, const SplineLoop::Closest& c) const;
  Foot locate(const Eigen::Vector3d& p) const;

  SplineLoop loop_;
  double span_;
  std::array<WingEnd, 2> ends_;
  std::vector<double> corner_t_;
  std::vector<bool> corner_convex_;
  double t_le_ = 0, t_a_ = 0, t_b_ = 0;
  bool sharp_ = true;
  std::array<std::unique_ptr<RoundedCap>, 2> caps_;
  std::vector<std::vector<CurvePiece>> curves_;
  double scale_ = 1;
};

}  // namespace plaf::analytic_detail
