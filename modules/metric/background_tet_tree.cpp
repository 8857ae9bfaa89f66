// SPDX-License-Identifier: MIT
// Implements the point location of the 3D background-mesh field (background_tet_tree.h): the
// containing element of K. J. Fidkowski, *Anisotropic Metric-Based Curved Meshing Using
// Prismatic Layers*, Sec. II.D, found through a bounding-volume tree over the tetrahedra's boxes
// (built top down by median splits of the box centres along their longest extent).
#include "modules/metric/background_tet_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "modules/base/error.h"
#include "modules/geometry/aabb_tree.h"

namespace plaf {
inline namespace metric {
namespace {

// Leaves hold at most this many tetrahedra.
constexpr std::int32_t leaf_capacity = 4;
// Median splits halve the count: the tree is at most log2(2^31) levels deep, and a traversal
// keeps at most one pending node a level.
constexpr std::size_t max_stack = 64;

// Squared distance from x to the box [lo, hi]; 0 inside.
double box_distance2(const Eigen::Vector3d& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return (lo - x).cwiseMax(x - hi).cwiseMax(0.0).squaredNorm();
}

bool in_box(const Eigen::Vector3d& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all();
}

}  // namespace

BackgroundMetricField<3>::Tree::Tree(const BackgroundMesh<3>& mesh) {
  // 1. Per tetrahedron: validity, its box widened by its locate margin, the box centre.
  const std::size_t num_tets = mesh.simplices.size();
  std::vector<Eigen::Vector3d> lo(num_tets), hi(num_tets), centers(num_tets);
  std::vector<Eigen::Matrix3d> edges(num_tets);
  slot_of.assign(num_tets, -1);
  for (std::size_t t = 0; t < num_tets; ++t) {
    const auto& v = mesh.simplices[t];
    std::array<Eigen::Vector3d, 4> p;
    for (std::size_t i = 0; i < 4; ++i) p[i] = mesh.nodes[static_cast<std::size_t>(v[i])];
    edges[t] << p[1] - p[0], p[2] - p[0], p[3] - p[0];
    double longest2 = 0;
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j) longest2 = std::max(longest2, (p[i] - p[j]).squaredNorm());
    const double longest = std::sqrt(longest2), det = edges[t].determinant();  // regular: 0.707 L^3
    if (!(std::abs(det) > degenerate_rel * longest2 * longest) || !std::isfinite(det)) continue;
    const double margin = 2 * bary_tol_rel * longest;
    lo[t] = p[0].cwiseMin(p[1]).cwiseMin(p[2]).cwiseMin(p[3]).array() - margin;
    hi[t] = p[0].cwiseMax(p[1]).cwiseMax(p[2]).cwiseMax(p[3]).array() + margin;
    centers[t] = 0.5 * (lo[t] + hi[t]);
    items.push_back(static_cast<std::int32_t>(t));
  }
  if (items.empty()) throw InputError("background mesh has no tetrahedron of positive volume");

  // 2. The tree, then the affine data in leaf order.
  nodes.reserve(2 * items.size() / leaf_capacity + 2);
  build(0, static_cast<std::int32_t>(items.size()), lo, hi, centers);
  affine.resize(items.size());
  for (std::size_t s = 0; s < items.size(); ++s) {
    const auto t = static_cast<std::size_t>(items[s]);
    slot_of[t] = static_cast<std::int32_t>(s);
    affine[s] = {mesh.nodes[static_cast<std::size_t>(mesh.simplices[t][0])], edges[t].inverse()};
  }
}

std::int32_t BackgroundMetricField<3>::Tree::build(std::int32_t begin, std::int32_t end,
                                                   const std::vector<Eigen::Vector3d>& lo,
                                                   const std::vector<Eigen::Vector3d>& hi,
                                                   const std::vector<Eigen::Vector3d>& centers) {
  const auto index = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  Node node;
  node.lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  node.hi = -node.lo;
  Eigen::Vector3d c_lo = node.lo, c_hi = node.hi;
  for (std::int32_t k = begin; k < end; ++k) {
    const auto t = static_cast<std::size_t>(items[static_cast<std::size_t>(k)]);
    node.lo = node.lo.cwiseMin(lo[t]);
    node.hi = node.hi.cwiseMax(hi[t]);
    c_lo = c_lo.cwiseMin(centers[t]);
    c_hi = c_hi.cwiseMax(centers[t]);
  }
  if (end - begin <= leaf_capacity) {
    node.begin = begin;
    node.count = end - begin;
    nodes[static_cast<std::size_t>(index)] = node;
    return index;
  }
  int axis = 0;
  (c_hi - c_lo).maxCoeff(&axis);
  const std::int32_t mid = begin + (end - begin) / 2;
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                   [&](std::int32_t a, std::int32_t b) {
                     return centers[static_cast<std::size_t>(a)][axis] < centers[static_cast<std::size_t>(b)][axis];
                   });
  build(begin, mid, lo, hi, centers);  // the next node
  node.second = build(mid, end, lo, hi, centers);
  nodes[static_cast<std::size_t>(index)] = node;
  return index;
}

