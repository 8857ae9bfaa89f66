// SPDX-License-Identifier: MIT
// The point location of the 2D background-mesh field (background_metric.h): a quadtree over the
// triangles of the background mesh, the triangle containing a point, and the nearest triangle
// to a point outside the mesh (3D: background_tet_tree.h). Internal to modules/metric.
#pragma once

#include <cstdint>
#include <vector>

#include "modules/metric/background_metric.h"

namespace plaf {
inline namespace metric {

template <>
struct BackgroundMetricField<2>::Tree {
  // Per-triangle affine data, then the tree; InputError if no triangle has positive area.
  explicit Tree(const BackgroundMesh<2>& mesh);

  // Barycentric coordinates of x in triangle t.
  Eigen::Vector3d barycentric(int t, const Eigen::Vector2d& x) const;
  // The triangle containing x (closed, with a relative tolerance), or -1.
  int locate(const Eigen::Vector2d& x) const;
  // The triangle nearest to x and the barycentric coordinates of its closest point to x
  // (simplex -1 if none is found).
  struct Nearest {
    int simplex = -1;
    Eigen::Vector3d weights = Eigen::Vector3d::Zero();
  };
  Nearest nearest(const BackgroundMesh<2>& mesh, const Eigen::Vector2d& x) const;

  // A node is a square cell; the root's centre and half side are stored, children are found by
  // halving. Leaves list the triangles that meet their cell (closed, widened by the locate
  // tolerance), so the triangle containing a point is among those of the point's leaf.
  struct Node {
    std::int32_t first_child = -1;  // four consecutive nodes, or -1; child k: bit 0 right, bit 1 above
    std::int32_t begin = 0, count = 0;
  };
  std::vector<Node> nodes;
  std::vector<std::int32_t> items;
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double half = 0;

  // Per triangle: vertex 0 and the inverse of [v1 - v0, v2 - v0] (NaN if degenerate), side by
  // side for one cache line per barycentric test; the smallest altitude and the longest edge.
  struct Affine {
    Eigen::Vector2d origin;
    Eigen::Matrix2d inverse;
  };
  std::vector<Affine> affine;
  std::vector<double> min_altitude, diameter;
  std::vector<bool> valid;

  static int quadrant(const Eigen::Vector2d& x, const Eigen::Vector2d& c) {
    return (x[0] >= c[0]) + 2 * (x[1] >= c[1]);
  }
  static Eigen::Vector2d child_center(const Eigen::Vector2d& c, double half, int q) {
    return {c[0] + ((q & 1) ? 0.5 : -0.5) * half, c[1] + ((q & 2) ? 0.5 : -0.5) * half};
  }

 private:
  // Files the triangles tris under node (the cell of centre c and half side cell_half), split
  // while that separates them.
  void build(const BackgroundMesh<2>& mesh, std::size_t node, const Eigen::Vector2d& c, double cell_half, int depth,
             std::vector<std::int32_t> tris);
};

}  // namespace metric
}  // namespace plaf
