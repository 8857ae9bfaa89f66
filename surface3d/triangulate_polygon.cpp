// SPDX-License-Identifier: MIT
// Planar polygon triangulation (see triangulate_polygon.h): ear clipping, then Lawson flips.
#include "surface3d/triangulate_polygon.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <utility>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"

namespace plaf::analytic_detail {

using Eigen::Vector2d;

namespace {

// Ear clipping of the simple polygon pts: counter-clockwise triangles, with exact orientation
// and containment tests.
std::vector<std::array<int, 3>> clip_ears(const std::vector<Vector2d>& pts, const std::string& name) {
  const int n = static_cast<int>(pts.size());
  double area = 0;
  for (int i = 0; i < n; ++i) {
    const Vector2d& a = pts[i];
    const Vector2d& b = pts[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (area < 0) std::reverse(order.begin(), order.end());
  std::vector<int> prev(n), next(n);
  for (int k = 0; k < n; ++k) {
    prev[order[k]] = order[(k + n - 1) % n];
    next[order[k]] = order[(k + 1) % n];
  }
  std::vector<std::array<int, 3>> tris;
  int remaining = n, v = order[0], misses = 0;
  const auto inside_closed = [&](const Vector2d& p, int a, int b, int c) {
    return sign_orient2d(pts[a], pts[b], p) >= 0 && sign_orient2d(pts[b], pts[c], p) >= 0 &&
           sign_orient2d(pts[c], pts[a], p) >= 0;
  };
  while (remaining > 3) {
    const int a = prev[v], c = next[v];
    bool ear = sign_orient2d(pts[a], pts[v], pts[c]) > 0;
    for (int w = next[c]; ear && w != a; w = next[w]) {
      if (pts[w] == pts[a] || pts[w] == pts[v] || pts[w] == pts[c]) continue;
      if (inside_closed(pts[w], a, v, c)) ear = false;
    }
    if (ear) {
      tris.push_back({a, v, c});
      next[a] = c;
      prev[c] = a;
      --remaining;
      v = c;
      misses = 0;
    } else {
      v = next[v];
      if (++misses > remaining) throw MesherError(name + ": the polygon is not simple (no ear left to clip)");
    }
  }
  tris.push_back({prev[v], v, next[v]});
  return tris;
}

// Lawson flips: an interior edge (a, b) with opposite vertices c (in a, b, c) and d (in b, a, d)
// is flipped to (c, d) when d is inside the circumcircle of a, b, c and the quad is convex.
// Inexact in-circle test with a relative margin: a flip needs a clear gain, so cocircular
// configurations never flip back and forth.
void flip_to_delaunay(const std::vector<Vector2d>& pts, std::vector<std::array<int, 3>>& tris) {
  const int n = static_cast<int>(pts.size());
  const auto incircle = [&](int a, int b, int c, int d) {
    const Vector2d pa = pts[a] - pts[d], pb = pts[b] - pts[d], pc = pts[c] - pts[d];
    const double det = pa.squaredNorm() * (pb.x() * pc.y() - pb.y() * pc.x()) -
                       pb.squaredNorm() * (pa.x() * pc.y() - pa.y() * pc.x()) +
                       pc.squaredNorm() * (pa.x() * pb.y() - pa.y() * pb.x());
    const double size = std::max({pa.squaredNorm(), pb.squaredNorm(), pc.squaredNorm()});
    return det > 1e-10 * size * size;
  };
  for (int sweep = 0; sweep < 10 * n; ++sweep) {
    std::map<std::pair<int, int>, std::pair<int, int>> edge_to;  // directed edge -> (triangle, local index)
    for (int t = 0; t < static_cast<int>(tris.size()); ++t)
      for (int k = 0; k < 3; ++k) edge_to[{tris[t][k], tris[t][(k + 1) % 3]}] = {t, k};
    bool flipped = false;
    std::vector<bool> touched(tris.size(), false);
    for (const auto& [e, tk] : edge_to) {
      const auto it = edge_to.find({e.second, e.first});
      if (it == edge_to.end()) continue;
      const int t1 = tk.first, t2 = it->second.first;
      if (touched[t1] || touched[t2]) continue;
      const int a = e.first, b = e.second;
      const int c = tris[t1][(tk.second + 2) % 3], d = tris[t2][(it->second.second + 2) % 3];
      if (!incircle(a, b, c, d)) continue;
      if (sign_orient2d(pts[c], pts[d], pts[b]) <= 0 || sign_orient2d(pts[d], pts[c], pts[a]) <= 0) continue;
      tris[t1] = {c, d, b};
      tris[t2] = {d, c, a};
      touched[t1] = touched[t2] = true;
      flipped = true;
    }
    if (!flipped) break;
  }
}

}  // namespace

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vector2d>& pts, const std::string& name) {
  const int n = static_cast<int>(pts.size());
  if (n < 3) throw MesherError(name + ": a polygon needs 3 points, got " + std::to_string(n));
  std::vector<std::array<int, 3>> tris = clip_ears(pts, name);
  flip_to_delaunay(pts, tris);
  return tris;
}

bool polygon_is_simple(const std::vector<Vector2d>& p) {
  const int n = static_cast<int>(p.size());
  if (n < 3) return false;
  for (int i = 0; i < n; ++i) {
    if (p[i] == p[(i + 1) % n]) return false;
    for (int j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) continue;
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
    }
  }
  return true;
}

}  // namespace plaf::analytic_detail
