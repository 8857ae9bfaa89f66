// SPDX-License-Identifier: MIT
// Implements the point location of the background-mesh field (background_quadtree.h): the
// containing element of K. J. Fidkowski, *Anisotropic Metric-Based Curved Meshing Using
// Prismatic Layers*, Sec. II.D, found through a quadtree over the triangles' bounding boxes.
#include "modules/metric/background_quadtree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {
namespace {

// A quadtree cell is split while it holds more than leaf_capacity triangles, is shallower than
// max_depth, and its side is larger than split_stop_rel times the smallest altitude of its
// triangles (below that, splitting cannot separate triangles that meet at one vertex).
constexpr std::size_t leaf_capacity = 8;
constexpr int max_depth = 40;
constexpr double split_stop_rel = 1.0;

// Squared distance from x to the axis-aligned square (c, half); 0 inside.
double box_distance2(const Eigen::Vector2d& x, const Eigen::Vector2d& c, double half) {
  const double dx = std::max(0.0, std::abs(x[0] - c[0]) - half);
  const double dy = std::max(0.0, std::abs(x[1] - c[1]) - half);
  return dx * dx + dy * dy;
}

// Closest point to x on the segment p q.
Eigen::Vector2d closest_on_segment(const Eigen::Vector2d& x, const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
  const Eigen::Vector2d e = q - p;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0 ? std::clamp((x - p).dot(e) / len2, 0.0, 1.0) : 0.0;
  return p + t * e;
}

// Does the triangle (p0, p1, p2) meet the square (c, half) widened by margin? Separating axes:
// the square's two axes and the three edge normals.
bool triangle_meets_square(const std::array<Eigen::Vector2d, 3>& p, const Eigen::Vector2d& c, double half) {
  for (int d = 0; d < 2; ++d) {
    const double lo = std::min({p[0][d], p[1][d], p[2][d]}), hi = std::max({p[0][d], p[1][d], p[2][d]});
    if (lo > c[d] + half || hi < c[d] - half) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d& a = p[static_cast<std::size_t>(i)];
    const Eigen::Vector2d& b = p[static_cast<std::size_t>((i + 1) % 3)];
    const Eigen::Vector2d& o = p[static_cast<std::size_t>((i + 2) % 3)];
    Eigen::Vector2d n(b[1] - a[1], a[0] - b[0]);
    if (n.dot(o - a) > 0) n = -n;  // outward
    // The square's corner deepest inside the edge's half plane.
    if (n.dot(c - a) - half * (std::abs(n[0]) + std::abs(n[1])) > 0) return false;
  }
  return true;
}

}  // namespace

BackgroundMetricField<2>::Tree::Tree(const BackgroundMesh<2>& mesh) {
  // 1. Per-triangle affine data.
  const std::size_t num_tris = mesh.simplices.size();
  affine.resize(num_tris);
  min_altitude.resize(num_tris);
  diameter.resize(num_tris);
  valid.resize(num_tris);
  std::vector<std::int32_t> all;
  all.reserve(num_tris);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  double max_margin = 0;
  for (std::size_t t = 0; t < num_tris; ++t) {
    const auto& tri = mesh.simplices[t];
    const Eigen::Vector2d &a = mesh.nodes[tri[0]], &b = mesh.nodes[tri[1]], &c = mesh.nodes[tri[2]];
    Eigen::Matrix2d e;
    e << b - a, c - a;
    const double det = e.determinant();
    const double longest = std::sqrt(std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()}));
    affine[t].origin = a;
    diameter[t] = longest;
    valid[t] = std::abs(det) > degenerate_rel * longest * longest && std::isfinite(det);
    if (!valid[t]) {
      affine[t].inverse.setConstant(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    affine[t].inverse = e.inverse();
    min_altitude[t] = std::abs(det) / longest;
    all.push_back(static_cast<std::int32_t>(t));
    for (const Eigen::Vector2d* p : {&a, &b, &c}) {
      lo = lo.cwiseMin(*p);
      hi = hi.cwiseMax(*p);
    }
    max_margin = std::max(max_margin, 2 * bary_tol_rel * longest);
  }
  if (all.empty()) throw InputError("background mesh has no triangle of positive area");

  // 2. The tree: a square root cell around every triangle (widened by the largest locate
  //    margin), split recursively; O(N log N) for meshes of bounded vertex degree.
  center = 0.5 * (lo + hi);
  half = 0.5 * (hi - lo).maxCoeff() + max_margin;
  half *= 1 + 1e-12;
  nodes.push_back({});
  items.reserve(2 * all.size());
  build(mesh, 0, center, half, 0, std::move(all));
}

