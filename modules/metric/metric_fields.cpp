// SPDX-License-Identifier: MIT
#include "modules/metric/metric_fields.h"

#include <cmath>

#include "modules/base/error.h"
#include "modules/metric/background_metric.h"

namespace plaf {
inline namespace metric {

UniformMetricParams parse_uniform_metric(const ConfigNode& m, int dim) {
  UniformMetricParams u;
  u.h = m.get_positive("h", u.h);
  u.sizes = m.get_double_list("sizes", {});
  if (!u.sizes.empty()) {
    if (m.has("h")) throw ConfigError(m.where("sizes") + ": give either h or sizes, not both");
    if (static_cast<int>(u.sizes.size()) != dim)
      throw ConfigError(m.where("sizes") +
                        (dim == 2 ? ": expected two sizes [h1, h2]" : ": expected three sizes [hx, hy, hz]"));
    for (double s : u.sizes)
      if (!(s > 0)) throw ConfigError(m.where("sizes") + ": sizes must be positive");
  }
  if (dim == 2) u.angle_deg = m.get_double("angle_deg", u.angle_deg);  // 3D: sizes along x, y, z
  return u;
}

Metric<2> uniform_metric_2d(const UniformMetricParams& u) {
  if (u.sizes.empty()) return Metric<2>::isotropic(u.h);
  const double a = u.angle_deg * M_PI / 180.0;
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return Metric<2>::from_directions(r, Eigen::Vector2d(u.sizes[0], u.sizes[1]));
}

Metric<3> uniform_metric_3d(const UniformMetricParams& u) {
  if (u.sizes.empty()) return Metric<3>::isotropic(u.h);
  return Metric<3>::from_directions(Eigen::Matrix3d::Identity(), Eigen::Vector3d(u.sizes[0], u.sizes[1], u.sizes[2]));
}

BackgroundParams parse_background_params(const ConfigNode& m) {
  BackgroundParams b;
  b.file = m.get_path("file", "");
  if (b.file.empty()) throw ConfigError(m.where() + ": file is required for a background metric");
  b.sol = m.get_path("sol", "");
  b.mean = m.get_choice("mean", b.mean, {"log_euclidean", "affine_invariant"});
  return b;
}

template <int Dim>
std::unique_ptr<MetricField<Dim>> make_background_field(const BackgroundParams& b, const std::string& where) {
  const bool meshb = std::filesystem::path(b.file).extension() == ".mesh";
  if (meshb && b.sol.empty()) throw ConfigError(where + ": a .mesh background needs its .sol file (sol:)");
  BackgroundMesh<Dim> mesh = meshb ? read_background_meshb<Dim>(b.file, b.sol) : read_background_msh<Dim>(b.file);
  try {
    return std::make_unique<BackgroundMetricField<Dim>>(std::move(mesh), parse_metric_mean(b.mean));
  } catch (const InputError& e) {
    // The checks of the mesh as a whole (check_background_mesh) know no file: name it.
    throw InputError(b.file + ": " + e.what());
  }
}
template std::unique_ptr<MetricField<2>> make_background_field<2>(const BackgroundParams&, const std::string&);
template std::unique_ptr<MetricField<3>> make_background_field<3>(const BackgroundParams&, const std::string&);

std::unique_ptr<MetricField<2>> make_wall_law_field(const WallLawParams& params, const Geometry2D& g,
                                                    const std::string& where) {
  std::vector<SplineLoop> walls;
  for (const GeometryLoop& l : g.loops)
    if (l.kind == BoundaryKind::Wall) walls.push_back(l.loop);
  if (walls.empty()) throw ConfigError(where + ": wall_power_law needs walls: use geometry type 'airfoils'");
  return std::make_unique<WallPowerLawField>(std::move(walls), params);
}

}  // namespace metric
}  // namespace plaf
