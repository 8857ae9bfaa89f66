// SPDX-License-Identifier: MIT
// Implements the background-mesh metric of K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D, in 3D (background_metric_3d.h): the containing
// tetrahedron through a bounding-volume tree (background_tet_tree.h), and the weighted mean of
// its vertex metrics (metric.h) with the point's barycentric weights.
#include "modules/metric/background_metric_3d.h"

#include <array>
#include <utility>

#include "modules/base/error.h"
#include "modules/metric/background_tet_tree.h"

namespace plaf {
inline namespace metric {

BackgroundMetricField3::BackgroundMetricField3(BackgroundMesh<3> mesh, MetricMean mean)
    : mesh_(std::move(mesh)), mean_(mean) {
  // 1. Validate the mesh.
  check_background_mesh(mesh_);
  // 2. Node logarithms: the log-Euclidean mean is then one exp.
  logs_.reserve(mesh_.nodes.size());
  for (const Metric<3>& m : mesh_.metrics) logs_.push_back(m.log());
  // 3. The point location.
  tree_ = std::make_unique<TetTree>(mesh_);
}

BackgroundMetricField3::~BackgroundMetricField3() = default;

Eigen::Vector4d BackgroundMetricField3::barycentric(int t, const Eigen::Vector3d& x) const {
  return tree_->barycentric(t, x);
}

int BackgroundMetricField3::locate(const Eigen::Vector3d& x) const {
  return tree_->locate(x);
}

BackgroundMetricField3::Weights BackgroundMetricField3::weights(const Eigen::Vector3d& x) const {
  if (!x.allFinite()) throw MesherError("background metric: evaluated at a non-finite point");
  Weights out{locate(x), Eigen::Vector4d::Zero()};
  if (out.tetrahedron >= 0) {
    out.w = barycentric(out.tetrahedron, x);
  } else {
    // Outside: the nearest tetrahedron, at its closest point.
    const TetTree::Nearest nearest = tree_->nearest(mesh_, x);
    if (nearest.tetrahedron < 0) throw MesherError("background metric: no nearest tetrahedron");
    out = {nearest.tetrahedron, nearest.weights};
  }
  // Clipped to the tetrahedron (a point within the tolerance outside may give -1e-16).
  out.w = out.w.cwiseMax(0.0);
  out.w /= out.w.sum();
  return out;
}

Metric<3> BackgroundMetricField3::evaluate(const Eigen::Vector3d& x) const {
  const Weights w = weights(x);
  const auto& v = mesh_.simplices[static_cast<std::size_t>(w.tetrahedron)];
  if (mean_ == MetricMean::LogEuclidean) {
    // exp(sum w_i log M_i), the logarithms computed once (metric.h, log_euclidean_mean).
    Eigen::Matrix3d log_mean = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < 4; ++i)
      if (w.w[static_cast<Eigen::Index>(i)] > 0)
        log_mean += w.w[static_cast<Eigen::Index>(i)] * logs_[static_cast<std::size_t>(v[i])];
    return Metric<3>::exp(log_mean);
  }
  std::array<Metric<3>, 4> m;
  std::array<double, 4> weights{};
  for (std::size_t i = 0; i < 4; ++i) {
    m[i] = mesh_.metrics[static_cast<std::size_t>(v[i])];
    weights[i] = w.w[static_cast<Eigen::Index>(i)];
  }
  return affine_invariant_mean<3>(m, weights);
}

}  // namespace metric
}  // namespace plaf
