// SPDX-License-Identifier: MIT
// The registry of 2D metric-field plugins, selected by `metric: {type: ...}`. Core registers
// `uniform`; later stages add theirs (wall_power_law, background) the same way.
#pragma once

#include <memory>

#include "modules/metric.h"
#include "modules/registry.h"
#include "modules/run_config.h"

namespace plaf {

using MetricField2Registry = Registry<std::unique_ptr<MetricField<2>>(const RunConfig&)>;
MetricField2Registry& metric_field_registry();

// The configured field (ConfigError naming the file, line and type if unknown).
std::unique_ptr<MetricField<2>> make_metric_field(const RunConfig& config);

}  // namespace plaf
