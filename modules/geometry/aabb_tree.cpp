// SPDX-License-Identifier: MIT
// Bounding-box tree over triangles (see the header). Nodes are stored in one vector, children
// after their parent; a leaf owns a contiguous range of order_ (triangle ids). Queries walk the
// tree with an explicit stack so deep trees cannot overflow the call stack.
#include "modules/geometry/aabb_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace plaf {
inline namespace geometry {

using Eigen::AlignedBox3d;
using Eigen::Vector3d;

namespace {

constexpr int kLeafSize = 4;

AlignedBox3d triangle_box(const std::array<Vector3d, 3>& t) {
  AlignedBox3d b(t[0]);
  b.extend(t[1]);
  b.extend(t[2]);
  return b;
}

// Closest point to p on the closed segment ab and its parameter t (a + t (b - a)).
Vector3d closest_on_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b, double* t) {
  const Vector3d d = b - a;
  const double dd = d.squaredNorm();
  double s = dd > 0 ? (p - a).dot(d) / dd : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  *t = s;
  return a + s * d;
}

// The parameter interval [t0, t1] of the ray inside the box (slab test); false when it misses or
// leaves the box before t0.
bool ray_box(const AlignedBox3d& box, const Vector3d& o, const Vector3d& inv, double& t0, double& t1) {
  for (int a = 0; a < 3; ++a) {
    double lo = (box.min()[a] - o[a]) * inv[a], hi = (box.max()[a] - o[a]) * inv[a];
    if (lo > hi) std::swap(lo, hi);
    // 0 * inf (a ray in the box's plane) is NaN: such an axis does not narrow the interval.
    if (!std::isnan(lo)) t0 = std::max(t0, lo);
    if (!std::isnan(hi)) t1 = std::min(t1, hi);
    if (t0 > t1) return false;
  }
  return true;
}

// Moeller-Trumbore: the ray's parameter at triangle (a, b, c), or -1 when it misses.
double ray_triangle(const Vector3d& o, const Vector3d& d, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (det == 0) return -1;
  const double inv = 1 / det;
  const Vector3d s = o - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return -1;
  const Vector3d qv = s.cross(e1);
  const double v = d.dot(qv) * inv;
  if (v < 0 || u + v > 1) return -1;
  return e2.dot(qv) * inv;
}

}  // namespace

Vector3d closest_point_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c,
                                   Vector3d* barycentric) {
  // Inside the prism over the triangle the answer is the projection onto its plane; otherwise it
  // lies on the boundary, the closest of the three edges' closest points. A degenerate
  // (collinear) triangle has no plane and is handled as its edges.
  const Vector3d e0 = b - a, e1 = c - a, w = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double det = d00 * d11 - d01 * d01;
  // det = |e0 x e1|^2 suffers cancellation for slivers; below this relative size the plane
  // solve is not trusted and the edges (always well defined) decide.
  constexpr double kFlatRel = 1e-14;
  if (det > kFlatRel * d00 * d11) {
    const double d20 = w.dot(e0), d21 = w.dot(e1);
    const double v = (d11 * d20 - d01 * d21) / det;
    const double u = (d00 * d21 - d01 * d20) / det;
    if (v >= 0 && u >= 0 && v + u <= 1) {
      if (barycentric) *barycentric = Vector3d(1 - v - u, v, u);
      return a + v * e0 + u * e1;
    }
  }
  double t_ab = 0, t_bc = 0, t_ca = 0;
  const Vector3d q_ab = closest_on_segment(p, a, b, &t_ab);
  const Vector3d q_bc = closest_on_segment(p, b, c, &t_bc);
  const Vector3d q_ca = closest_on_segment(p, c, a, &t_ca);
  const double d_ab = (p - q_ab).squaredNorm(), d_bc = (p - q_bc).squaredNorm(), d_ca = (p - q_ca).squaredNorm();
  if (d_ab <= d_bc && d_ab <= d_ca) {
    if (barycentric) *barycentric = Vector3d(1 - t_ab, t_ab, 0);
    return q_ab;
  }
  if (d_bc <= d_ca) {
    if (barycentric) *barycentric = Vector3d(0, 1 - t_bc, t_bc);
    return q_bc;
  }
  if (barycentric) *barycentric = Vector3d(t_ca, 0, 1 - t_ca);
  return q_ca;
}

