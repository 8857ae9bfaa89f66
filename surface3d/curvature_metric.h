// SPDX-License-Identifier: MIT
// A metric field that follows the surface's curvature: the base field intersected (metric.h) with
// a curvature metric whose sizes along the principal directions of the closest reference point are
// factor / |kappa_i| (at least h_min), so a curved surface is resolved at a fixed angle per edge
// (the 3D analogue of the 2D wall law's curvature_factor), and at most what the chord error of
// the surface's order allows (ChordCap). The normal direction keeps the base metric's size.
//
// Curvature is measured from the reference's normals by central differences: the shape operator
// S t ~ (n(x + e t) - n(x - e t)) / 2e along two tangent directions. The step starts at a quarter of
// the base size and halves while the normal turns by more than 20 degrees over it, so tight
// leading edges are measured at their own scale. A turn still unresolved at a quarter of h_min is
// a ridge when a feature curve of the reference passes within the step (the remesher keeps
// ridges; there is no curvature across them to resolve) and otherwise a radius tighter than h_min
// (the size is then h_min).
#pragma once

#include "modules/metric/metric.h"
#include "surface3d/discrete_reference.h"

namespace plaf {

// The chord error an order-Q triangle may leave: sizes are also at most the length over which
// an order-Q interpolant of a circle of radius R departs from it by `tolerance` (R (h / 2R)^(Q+1)
// / (Q+1)!: h^2 / 8R at Q1), so a surface meets surface.fidelity_tol at every order (at Q1,
// curvature_factor 0.3 alone leaves 0.011 R, which on the published bullet was 1.03e-3 of the
// diagonal against a tolerance of 1e-3). Off when order or tolerance is 0.
struct ChordCap {
  int order = 0;
  double tolerance = 0;
};

class CurvatureMetricField final : public MetricField<3> {
 public:
  // base and reference must outlive the field.
  CurvatureMetricField(const MetricField<3>& base, const ReferenceGeometry<3>& reference, double factor, double h_min,
                       ChordCap chord = {});
  Metric<3> evaluate(const Point& x) const override;

  // The principal curvatures (|kappa_1| >= |kappa_2|, signed: > 0 convex) and their unit
  // directions at the reference point closest to x.
  struct Curvature {
    double k1 = 0, k2 = 0;
    Eigen::Vector3d d1, d2, normal;
  };
  Curvature curvature(const Eigen::Vector3d& x, double step) const;

 private:
  bool near_curve(const Eigen::Vector3d& x, double distance) const;

  const MetricField<3>& base_;
  const ReferenceGeometry<3>& ref_;
  double factor_, h_min_;
  ChordCap chord_;
};

}  // namespace plaf
