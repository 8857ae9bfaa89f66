// SPDX-License-Identifier: MIT
// Implements the background-mesh metric of K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D, in 2D: the mesh is snapped to linear, the
// containing element is found through a quadtree (background_quadtree.h), and the vertex metrics
// are averaged with the linear (barycentric) weights of the point (metric_mean3.h). The mesh check
// serves 3D too (background_metric_3d.cpp); the file readers are in background_read_msh.cpp and
// background_read_meshb.cpp.
#include "modules/metric/background_metric.h"

#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "modules/base/error.h"
#include "modules/metric/background_quadtree.h"
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

BackgroundMetricField::BackgroundMetricField(BackgroundMesh<2> mesh, MetricMean mean)
    : mesh_(std::move(mesh)), mean_(mean) {
  // 1. Validate the mesh.
  check_background_mesh(mesh_);
  // 2. Node logarithms: the log-Euclidean mean is then one exp, and it starts the
  //    affine-invariant iteration.
  logs_.reserve(mesh_.nodes.size());
  for (const Metric<2>& m : mesh_.metrics) logs_.push_back(m.log());
  // 3. The point location.
  tree_ = std::make_unique<Quadtree>(mesh_);
}

BackgroundMetricField::~BackgroundMetricField() = default;

Eigen::Vector3d BackgroundMetricField::barycentric(int t, const Eigen::Vector2d& x) const {
  return tree_->barycentric(t, x);
}

int BackgroundMetricField::locate(const Eigen::Vector2d& x) const {
  return tree_->locate(x);
}

Metric<2> BackgroundMetricField::evaluate(const Eigen::Vector2d& x) const {
  if (!x.allFinite()) throw MesherError("background metric: evaluated at a non-finite point");
  int t = locate(x);
  Eigen::Vector3d w;
  if (t >= 0) {
    w = barycentric(t, x);
  } else {
    // Outside: the nearest triangle, then the metric at its closest point.
    const Quadtree::Nearest nearest = tree_->nearest(mesh_, x);
    t = nearest.triangle;
    if (t < 0) throw MesherError("background metric: no nearest triangle (the point is too far away)");
    w = barycentric(t, nearest.point);
  }
  // Barycentric weights, clipped to the triangle (a point within the tolerance outside, or a
  // closest point on an edge, may give -1e-16).
  w = w.cwiseMax(0.0);
  w /= w.sum();
  const auto& v = mesh_.simplices[static_cast<std::size_t>(t)];
  const auto i0 = static_cast<std::size_t>(v[0]), i1 = static_cast<std::size_t>(v[1]),
             i2 = static_cast<std::size_t>(v[2]);
  return metric_mean3(mean_, {&mesh_.metrics[i0].matrix(), &mesh_.metrics[i1].matrix(), &mesh_.metrics[i2].matrix()},
                      {&logs_[i0], &logs_[i1], &logs_[i2]}, w);
}

}  // namespace metric
}  // namespace plaf