TriangleTree::TriangleTree(const std::vector<Vector3d>& points, const std::vector<std::array<int, 3>>& triangles) {
  tris_.reserve(triangles.size());
  for (const auto& t : triangles)
    tris_.push_back({points[static_cast<std::size_t>(t[0])], points[static_cast<std::size_t>(t[1])],
                     points[static_cast<std::size_t>(t[2])]});
  const int n = static_cast<int>(tris_.size());
  if (n == 0) return;
  order_.resize(tris_.size());
  std::vector<AlignedBox3d> boxes(tris_.size());
  std::vector<Vector3d> centers(tris_.size());
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    order_[k] = i;
    boxes[k] = triangle_box(tris_[k]);
    centers[k] = boxes[k].center();
  }
  nodes_.reserve(2 * tris_.size() / kLeafSize + 2);
  build(0, n, boxes, centers);
  // The triangles (and their boxes) stored in leaf order: a leaf's are contiguous in memory.
  std::vector<std::array<Vector3d, 3>> sorted;
  sorted.reserve(tris_.size());
  leaf_boxes_.reserve(tris_.size());
  slot_of_.resize(tris_.size());
  for (std::size_t i = 0; i < order_.size(); ++i) {
    const std::size_t t = static_cast<std::size_t>(order_[i]);
    sorted.push_back(tris_[t]);
    leaf_boxes_.push_back(boxes[t]);
    slot_of_[t] = static_cast<int>(i);
  }
  tris_ = std::move(sorted);
  const AlignedBox3d& all = nodes_[0].box;
  const double extent = std::max(all.min().cwiseAbs().maxCoeff(), all.max().cwiseAbs().maxCoeff());
  prune_abs_ = 1e-28 * extent * extent;
}

int TriangleTree::build(int first, int count, std::vector<AlignedBox3d>& boxes, std::vector<Vector3d>& centers) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  AlignedBox3d box;  // empty
  AlignedBox3d center_box;
  for (int i = first; i < first + count; ++i) {
    const auto t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
    box.extend(boxes[t]);
    center_box.extend(centers[t]);
  }
  nodes_[static_cast<std::size_t>(id)].box = box;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(id)].first = first;
    nodes_[static_cast<std::size_t>(id)].count = count;
    return id;
  }
  // Median split of the centres along the axis where they spread most: balanced depth
  // log2(n / kLeafSize) whatever the triangle distribution.
  int axis = 0;
  center_box.sizes().maxCoeff(&axis);
  const int half = count / 2;
  auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](int a, int b) {
    return centers[static_cast<std::size_t>(a)][axis] < centers[static_cast<std::size_t>(b)][axis];
  });
  const int left = build(first, half, boxes, centers);
  const int right = build(first + half, count - half, boxes, centers);
  Node& node = nodes_[static_cast<std::size_t>(id)];
  node.left = left;
  node.right = right;
  node.count = 0;
  return id;
}

void TriangleTree::query(const AlignedBox3d& box, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    if (!node.box.intersects(box)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = order_[static_cast<std::size_t>(i)];
        if (leaf_boxes_[static_cast<std::size_t>(i)].intersects(box)) out.push_back(t);
      }
    } else {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
}

TriangleTree::Closest TriangleTree::closest(const Vector3d& p) const {
  Closest best;
  best.distance2 = std::numeric_limits<double>::infinity();
  best.point = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  best.barycentric = Vector3d::Zero();
  if (nodes_.empty()) return best;
  // Depth first, nearer child first, so a good candidate prunes most boxes early. The stack is
  // the thread's own, kept between queries (no allocation per query: the wall metric asks one
  // per point it evaluates).
  thread_local std::vector<std::pair<double, int>> stack;
  // The thread's last answer on this tree bounds this one's distance from above: successive
  // queries are mostly near each other (a remesher's edge and the faces around it), so most
  // boxes are pruned at once. The answer is the same bit for bit: every triangle at the least
  // distance is still visited, in the same depth-first order (the bound only prunes boxes
  // farther than a triangle already known), and the first of them still wins.
  thread_local const TriangleTree* hint_tree = nullptr;
  thread_local std::size_t hint_slot = 0;
  if (hint_tree == this && hint_slot < tris_.size()) {
    const auto& tri = tris_[hint_slot];
    const double e2 = (closest_point_on_triangle(p, tri[0], tri[1], tri[2]) - p).squaredNorm();
    // (Just above it, so that the hint's own triangle is found again and recorded.)
    best.distance2 = std::nextafter(e2 * (1 + 1e-12) + prune_abs_, std::numeric_limits<double>::infinity());
  }
  stack.clear();
  stack.emplace_back(nodes_[0].box.squaredExteriorDistance(p), 0);
  while (!stack.empty()) {
    const auto [d2, id] = stack.back();
    stack.pop_back();
    if (d2 > best.distance2) continue;
    const Node& node = nodes_[static_cast<std::size_t>(id)];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const std::size_t slot = static_cast<std::size_t>(i);
        // A triangle whose box is farther than the best so far (by a relative 1e-9 and an
        // absolute (1e-14 x extent)^2, far beyond the rounding of either distance) cannot be
        // closer: skipped, the answer the same bit for bit.
        if (leaf_boxes_[slot].squaredExteriorDistance(p) > best.distance2 * (1 + 1e-9) + prune_abs_) continue;
        const int t = order_[slot];
        const auto& tri = tris_[slot];
        Vector3d bary;
        const Vector3d q = closest_point_on_triangle(p, tri[0], tri[1], tri[2], &bary);
        const double e2 = (q - p).squaredNorm();
        if (e2 < best.distance2) {
          best.distance2 = e2;
          best.point = q;
          best.triangle = t;
          best.barycentric = bary;
          hint_slot = slot;
        }
      }
      continue;
    }
    const double dl = nodes_[static_cast<std::size_t>(node.left)].box.squaredExteriorDistance(p);
    const double dr = nodes_[static_cast<std::size_t>(node.right)].box.squaredExteriorDistance(p);
    // The nearer child is pushed last, so it is visited first.
    if (dl <= dr) {
      if (dr <= best.distance2) stack.emplace_back(dr, node.right);
      if (dl <= best.distance2) stack.emplace_back(dl, node.left);
    } else {
      if (dl <= best.distance2) stack.emplace_back(dl, node.left);
      if (dr <= best.distance2) stack.emplace_back(dr, node.right);
    }
  }
  hint_tree = this;
  return best;
}

