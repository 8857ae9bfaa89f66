// SPDX-License-Identifier: MIT
// A metric given at the nodes of a background mesh (paper Sec. II.D): the metric of the previous
// adaptation step, regenerated into a new mesh. Evaluation locates the containing simplex and
// interpolates its vertex metrics with barycentric weights, by the log-Euclidean (default) or
// affine-invariant weighted mean (metric.h). A point outside the background mesh takes the metric
// of the nearest simplex at the closest point of that simplex.
// The means: 2D in closed form for three 2x2 metrics (metric_mean3.h); 3D log_euclidean_mean's
// formula with the node logarithms computed once, and affine_invariant_mean (metric.h).
// The field and the readers are templates over the run's dimension (2 or 3): triangles in 2D,
// tetrahedra in 3D; a file of the other dimension is an InputError naming the line.
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
  std::vector<Simplex> simplices;    // triangles (2D) or tetrahedra (3D), linear
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
//       diagonals through their first node in file order, so that neighbouring prisms agree:
//       J. Dompierre et al., *How to Subdivide Pyramids, Prisms and Hexahedra into Tetrahedra*,
//       IMR 1999); hexahedra and pyramids are refused by the MSH reader (msh_io.h). A view of 9
//       components (3x3, row-major) or 6 (xx xy yy xz yz zz: the libMeshb order of the .sol below).
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

// The field: the containing simplex (closed, with a relative tolerance) through a tree over the
// simplices' boxes, O(log n) per point for a mesh whose boxes overlap boundedly. Simplices of
// zero size (|det| <= 1e-13 (longest edge)^Dim) are never located.
template <int Dim>
class BackgroundMetricField final : public MetricField<Dim> {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Matrix = Eigen::Matrix<double, Dim, Dim>;
  using Weights = Eigen::Matrix<double, Dim + 1, 1>;

  // InputError if the mesh fails check_background_mesh or no simplex has a positive size.
  BackgroundMetricField(BackgroundMesh<Dim> mesh, MetricMean mean);
  ~BackgroundMetricField() override;
  Metric<Dim> evaluate(const Point& x) const override;

  // The simplex containing x, or -1: for tests.
  int locate(const Point& x) const;
  // Barycentric coordinates of x in simplex s (NaN for a simplex of zero size).
  Weights barycentric(int s, const Point& x) const;
  // What evaluate averages at x: the simplex (the containing one, or the nearest) and the
  // barycentric weights there (of x, or of the simplex's closest point to x), clipped to >= 0 and
  // summing to 1. MesherError at a non-finite x.
  struct Located {
    int simplex;
    Weights w;
  };
  Located weights(const Point& x) const;
  const BackgroundMesh<Dim>& mesh() const { return mesh_; }

 private:
  // The point location, one per dimension: 2D a quadtree over the triangles
  // (background_quadtree.h), 3D a bounding-volume tree over the tetrahedra
  // (background_tet_tree.h).
  struct Tree;
  // Both trees: a point may lie this far outside a simplex, in units of its altitude (the
  // barycentric coordinate is the signed distance to a facet over the altitude), and be in it.
  static constexpr double bary_tol_rel = 1e-10;
  // Both trees: simplices with |det| <= degenerate_rel * (longest edge)^Dim have no size.
  static constexpr double degenerate_rel = 1e-13;

  BackgroundMesh<Dim> mesh_;
  MetricMean mean_;
  std::vector<Matrix> logs_;  // log of every node metric, for the log-Euclidean mean
  std::unique_ptr<Tree> tree_;
};

}  // namespace metric
}  // namespace plaf
