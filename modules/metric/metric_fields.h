// SPDX-License-Identifier: MIT
// The registry of 2D metric-field plugins, selected by `metric: {type: ...}`: uniform,
// wall_power_law (wall_metric.h) and background (background_metric.h). A plugin is built from
// the run configuration and the run's geometry (the walls, for wall-distance metrics).
#pragma once

#include <memory>

#include "modules/geometry/geometry2d.h"
#include "modules/metric/metric.h"
#include "modules/pipeline/registry.h"
#include "modules/pipeline/run_config.h"

namespace plaf {
inline namespace metric {

using MetricField2Registry = Registry<std::unique_ptr<MetricField<2>>(const RunConfig&, const Geometry2D&)>;
MetricField2Registry& metric_field_registry();

// The configured field (ConfigError naming the file, line and type if unknown).
std::unique_ptr<MetricField<2>> make_metric_field(const RunConfig& config, const Geometry2D& geometry);

// The 3D uniform metric of `metric: {type: uniform}`: isotropic h, or sizes along x, y, z.
Metric<3> uniform_metric_3d(const UniformMetricParams& params);

}  // namespace metric
}  // namespace plaf