TriangleTree::Hit TriangleTree::first_hit(const Vector3d& origin, const Vector3d& dir, double t_min, double t_max,
                                          const std::function<bool(int)>& skip) const {
  Hit best;
  best.t = t_max;
  if (nodes_.empty()) return best;
  const Vector3d inv = dir.cwiseInverse();
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<std::size_t>(stack.back())];
    stack.pop_back();
    double t0 = t_min, t1 = best.t;
    if (!ray_box(node.box, origin, inv, t0, t1)) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = order_[static_cast<std::size_t>(i)];
        const auto& tri = tris_[static_cast<std::size_t>(i)];
        const double s = ray_triangle(origin, dir, tri[0], tri[1], tri[2]);
        if (s > t_min && s <= best.t && !(skip && skip(t))) {
          best.t = s;
          best.triangle = t;
        }
      }
      continue;
    }
    stack.push_back(node.left);
    stack.push_back(node.right);
  }
  if (best.triangle < 0) best.t = t_max;
  return best;
}

std::vector<std::pair<int, int>> TriangleTree::overlapping_pairs() const {
  std::vector<std::pair<int, int>> out;
  if (nodes_.empty()) return out;
  // Simultaneous descent: a node against itself splits into its two children against
  // themselves and against each other; two distinct nodes are visited only while their boxes
  // overlap, so the work is proportional to the overlapping node pairs, not n^2.
  std::vector<std::pair<int, int>> stack = {{0, 0}};
  while (!stack.empty()) {
    const auto [ia, ib] = stack.back();
    stack.pop_back();
    const Node& a = nodes_[static_cast<std::size_t>(ia)];
    const Node& b = nodes_[static_cast<std::size_t>(ib)];
    if (ia == ib) {
      if (a.count > 0) {
        for (int i = a.first; i < a.first + a.count; ++i) {
          const int ti = order_[static_cast<std::size_t>(i)];
          const AlignedBox3d& bi = leaf_boxes_[static_cast<std::size_t>(i)];
          for (int j = i + 1; j < a.first + a.count; ++j) {
            const int tj = order_[static_cast<std::size_t>(j)];
            if (bi.intersects(leaf_boxes_[static_cast<std::size_t>(j)]))
              out.emplace_back(std::min(ti, tj), std::max(ti, tj));
          }
        }
      } else {
        stack.emplace_back(a.left, a.left);
        stack.emplace_back(a.right, a.right);
        stack.emplace_back(a.left, a.right);
      }
      continue;
    }
    if (!a.box.intersects(b.box)) continue;
    if (a.count > 0 && b.count > 0) {
      for (int i = a.first; i < a.first + a.count; ++i) {
        const int ti = order_[static_cast<std::size_t>(i)];
        const AlignedBox3d& bi = leaf_boxes_[static_cast<std::size_t>(i)];
        if (!bi.intersects(b.box)) continue;
        for (int j = b.first; j < b.first + b.count; ++j) {
          const int tj = order_[static_cast<std::size_t>(j)];
          if (bi.intersects(leaf_boxes_[static_cast<std::size_t>(j)]))
            out.emplace_back(std::min(ti, tj), std::max(ti, tj));
        }
      }
      continue;
    }
    // Split the larger (or the inner) node so both sides shrink at a similar rate.
    const bool split_a =
        b.count > 0 || (a.count == 0 && a.box.diagonal().squaredNorm() >= b.box.diagonal().squaredNorm());
    if (split_a) {
      stack.emplace_back(a.left, ib);
      stack.emplace_back(a.right, ib);
    } else {
      stack.emplace_back(ia, b.left);
      stack.emplace_back(ia, b.right);
    }
  }
  return out;
}

}  // namespace geometry
}  // namespace plaf
