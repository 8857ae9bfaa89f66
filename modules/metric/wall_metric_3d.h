// SPDX-License-Identifier: MIT
// The boundary-layer metric of the paper's Sec. IV.A, eq. (6), in 3D: the 2D wall law
// (wall_metric.h: the same keys, WallLawParams, and the same normal size) measured from the 3D
// reference geometry (modules/geometry/reference.h) of a sphere, ellipsoid, box, wing or surface
// file.
//
// Distance and normal. d = |x - p| with p = project(x), the closest wall point. The normal
// direction is the direction from p to x: the reference's normal (or its opposite, inside the
// body) at a smooth closest point, and across an edge's or a corner's fan (a box's edges, a
// wing's trailing edge, however thin) the direction from the edge or corner, as the 2D field
// does at corners. Only the normal's line matters to the metric, so no inside/outside test is
// needed (an earlier one, the offset within 120 degrees of the reference's normal at p, took the
// far side of a thin trailing edge's fan for the inside and gave its layers the size along the
// wall). Where the direction is undefined -- x within 1e-9 x the reference's scale of the wall --
// or within the closest point's accuracy (1e-12 of the reference's scale over d) of the normal's
// line, it is the reference's normal at p.
// Normal size: h_perp(d) = wall_normal_size(params, d) (wall_metric.h): h0 + (g - 1) d, so that
// layer k is h0 g^k thick, or h0 g^(d/delta); capped at h_max.
// Tangential size: both directions along the wall get wall_tangential_size(params, h_wall_max,
// h_perp), as in 2D: h_wall_max at the wall, never below h_perp (the metric turns isotropic where
// h_perp reaches h_wall_max) and capped at h_max (isotropic h_max where h_perp reaches h_max).
// Curvature and corners: the 2D keys curvature_factor and h_corner have no 3D counterpart here.
// Sizes along a curved wall come from the surface stage's curvature metric
// (surface3d/curvature_metric.h, `surface: {curvature_factor: ...}`, intersected with the sizes
// along the wall below), and the surface stage keeps ridges and corners; the 3D plugin rejects
// both keys (parse_wall_law_params with dim 3).
//
// The surface mesh follows the sizes along the wall alone (WallSizesAlongWall3). A triangle's
// edges are chords of the curved wall: an edge of length L on a wall of radius R leaves it at an
// angle L / (2R), so in the full metric its length would be dominated by the normal size
// (L^2 / (2 R h0): 20 for L = 0.2, R = 1, h0 = 1e-3) and the surface refined to about
// sqrt(2 R h0) instead of h_wall_max. The normal size is the layers'; the metric plugin hands the
// sizes along the wall to the surface stage as RunState<3>::surface_sizes.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "modules/geometry/reference.h"
#include "modules/metric/metric.h"
#include "modules/metric/wall_metric.h"

namespace plaf {
inline namespace metric {

class WallPowerLawField3 final : public MetricField<3> {
 public:
  // The field shares the wall (the 3D geometry stage's reference, which the surface stage may
  // replace in the run state with its own copy), so it stays valid as long as the field.
  WallPowerLawField3(std::shared_ptr<const ReferenceGeometry<3>> wall, const WallLawParams& params);
  Metric<3> evaluate(const Eigen::Vector3d& x) const override;

  // The sizes at x (for tests and reports): normal along normal_direction, tangential along both
  // directions perpendicular to it; distance is d.
  struct Sizes {
    double normal, tangential, distance;
    Eigen::Vector3d normal_direction;
  };
  Sizes sizes(const Eigen::Vector3d& x) const;
  // h_perp at wall distance d.
  double normal_size(double d) const { return wall_normal_size(p_, d); }

 private:
  std::shared_ptr<const ReferenceGeometry<3>> wall_;
  WallLawParams p_;
};

// The wall law's sizes along the wall, what the surface mesh follows (see above): isotropic at
// WallPowerLawField3::sizes(x).tangential.
class WallSizesAlongWall3 final : public MetricField<3> {
 public:
  explicit WallSizesAlongWall3(WallPowerLawField3 wall) : wall_(std::move(wall)) {}
  Metric<3> evaluate(const Eigen::Vector3d& x) const override {
    return Metric<3>::isotropic(wall_.sizes(x).tangential);
  }

 private:
  WallPowerLawField3 wall_;
};

}  // namespace metric
}  // namespace plaf
