// SPDX-License-Identifier: MIT
// Implements the background-mesh metric of K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D (background_metric.h): the mesh is snapped to
// linear, the containing element is found through a tree (2D: background_quadtree.h, 3D:
// background_tet_tree.h), and the vertex metrics are averaged with the linear (barycentric)
// weights of the point (2D: metric_mean3.h, 3D: metric.h). The file readers are in
// background_read_msh.cpp and background_read_meshb.cpp.
#include "modules/metric/background_metric.h"

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "modules/base/error.h"
#include "modules/metric/background_quadtree.h"
#include "modules/metric/background_tet_tree.h"
#include "modules/metric/metric_mean3.h"

namespace plaf {
inline namespace metric {

template <int Dim>
void check_background_mesh(const BackgroundMesh<Dim>& mesh) {
  const char* simplex = Dim == 2 ? "triangle" : "tetrahedron";
  const std::size_t num_nodes = mesh.nodes.size(), num_simplices = mesh.simplices.size();
  if (mesh.metrics.size() != num_nodes)
    throw InputError("background mesh: " + std::to_string(mesh.metrics.size()) + " metrics for " +
                     std::to_string(num_nodes) + " nodes");
  if (num_simplices > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError(std::string("background mesh: too many ") + simplex + "s");
  for (std::size_t i = 0; i < num_nodes; ++i)
    if (!mesh.nodes[i].allFinite()) throw InputError("background mesh: node " + std::to_string(i) + " is not finite");
  for (std::size_t t = 0; t < num_simplices; ++t)
    for (NodeId v : mesh.simplices[t])
      if (v < 0 || static_cast<std::size_t>(v) >= num_nodes)
        throw InputError("background mesh: " + std::string(simplex) + " " + std::to_string(t) + " refers to node " +
                         std::to_string(v) + " of " + std::to_string(num_nodes));
}
template void check_background_mesh<2>(const BackgroundMesh<2>&);
template void check_background_mesh<3>(const BackgroundMesh<3>&);

template <int Dim>
BackgroundMetricField<Dim>::BackgroundMetricField(BackgroundMesh<Dim> mesh, MetricMean mean)
    : mesh_(std::move(mesh)), mean_(mean) {
  // 1. Validate the mesh.
  check_background_mesh(mesh_);
  // 2. Node logarithms: the log-Euclidean mean is then one exp, and they start the 2D
  //    affine-invariant iteration.
  logs_.reserve(mesh_.nodes.size());
  for (const Metric<Dim>& m : mesh_.metrics) logs_.push_back(m.log());
  // 3. The point location.
  tree_ = std::make_unique<Tree>(mesh_);
}

template <int Dim>
BackgroundMetricField<Dim>::~BackgroundMetricField() = default;

template <int Dim>
typename BackgroundMetricField<Dim>::Weights BackgroundMetricField<Dim>::barycentric(int s, const Point& x) const {
  return tree_->barycentric(s, x);
}

template <int Dim>
int BackgroundMetricField<Dim>::locate(const Point& x) const {
  return tree_->locate(x);
}

template <int Dim>
typename BackgroundMetricField<Dim>::Located BackgroundMetricField<Dim>::weights(const Point& x) const {
  if (!x.allFinite()) throw MesherError("background metric: evaluated at a non-finite point");
  Located out{locate(x), Weights::Zero()};
  if (out.simplex >= 0) {
    out.w = barycentric(out.simplex, x);
  } else {
    // Outside: the nearest simplex, at its closest point.
    const typename Tree::Nearest nearest = tree_->nearest(mesh_, x);
    if (nearest.simplex < 0) throw MesherError("background metric: no nearest simplex (the point is too far away)");
    out = {nearest.simplex, nearest.weights};
  }
  // Clipped to the simplex (a point within the tolerance outside, or a closest point on a facet,
  // may give -1e-16).
  out.w = out.w.cwiseMax(0.0);
  out.w /= out.w.sum();
  return out;
}

template <int Dim>
Metric<Dim> BackgroundMetricField<Dim>::evaluate(const Point& x) const {
  const Located at = weights(x);
  const auto& v = mesh_.simplices[static_cast<std::size_t>(at.simplex)];
  std::array<std::size_t, Dim + 1> node;
  for (std::size_t i = 0; i <= Dim; ++i) node[i] = static_cast<std::size_t>(v[i]);
  if constexpr (Dim == 2) {
    return metric_mean3(
        mean_, {&mesh_.metrics[node[0]].matrix(), &mesh_.metrics[node[1]].matrix(), &mesh_.metrics[node[2]].matrix()},
        {&logs_[node[0]], &logs_[node[1]], &logs_[node[2]]}, at.w);
  } else {
    if (mean_ == MetricMean::LogEuclidean) {
      // exp(sum w_i log M_i): log_euclidean_mean (metric.h) with the logarithms computed once.
      Matrix log_mean = Matrix::Zero();
      for (std::size_t i = 0; i <= Dim; ++i)
        if (at.w[static_cast<Eigen::Index>(i)] > 0) log_mean += at.w[static_cast<Eigen::Index>(i)] * logs_[node[i]];
      return Metric<Dim>::exp(log_mean);
    }
    std::array<Metric<Dim>, Dim + 1> m;
    std::array<double, Dim + 1> w{};
    for (std::size_t i = 0; i <= Dim; ++i) {
      m[i] = mesh_.metrics[node[i]];
      w[i] = at.w[static_cast<Eigen::Index>(i)];
    }
    return affine_invariant_mean<Dim>(m, w);
  }
}

template class BackgroundMetricField<2>;
template class BackgroundMetricField<3>;

}  // namespace metric
}  // namespace plaf
