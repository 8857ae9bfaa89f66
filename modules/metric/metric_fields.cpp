// SPDX-License-Identifier: MIT
#include "modules/metric/metric_fields.h"

#include <cmath>

#include "modules/metric/background_metric.h"
#include "modules/base/error.h"
#include "modules/metric/wall_metric.h"

namespace plaf {
inline namespace metric {

namespace {

std::unique_ptr<MetricField<2>> make_uniform(const RunConfig& c, const Geometry2D&) {
  const UniformMetricParams& u = c.metric.uniform;
  if (u.sizes.empty()) return std::make_unique<UniformMetricField<2>>(Metric<2>::isotropic(u.h));
  const double a = u.angle_deg * M_PI / 180.0;
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return std::make_unique<UniformMetricField<2>>(
      Metric<2>::from_directions(r, Eigen::Vector2d(u.sizes[0], u.sizes[1])));
}

std::unique_ptr<MetricField<2>> make_wall_law(const RunConfig& c, const Geometry2D& g) {
  std::vector<SplineLoop> walls;
  for (const GeometryLoop& l : g.loops)
    if (l.kind == BoundaryKind::Wall) walls.push_back(l.loop);
  if (walls.empty())
    throw ConfigError(c.metric.where + ": wall_power_law needs walls: use geometry type 'airfoils'");
  return std::make_unique<WallPowerLawField>(std::move(walls), c.metric.wall_law);
}

std::unique_ptr<MetricField<2>> make_background(const RunConfig& c, const Geometry2D&) {
  const BackgroundParams& b = c.metric.background;
  const bool meshb = std::filesystem::path(b.file).extension() == ".mesh";
  if (meshb && b.sol.empty()) throw ConfigError(c.metric.where + ": a .mesh background needs its .sol file (sol:)");
  BackgroundMesh mesh = meshb ? read_background_meshb(b.file, b.sol) : read_background_msh(b.file);
  return std::make_unique<BackgroundMetricField>(std::move(mesh), parse_metric_mean(b.mean));
}

}  // namespace

MetricField2Registry& metric_field_registry() {
  static MetricField2Registry registry = [] {
    MetricField2Registry r("metric field");
    r.add("uniform", make_uniform);
    r.add("wall_power_law", make_wall_law);
    r.add("background", make_background);
    return r;
  }();
  return registry;
}

std::unique_ptr<MetricField<2>> make_metric_field(const RunConfig& config, const Geometry2D& geometry) {
  return metric_field_registry().create(config.metric.type, config.metric.where, config, geometry);
}

Metric<3> uniform_metric_3d(const UniformMetricParams& u) {
  if (u.sizes.empty()) return Metric<3>::isotropic(u.h);
  return Metric<3>::from_directions(Eigen::Matrix3d::Identity(), Eigen::Vector3d(u.sizes[0], u.sizes[1], u.sizes[2]));
}

}  // namespace metric
}  // namespace plaf
