// SPDX-License-Identifier: MIT
// A metric given at the nodes of a background mesh (paper Sec. II.D): the metric of the previous
// adaptation step, regenerated into a new mesh. Evaluation locates the containing simplex and
// interpolates its vertex metrics with barycentric weights, by the log-Euclidean (default) or
// affine-invariant weighted mean (metric.h). A point outside the background mesh takes the metric
// of the nearest simplex at the closest point of that simplex.
//   2D: BackgroundMetricField (below), triangles found through a quadtree (background_quadtree.h).
//   3D: BackgroundMetricField3 (background_metric_3d.h), tetrahedra found through a
//       bounding-volume tree (background_tet_tree.h).
// The readers serve both: the run's dimension is the template argument, and a file of the other
// dimension is an InputError naming the line.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

template <int Dim>
struct BackgroundMesh {
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Simplex = std::array<NodeId, Dim + 1>;
  std::vector<Point> nodes;
  std::vector<Simplex> simplices;  // triangles (2D) or tetrahedra (3D), linear
  std::vector<Metric<Dim>> metrics;  // one per node
};

// Throws InputError unless there is one metric per node, every node is finite and every simplex
// refers to existing nodes.
template <int Dim>
void check_background_mesh(const BackgroundMesh<Dim>& mesh);

// Gmsh MSH 4.1 ASCII and a $NodeData view with one tensor per node, as Gmsh's metric views store
// them. High-order cells are snapped to their vertices (their other nodes need no value).
//   2D: triangles and quadrilaterals (split in two along 0-2); a view of 9 components (3x3
//       tensor, row-major; its xx xy / yx yy block is used) or 4 (2x2, row-major).
//   3D: tetrahedra and prisms (split into three tetrahedra along the quadrilateral faces'
//       diagonals through their first node in file order, so neighbouring prisms agree: J. Dompierre et
//       al., *How to Subdivide Pyramids, Prisms and Hexahedra into Tetrahedra*, IMR 1999);
//       hexahedra and pyramids are refused by the MSH reader (msh_io.h). A view of 9 components
//       (3x3, row-major) or 6 (xx xy yy xz yz zz: the libMeshb order of the .sol below).
// InputError "path:line: reason" on bad content, a mesh of the other dimension, a mesh without
// cells of the run's dimension, a missing view, a non-SPD tensor or a vertex without a value.
template <int Dim>
BackgroundMesh<Dim> read_background_msh(const std::filesystem::path& path);

// libMeshb ASCII pair (as read by MMG and BAMG): .mesh and .sol (SolAtVertices with one field of
// type 3 = SymMat, stored xx xy yy in 2D and xx xy yy xz yz zz in 3D).
//   2D: Dimension 2, Vertices, Triangles and Quadrilaterals (split along 0-2).
//   3D: Dimension 3, Vertices, Tetrahedra; Prisms, Pyramids and Hexahedra are refused (split
//       them into tetrahedra first), the boundary's Triangles and Quadrilaterals are skipped.
template <int Dim>
BackgroundMesh<Dim> read_background_meshb(const std::filesystem::path& mesh, const std::filesystem::path& sol);

class BackgroundMetricField final : public MetricField<2> {
 public:
  BackgroundMetricField(BackgroundMesh<2> mesh, MetricMean mean);
  ~BackgroundMetricField() override;
  Metric<2> evaluate(const Eigen::Vector2d& x) const override;

  // The triangle containing x (closed, with a relative tolerance), or -1: for tests.
  int locate(const Eigen::Vector2d& x) const;
  // Barycentric coordinates of x in triangle t.
  Eigen::Vector3d barycentric(int t, const Eigen::Vector2d& x) const;
  const BackgroundMesh<2>& mesh() const { return mesh_; }

 private:
  struct Quadtree;
  BackgroundMesh<2> mesh_;
  MetricMean mean_;
  std::vector<Eigen::Matrix2d> logs_;  // log of every node metric, for the log-Euclidean mean
  std::unique_ptr<Quadtree> tree_;
};

}  // namespace metric
}  // namespace plaf
