// SPDX-License-Identifier: MIT
// The boundary-layer metric of the paper's Sec. IV.A, eq. (6): sizes from the wall distance
// normal to the wall and from the wall's curvature along it.
//
// Normal size. Eq. (6) as printed, h_perp = h0 g^(d/h0), names h0 twice ("h0 is the initial
// layer height ... h0 is the growth distance") and taken literally it explodes: the metric
// distance from d to infinity is g^(-d/h0) / ln g, so for g = 1.2 all of space beyond
// d = 9.3 h0 lies within one unit of metric length (and the whole domain within 5.5). What the paper's
// results need is geometric layers, layer k of height h0 g^k, and that is what the default
// law gives:  h_perp(d) = h0 + (g - 1) d  — a layer of height h_perp(d_k) starting at
// d_k = h0 (g^k - 1)/(g - 1) has height h0 g^k exactly. The printed form with a separate growth
// distance delta, h_perp(d) = h0 g^(d/delta), is `law: exponential`.
// Tangential size. h_par = min(h_wall_max, c R) with R the wall's radius of curvature at the
// closest wall point, clipped near corners to h_corner + (g - 1) s (s: distance of the closest
// wall point to the nearest corner), and never below h_perp, so that far from the walls the
// metric becomes isotropic; every size is capped at h_max.
// Directions: the normal is the wall normal at the closest wall point (found with each loop's
// spatial index, spline_loop.h), pointing towards x; near a corner, the direction from the
// corner to x.
// The 3D field (wall_metric_3d.h) takes the same keys and shares the law: wall_normal_size and
// wall_tangential_size below.
#pragma once

#include <vector>

#include "modules/metric/metric.h"
#include "modules/pipeline/config.h"
#include "modules/geometry/spline_loop.h"

namespace plaf {
inline namespace metric {

// Its section (`type: wall_power_law`, the plugin in modules/pipeline/stages.h): h0, growth,
// law, delta, h_max, h_wall_max, curvature_factor, h_corner (3D: all but the last two, an error
// there: curvature sizes come from the surface section's curvature_factor, wall_metric_3d.h).
// Types, defaults and descriptions: `plaf keys metric` (docs/config.md; the lines in
// apps/key_notes.cpp).
struct WallLawParams {
  double h0 = 0.005;
  double growth = 1.2;
  bool exponential = false;
  double delta = 0.0;  // 0: h0
  double h_max = 1.0;
  double h_wall_max = 0.05;
  double curvature_factor = 0.25;
  double h_corner = 0.01;
};

// The wall_power_law keys of a metric section of a dim-dimensional run (ConfigError naming the
// key).
WallLawParams parse_wall_law_params(const ConfigNode& metric, int dim);

// The law, shared by both dimensions. h_perp at wall distance d: h0 + (g - 1) d, or h0 g^(d/delta)
// (delta 0: h0), capped at h_max.
double wall_normal_size(const WallLawParams& params, double d);
// The size along the wall where the wall asks for h_wall (2D: from h_wall_max, the curvature and
// the corners; 3D: h_wall_max) and the normal size is h_perp: never below h_perp, so that far from
// the walls the metric becomes isotropic, and capped at h_max.
double wall_tangential_size(const WallLawParams& params, double h_wall, double h_perp);

class WallPowerLawField final : public MetricField<2> {
 public:
  WallPowerLawField(std::vector<SplineLoop> walls, const WallLawParams& params);
  Metric<2> evaluate(const Eigen::Vector2d& x) const override;

  // The two sizes at x (for tests and reports).
  struct Sizes {
    double normal, tangential, distance;
    Eigen::Vector2d normal_direction;
  };
  Sizes sizes(const Eigen::Vector2d& x) const;
  // h_perp at wall distance d.
  double normal_size(double d) const;

 private:
  std::vector<SplineLoop> walls_;
  std::vector<Eigen::Vector2d> corners_;
  double length_scale_ = 0;  // the longest wall: the scale of "on the wall"
  WallLawParams p_;
};

}  // namespace metric
}  // namespace plaf
