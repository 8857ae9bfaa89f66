// SPDX-License-Identifier: MIT
// A 2D metric field extruded along z (the metric of a wing between symmetry planes whose section
// runs a 2D case, modules/mesh/extrude_front.h): at (x, y, z) the section's metric at (x, y) in
// the plane and the size hz along z. A direction n with no z component has the section's size, so
// the 3D layers' heights along such normals are the 2D heights. With hz <= 0 the size along z is
// the section's largest size at (x, y): its size along the wall next to a wall metric's body, so
// the 3D metric is isotropic exactly where the section's is (the isotropic stop of the layers
// stops both alike).
#pragma once

#include <Eigen/Eigenvalues>
#include <cmath>

#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

class ExtrudedMetricField final : public MetricField<3> {
 public:
  // section must outlive the field; hz > 0, or <= 0 for the section's largest size.
  ExtrudedMetricField(const MetricField<2>& section, double hz) : section_(section), hz_(hz) {}
  Metric<3> evaluate(const Point& x) const override {
    const Eigen::Matrix2d m2 = section_.evaluate(x.head<2>()).matrix();
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    m.topLeftCorner<2, 2>() = m2;
    const double hz = hz_ > 0 ? hz_ : std::sqrt(1 / Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(m2).eigenvalues()[0]);
    m(2, 2) = 1 / (hz * hz);
    return Metric<3>::from_matrix(m);
  }

 private:
  const MetricField<2>& section_;
  double hz_;
};

}  // namespace metric
}  // namespace plaf
