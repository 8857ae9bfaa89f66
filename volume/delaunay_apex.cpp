// SPDX-License-Identifier: MIT
// Implements the constrained-Delaunay fallback of the 2D advancing front (delaunay_apex.h).
#include "volume/delaunay_apex.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "modules/geometry/predicates.h"
#include "volume/valid_apex.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;

}  // namespace

std::optional<Apex> delaunay_apex(const OccurrenceFront& front, int o, const AdvancingFrontParams& params) {
  const int ob = front.next(o);
  const NodeId na = front.nd(o), nb = front.nd(ob);
  const Vec &a = front.opt(o), &b = front.opt(ob);
  const Mat& f = front.nm(na).f;
  const Vec fa = f * a, fb = f * b, mid = 0.5 * (fa + fb);
  const Vec normal = Vec(-(fb - fa).y(), (fb - fa).x()).normalized();
  const double half_ab = 0.5 * (fb - fa).norm();
  double r = (b - a).norm();
  std::vector<std::pair<double, NodeId>> cand;
  for (int round = 0; round < 80; ++round, r *= 2) {
    cand.clear();
    const Vec c0 = 0.5 * (a + b);
    front.edges_near({c0.x() - r, c0.y() - r, c0.x() + r, c0.y() + r}, [&](int e) {
      for (NodeId v : {front.nd(e), front.nd(front.next(e))}) {
        if (v == na || v == nb || !(orient2d(a, b, front.pt(v)) > 0)) continue;
        // Centre of the circle through a, b, v (metric space) along the normal: k with
        // |w - (mid + k n)|^2 = half_ab^2 + k^2.
        const Vec w = f * front.pt(v) - mid;
        const double k = (w.squaredNorm() - half_ab * half_ab) / (2 * w.dot(normal));
        cand.emplace_back(k, v);
      }
    });
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    // The best-shaped valid apex first; then a new point on the edge's metric-equilateral
    // apex, lowered step by step; a sliver only when nothing else is valid.
    for (const auto& [q_min, l_max] : {std::pair{params.min_quality, params.max_length}, std::pair{1e-3, 0.0},
                                       std::pair{-1.0, 0.0}, std::pair{0.0, 0.0}}) {
      if (q_min < 0) {
        // New points once, near the edge, and not on an edge already much shorter than the
        // metric asks (under 0.35 units): there each new point made a shorter edge for the next
        // fallback, a cascade down to nodes 1e-10 apart before the NACA 0012's leading edge at
        // h0 1e-6 c (issue 12); such an edge takes an existing node below.
        if (round > 0 || 2 * half_ab < 0.35) continue;
        const Mat f_inv = front.nm(na).f_inv;
        for (double height : {0.866, 0.5, 0.25, 0.125, 0.0625}) {
          const Apex c{-1, -1, f_inv * (mid + height * 2 * half_ab * normal)};
          // Clear of the other front edges by half its height (in the edge's metric): a point
          // lowered onto a crowded spot made near-duplicate nodes 3e-10 apart behind the NACA
          // 0012's blunt trailing edge (issue 12).
          if (valid_apex(front, o, c, 1e-3) && clear_of_front(front, c.point, front.nm(na), height * half_ab))
            return c;
        }
        continue;
      }
      for (const auto& [k, v] : cand) {
        const Apex c{v, front.occurrence_towards(v, 0.5 * (a + b)), front.pt(v)};
        if (c.occ >= 0 && valid_apex(front, o, c, q_min, l_max)) return c;
      }
    }
    if (r > 2 * front.root_extent()) break;
  }
  return std::nullopt;
}

}  // namespace plaf::volume
