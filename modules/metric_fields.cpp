// SPDX-License-Identifier: MIT
#include "modules/metric_fields.h"

#include <cmath>

namespace plaf {

namespace {

std::unique_ptr<MetricField<2>> make_uniform(const RunConfig& c) {
  const UniformMetricParams& u = c.metric.uniform;
  if (u.sizes.empty()) return std::make_unique<UniformMetricField<2>>(Metric<2>::isotropic(u.h));
  const double a = u.angle_deg * M_PI / 180.0;
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return std::make_unique<UniformMetricField<2>>(
      Metric<2>::from_directions(r, Eigen::Vector2d(u.sizes[0], u.sizes[1])));
}

}  // namespace

MetricField2Registry& metric_field_registry() {
  static MetricField2Registry registry = [] {
    MetricField2Registry r("metric field");
    r.add("uniform", make_uniform);
    return r;
  }();
  return registry;
}

std::unique_ptr<MetricField<2>> make_metric_field(const RunConfig& config) {
  return metric_field_registry().create(config.metric.type, config.metric.where, config);
}

}  // namespace plaf