Eigen::Vector4d BackgroundMetricField<3>::Tree::barycentric(int t, const Eigen::Vector3d& x) const {
  const std::int32_t s = slot_of[static_cast<std::size_t>(t)];
  if (s < 0) return Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
  return slot_barycentric(static_cast<std::size_t>(s), x);
}

int BackgroundMetricField<3>::Tree::locate(const Eigen::Vector3d& x) const {
  // Every leaf whose box holds x, depth first: the first tetrahedron with x inside, else the one x
  // is least outside (within the tolerance).
  int best = -1;
  double best_min = -bary_tol_rel;
  std::array<std::int32_t, max_stack> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    std::int32_t n = stack[--top];
    while (true) {
      const Node& node = nodes[static_cast<std::size_t>(n)];
      if (!in_box(x, node.lo, node.hi)) break;
      if (node.count == 0) {
        stack[top++] = node.second;
        ++n;
        continue;
      }
      for (std::int32_t k = node.begin; k < node.begin + node.count; ++k) {
        const auto s = static_cast<std::size_t>(k);
        const double m = slot_barycentric(s, x).minCoeff();
        if (m >= 0) return items[s];
        if (m >= best_min) {
          best_min = m;
          best = items[s];
        }
      }
      break;
    }
  }
  return best;
}

BackgroundMetricField<3>::Tree::Nearest BackgroundMetricField<3>::Tree::nearest(const BackgroundMesh<3>& mesh,
                                                                                const Eigen::Vector3d& x) const {
  // Branch and bound over the tree: children visited nearest first, nodes and tetrahedra pruned by
  // the distance to their boxes (which hold them, so the pruning is exact). A tetrahedron's
  // closest point to x outside it is the closest of its faces' closest points.
  struct Entry {
    std::int32_t node;
    double dist2;
  };
  std::array<Entry, 2 * max_stack> stack;
  std::size_t top = 0;
  stack[top++] = {0, box_distance2(x, nodes[0].lo, nodes[0].hi)};
  double best2 = std::numeric_limits<double>::infinity();
  Nearest best;
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.dist2 >= best2) continue;
    const Node& node = nodes[static_cast<std::size_t>(e.node)];
    if (node.count > 0) {
      for (std::int32_t k = node.begin; k < node.begin + node.count; ++k) {
        const auto s = static_cast<std::size_t>(k);
        const Eigen::Vector4d inside = slot_barycentric(s, x);
        if (inside.minCoeff() >= 0) return {items[s], inside};
        const auto& v = mesh.simplices[static_cast<std::size_t>(items[s])];
        std::array<const Eigen::Vector3d*, 4> p;
        for (std::size_t i = 0; i < 4; ++i) p[i] = &mesh.nodes[static_cast<std::size_t>(v[i])];
        const Eigen::Vector3d lo = p[0]->cwiseMin(*p[1]).cwiseMin(*p[2]).cwiseMin(*p[3]);
        const Eigen::Vector3d hi = p[0]->cwiseMax(*p[1]).cwiseMax(*p[2]).cwiseMax(*p[3]);
        if (box_distance2(x, lo, hi) >= best2) continue;
        // The closest point lies on a face x is beyond (the outward normal cone at it holds x - p):
        // the face opposite a vertex whose barycentric coordinate is negative.
        for (std::size_t f = 0; f < 4; ++f) {
          if (inside[static_cast<Eigen::Index>(f)] >= 0) continue;
          std::array<std::size_t, 3> corner;
          for (std::size_t i = 0, j = 0; i < 4; ++i)
            if (i != f) corner[j++] = i;
          Eigen::Vector3d face_weights;
          const Eigen::Vector3d q =
              closest_point_on_triangle(x, *p[corner[0]], *p[corner[1]], *p[corner[2]], &face_weights);
          const double d2 = (q - x).squaredNorm();
          if (d2 < best2) {
            best2 = d2;
            best.simplex = items[s];
            best.weights.setZero();
            for (std::size_t j = 0; j < 3; ++j)
              best.weights[static_cast<Eigen::Index>(corner[j])] = face_weights[static_cast<Eigen::Index>(j)];
          }
        }
      }
      continue;
    }
    Entry first{e.node + 1, 0}, second{node.second, 0};
    first.dist2 = box_distance2(x, nodes[static_cast<std::size_t>(first.node)].lo,
                                nodes[static_cast<std::size_t>(first.node)].hi);
    second.dist2 = box_distance2(x, nodes[static_cast<std::size_t>(second.node)].lo,
                                 nodes[static_cast<std::size_t>(second.node)].hi);
    if (first.dist2 < second.dist2) std::swap(first, second);  // the nearer is popped first
    if (first.dist2 < best2) stack[top++] = first;
    if (second.dist2 < best2) stack[top++] = second;
  }
  return best;
}

}  // namespace metric
}  // namespace plaf
