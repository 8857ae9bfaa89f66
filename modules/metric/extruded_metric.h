// SPDX-License-Identifier: MIT
// A 2D metric field extruded along z (the metric of a wing between symmetry planes whose section
// runs a 2D case, modules/mesh/extrude_front.h): at (x, y, z) the section's metric at (x, y) in
// the plane and the size hz along z. A direction n with no z component has the section's size, so
// the 3D layers' heights along such normals are the 2D heights.
#pragma once

#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

class ExtrudedMetricField final : public MetricField<3> {
 public:
  // section must outlive the field; hz > 0.
  ExtrudedMetricField(const MetricField<2>& section, double hz) : section_(section), hz_(hz) {}
  Metric<3> evaluate(const Point& x) const override {
    const Eigen::Matrix2d m2 = section_.evaluate(x.head<2>()).matrix();
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    m.topLeftCorner<2, 2>() = m2;
    m(2, 2) = 1 / (hz_ * hz_);
    return Metric<3>::from_matrix(m);
  }

 private:
  const MetricField<2>& section_;
  double hz_;
};

}  // namespace metric
}  // namespace plaf
