// SPDX-License-Identifier: MIT
// The point location of the 3D background-mesh field (background_metric.h): a bounding-volume
// tree over the tetrahedra's boxes, the tetrahedron containing a point, and the nearest
// tetrahedron to a point outside the mesh with the barycentric weights of its closest point
// (2D: background_quadtree.h). Internal to modules/metric.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "modules/metric/background_metric.h"

namespace plaf {
inline namespace metric {

template <>
struct BackgroundMetricField<3>::Tree {
  // Per-tetrahedron affine data, then the tree; InputError if no tetrahedron has positive volume.
  explicit Tree(const BackgroundMesh<3>& mesh);

  // Barycentric coordinates of x in tetrahedron t (NaN for a tetrahedron of zero volume).
  Eigen::Vector4d barycentric(int t, const Eigen::Vector3d& x) const;
  // The tetrahedron containing x (closed, with a relative tolerance), or -1.
  int locate(const Eigen::Vector3d& x) const;
  // The tetrahedron nearest to x and the barycentric coordinates of its closest point to x
  // (simplex -1 if none is found).
  struct Nearest {
    int simplex = -1;
    Eigen::Vector4d weights = Eigen::Vector4d::Zero();
  };
  Nearest nearest(const BackgroundMesh<3>& mesh, const Eigen::Vector3d& x) const;

  // Nodes in depth-first order: an inner node's first child is the next node. A node's box holds
  // the boxes of its tetrahedra, each widened by its locate margin, so that the tetrahedron
  // containing a point is in a leaf whose box holds the point.
  struct Node {
    Eigen::Vector3d lo, hi;
    std::int32_t begin = 0, count = 0;  // leaf: slots begin .. begin + count - 1; inner: count 0
    std::int32_t second = -1;           // inner: the second child
  };
  std::vector<Node> nodes;
  // Slots: the tetrahedra of positive volume in leaf order (items[slot] is the tetrahedron), with
  // vertex 0 and the inverse of [v1 - v0, v2 - v0, v3 - v0] side by side for one cache line pair
  // per barycentric test; slot_of[t] is -1 for a tetrahedron of zero volume.
  struct Affine {
    Eigen::Vector3d origin;
    Eigen::Matrix3d inverse;
  };
  std::vector<std::int32_t> items, slot_of;
  std::vector<Affine> affine;

  Eigen::Vector4d slot_barycentric(std::size_t slot, const Eigen::Vector3d& x) const {
    const Affine& a = affine[slot];
    const Eigen::Vector3d l = a.inverse * (x - a.origin);
    return {1 - l[0] - l[1] - l[2], l[0], l[1], l[2]};
  }

 private:
  // The subtree over items[begin, end), which it reorders (boxes and centres by tetrahedron);
  // returns its root.
  std::int32_t build(std::int32_t begin, std::int32_t end, const std::vector<Eigen::Vector3d>& lo,
                     const std::vector<Eigen::Vector3d>& hi, const std::vector<Eigen::Vector3d>& centers);
};

}  // namespace metric
}  // namespace plaf
