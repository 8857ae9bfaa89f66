// SPDX-License-Identifier: MIT
// A static bounding-box tree over triangles: candidate pairs for the self-intersection test,
// closest points for projection onto a discrete surface, and box queries (later: layer
// collisions, and the first triangle a ray meets (the layers' proximity rule). Built top down by median splits along the longest box axis, leaves of a few
// triangles; O(n log n) to build, queries O(log n + k).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <utility>
#include <vector>

namespace plaf {
inline namespace geometry {

class TriangleTree {
 public:
  TriangleTree() = default;
  // Copies the triangles' coordinates (indices into points).
  TriangleTree(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 3>>& triangles);

  std::size_t size() const { return tris_.size(); }
  const std::array<Eigen::Vector3d, 3>& triangle(int t) const {
    return tris_[static_cast<std::size_t>(slot_of_[static_cast<std::size_t>(t)])];
  }

  // Triangles whose bounding boxes overlap the box (closed), appended to out.
  void query(const Eigen::AlignedBox3d& box, std::vector<int>& out) const;

  struct Closest {
    Eigen::Vector3d point;             // closest point on the triangles
    int triangle = -1;                 // the triangle it lies on
    Eigen::Vector3d barycentric;       // of point in that triangle
    double distance2 = 0;              // squared distance to the query point
  };
  // The closest point on all triangles (exact per triangle, pruned by box distance; the calling
  // thread's last answer on this tree bounds the search, which leaves the answer, ties included,
  // the same bit for bit: successive queries near each other prune most boxes at once).
  Closest closest(const Eigen::Vector3d& p) const;

  struct Hit {
    int triangle = -1;  // -1: the ray meets no triangle in (t_min, t_max]
    double t = 0;       // origin + t * dir is the hit point
  };
  // The nearest triangle that the ray origin + t * dir, t in (t_min, t_max], meets (Moeller and
  // Trumbore's test in doubles: a hit on an edge may be missed or found twice, which a distance
  // query tolerates). dir need not be unit; t is in its units.
  // Triangles that `skip` accepts (when given) are passed through.
  Hit first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min, double t_max,
                const std::function<bool(int)>& skip = {}) const;

  // All pairs (i < j) of triangles whose boxes overlap (closed boxes), for exact tests after.
  std::vector<std::pair<int, int>> overlapping_pairs() const;

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    int first = 0, count = 0;  // leaf: range in order_; inner: count = 0
    int left = -1, right = -1;
  };
  // The triangles and their boxes by slot: in leaf order (order_[slot] is the triangle's id,
  // slot_of_ the inverse), each leaf's contiguous in memory.
  std::vector<std::array<Eigen::Vector3d, 3>> tris_;
  std::vector<Eigen::AlignedBox3d> leaf_boxes_;
  std::vector<int> order_, slot_of_;
  double prune_abs_ = 0;  // closest(): an absolute margin of the box prune, (1e-14 x the extent)^2
  std::vector<Node> nodes_;
  int build(int first, int count, std::vector<Eigen::AlignedBox3d>& boxes, std::vector<Eigen::Vector3d>& centers);
};

// Closest point to p on triangle (a, b, c), with its barycentric coordinates.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, Eigen::Vector3d* barycentric = nullptr);

}  // namespace geometry
}  // namespace plaf