void BackgroundMetricField<2>::Tree::build(const BackgroundMesh<2>& mesh, std::size_t node, const Eigen::Vector2d& c,
                                           double cell_half, int depth, std::vector<std::int32_t> tris) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::int32_t t : tris) smallest = std::min(smallest, min_altitude[static_cast<std::size_t>(t)]);
  if (tris.size() <= leaf_capacity || depth >= max_depth || 2 * cell_half < split_stop_rel * smallest) {
    nodes[node].begin = static_cast<std::int32_t>(items.size());
    nodes[node].count = static_cast<std::int32_t>(tris.size());
    items.insert(items.end(), tris.begin(), tris.end());
    return;
  }
  const std::size_t first = nodes.size();
  nodes[node].first_child = static_cast<std::int32_t>(first);
  nodes.resize(first + 4);
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d cc = child_center(c, cell_half, k);
    std::vector<std::int32_t> sub;
    for (std::int32_t t : tris) {
      const auto& tri = mesh.simplices[static_cast<std::size_t>(t)];
      const double margin = 2 * bary_tol_rel * diameter[static_cast<std::size_t>(t)];
      if (triangle_meets_square({mesh.nodes[tri[0]], mesh.nodes[tri[1]], mesh.nodes[tri[2]]}, cc,
                                0.5 * cell_half + margin))
        sub.push_back(t);
    }
    build(mesh, first + static_cast<std::size_t>(k), cc, 0.5 * cell_half, depth + 1, std::move(sub));
  }
}

Eigen::Vector3d BackgroundMetricField<2>::Tree::barycentric(int t, const Eigen::Vector2d& x) const {
  const auto i = static_cast<std::size_t>(t);
  const Affine& a = affine[i];
  const Eigen::Vector2d l = a.inverse * (x - a.origin);
  return {1 - l[0] - l[1], l[0], l[1]};
}

int BackgroundMetricField<2>::Tree::locate(const Eigen::Vector2d& x) const {
  if (box_distance2(x, center, half) > 0) return -1;
  // Descend to the leaf holding x.
  std::size_t node = 0;
  Eigen::Vector2d c = center;
  double h = half;
  while (nodes[node].first_child >= 0) {
    const int k = quadrant(x, c);
    c = child_center(c, h, k);
    h *= 0.5;
    node = static_cast<std::size_t>(nodes[node].first_child + k);
  }
  // Of its triangles, the first with x inside, else the one x is least outside (within tolerance).
  int best = -1;
  double best_min = -bary_tol_rel;
  const Node& leaf = nodes[node];
  for (std::int32_t k = 0; k < leaf.count; ++k) {
    const int t = items[static_cast<std::size_t>(leaf.begin + k)];
    const double m = barycentric(t, x).minCoeff();
    if (m >= 0) return t;
    if (m >= best_min) {
      best_min = m;
      best = t;
    }
  }
  return best;
}

BackgroundMetricField<2>::Tree::Nearest BackgroundMetricField<2>::Tree::nearest(const BackgroundMesh<2>& mesh,
                                                                                const Eigen::Vector2d& x) const {
  // Branch and bound over the tree (children visited nearest first, cells pruned by their
  // distance). The closest point of a triangle lies in a leaf that lists it, so pruning by cell
  // distance is exact.
  struct Entry {
    std::int32_t node;
    double half, dist2;
    Eigen::Vector2d c;
  };
  std::array<Entry, 4 * max_depth + 8> stack;  // depth-first: at most 3 pending siblings a level
  std::size_t top = 0;
  stack[top++] = {0, half, box_distance2(x, center, half), center};
  double best2 = std::numeric_limits<double>::infinity();
  int best = -1;
  Eigen::Vector2d best_point = x;
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.dist2 >= best2) continue;
    const Node& n = nodes[static_cast<std::size_t>(e.node)];
    if (n.first_child < 0) {
      for (std::int32_t k = 0; k < n.count; ++k) {
        const int tri = items[static_cast<std::size_t>(n.begin + k)];
        const auto& v = mesh.simplices[static_cast<std::size_t>(tri)];
        for (int i = 0; i < 3; ++i) {
          const Eigen::Vector2d p =
              closest_on_segment(x, mesh.nodes[v[static_cast<std::size_t>(i)]], mesh.nodes[v[(i + 1) % 3]]);
          const double d2 = (p - x).squaredNorm();
          if (d2 < best2) {
            best2 = d2;
            best = tri;
            best_point = p;
          }
        }
      }
      continue;
    }
    std::array<Entry, 4> children;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d cc = child_center(e.c, e.half, k);
      children[static_cast<std::size_t>(k)] = {n.first_child + k, 0.5 * e.half, box_distance2(x, cc, 0.5 * e.half), cc};
    }
    std::sort(children.begin(), children.end(), [](const Entry& a, const Entry& b) { return a.dist2 > b.dist2; });
    for (const Entry& child : children)
      if (child.dist2 < best2) stack[top++] = child;
  }
  if (best < 0) return {};
  return {best, barycentric(best, best_point)};
}

}  // namespace metric
}  // namespace plaf
