// SPDX-License-Identifier: MIT
// A metric given at the nodes of a background triangulation (paper Sec. II.D): the metric of the
// previous adaptation step, regenerated into a new mesh. Evaluation locates the containing
// triangle with a quadtree over the triangles' bounding boxes and interpolates the three vertex
// metrics with barycentric weights, by the log-Euclidean (default) or affine-invariant weighted
// mean (metric.h). A point outside the background mesh takes the metric of the nearest triangle
// at the closest point of that triangle.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

struct BackgroundMesh {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<NodeId, 3>> triangles;  // linear; curved input is snapped to linear
  std::vector<Metric<2>> metrics;                // one per node
};

// Gmsh MSH 4.1 ASCII: triangles (quadrilaterals are split in two; high-order cells use their
// vertices) and a $NodeData view of 9 (3x3 tensor, the 2D block is used) or 4 (2x2) components
// per node, as Gmsh's metric views store them. InputError "path:line: reason" on bad content, a
// missing view, a non-SPD tensor or nodes without a value.
BackgroundMesh read_background_msh(const std::filesystem::path& path);

// libMeshb ASCII pair: .mesh (Dimension 2, Vertices, Triangles) and .sol (SolAtVertices with one
// field of type 3 = SymMat, stored xx, xy, yy).
BackgroundMesh read_background_meshb(const std::filesystem::path& mesh, const std::filesystem::path& sol);

class BackgroundMetricField final : public MetricField<2> {
 public:
  BackgroundMetricField(BackgroundMesh mesh, MetricMean mean);
  ~BackgroundMetricField() override;
  Metric<2> evaluate(const Eigen::Vector2d& x) const override;

  // The triangle containing x (closed, with a relative tolerance), or -1: for tests.
  int locate(const Eigen::Vector2d& x) const;
  // Barycentric coordinates of x in triangle t.
  Eigen::Vector3d barycentric(int t, const Eigen::Vector2d& x) const;
  const BackgroundMesh& mesh() const { return mesh_; }

 private:
  struct Quadtree;
  BackgroundMesh mesh_;
  MetricMean mean_;
  std::vector<Eigen::Matrix2d> logs_;  // log of every node metric, for the log-Euclidean mean
  std::unique_ptr<Quadtree> tree_;
};

}  // namespace metric
}  // namespace plaf
