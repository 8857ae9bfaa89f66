// SPDX-License-Identifier: MIT
// The metric plugins' options, each parsed from its own `metric:` section (the plugins are
// registered in modules/pipeline/stages.cpp), and the fields they make: `uniform` (one metric
// everywhere) and `background` (the metric at the nodes of a background mesh of the run's
// dimension, 2D triangles or 3D tetrahedra; background_metric.h: the field and the file formats).
// The wall_power_law options live beside its field in wall_metric.h (3D: wall_metric_3d.h). The
// keys, types, defaults and descriptions: `plaf keys metric` (docs/config.md; the lines in
// apps/key_notes.cpp).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "modules/geometry/geometry2d.h"
#include "modules/metric/metric.h"
#include "modules/metric/wall_metric.h"
#include "modules/pipeline/config.h"

namespace plaf {
inline namespace metric {

struct UniformMetricParams {
  double h = 0.25;
  std::vector<double> sizes;  // empty: isotropic h
  double angle_deg = 0.0;
};

// The uniform keys of a metric section of a dim-dimensional run (ConfigError naming the key).
UniformMetricParams parse_uniform_metric(const ConfigNode& metric, int dim);
// The uniform metrics: isotropic h, or sizes along the directions (2D: h1 at angle_deg from x;
// 3D: along x, y, z).
Metric<2> uniform_metric_2d(const UniformMetricParams& params);
Metric<3> uniform_metric_3d(const UniformMetricParams& params);

struct BackgroundParams {
  std::string file;
  std::string sol;
  std::string mean = "log_euclidean";
};

// The same keys in 2D and 3D (ConfigError naming the key).
BackgroundParams parse_background_params(const ConfigNode& metric);
// The background field of a Dim-dimensional run: reads the file(s) (InputError "path:line:
// reason", a mesh of the other dimension included) and builds the field; `where` names the
// config key in errors (ConfigError: a .mesh without sol).
template <int Dim>
std::unique_ptr<MetricField<Dim>> make_background_field(const BackgroundParams& params, const std::string& where);

// The wall power law over the geometry's wall loops (ConfigError naming `where` without walls).
std::unique_ptr<MetricField<2>> make_wall_law_field(const WallLawParams& params, const Geometry2D& geometry,
                                                    const std::string& where);

}  // namespace metric
}  // namespace plaf
