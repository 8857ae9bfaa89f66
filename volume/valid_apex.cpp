// SPDX-License-Identifier: MIT
// Implements the candidate-triangle tests of the 2D advancing front (valid_apex.h) with the
// exact predicates of predicates.h.
#include "volume/valid_apex.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "modules/geometry/predicates.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;

// A front node closer than this (metric units) to a new edge counts as on it.
constexpr double kOnEdge = 1e-6;

bool in_closed_triangle(const Vec& a, const Vec& b, const Vec& c, const Vec& q) {
  return orient2d(a, b, q) >= 0 && orient2d(b, c, q) >= 0 && orient2d(c, a, q) >= 0;
}

double point_segment_distance(const Vec& x, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((x - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - x).norm();
}

// 4 sqrt(3) A / (l1^2 + l2^2 + l3^2) in the metric space of f: 1 for an equilateral triangle.
double shape_quality(const Vec& a, const Vec& b, const Vec& c, const Mat& f) {
  const Vec u = f * (b - a), w = f * (c - a), v = w - u;
  const double l2 = u.squaredNorm() + w.squaredNorm() + v.squaredNorm();
  return l2 > 0 ? 2 * std::sqrt(3.0) * cross(u, w) / l2 : 0.0;
}

}  // namespace

bool valid_apex(const OccurrenceFront& front, int o, const Apex& c, double min_quality, double max_length) {
  const int ob = front.next(o);
  const Vec &a = front.opt(o), &b = front.opt(ob), &x = c.point;
  if (!(orient2d(a, b, x) > 0)) return false;
  if (min_quality > 0 && shape_quality(a, b, x, front.nm(front.nd(o)).f) < min_quality) return false;
  const int op = front.prev(o), obn = front.next(ob);
  const bool closes_a = c.occ >= 0 && c.node == front.nd(op);   // a -> c is the front edge c -> a
  const bool closes_b = c.occ >= 0 && c.node == front.nd(obn);  // c -> b is the front edge b -> c
  if (!closes_a && !in_sector(a, b, front.opt(op), x)) return false;
  if (!closes_b && !in_sector(b, front.opt(obn), a, x)) return false;
  if (c.occ >= 0 && !in_sector(x, front.opt(front.next(c.occ)), front.opt(front.prev(c.occ)), 0.5 * (a + b)))
    return false;
  const NodeId na = front.nd(o), nb = front.nd(ob);
  Box box = segment_box(a, b);
  box = {std::min(box.x0, x.x()), std::min(box.y0, x.y()), std::max(box.x1, x.x()), std::max(box.y1, x.y())};
  bool ok = true;
  front.edges_near(box, [&](int e) {
    if (!ok) return;
    const int en = front.next(e);
    const NodeId s = front.nd(e), t = front.nd(en);
    const Vec &ps = front.opt(e), &pt_ = front.opt(en);
    // Front nodes inside or on the triangle, or so near a new edge that only rounding keeps them
    // off it (kOnEdge in the metric): a fan's kites put P_k exactly on the line X_k-1 X_k
    // (Fig. 4), and an edge X_k-1 X_k that rounding let pass left a zero-area pocket the fill
    // could close only with a flat triangle (E387, h0 5e-3 c, Q2: quality 2e-15, then inverted).
    for (const auto& [v, p] : {std::pair{s, &ps}, std::pair{t, &pt_}}) {
      if (v == na || v == nb || v == c.node) continue;
      if (in_closed_triangle(a, b, x, *p)) ok = false;
      const Mat& f = front.nm(na).f;
      if ((!closes_a && point_segment_distance(f * *p, f * a, f * x) < kOnEdge) ||
          (!closes_b && point_segment_distance(f * *p, f * x, f * b) < kOnEdge))
        ok = false;
    }
    if (!ok) return;
    // Front edges crossing or touching the new edges a - c and c - b.
    auto blocks = [&](NodeId u, const Vec& pu) {
      const bool shares = s == u || t == u || s == c.node || t == c.node;
      if (!shares) return segments_intersect(pu, x, ps, pt_);
      return false;  // a shared end: a collinear overlap puts the other end on the edge (tested above)
    };
    if (!closes_a && blocks(na, a)) ok = false;
    if (!closes_b && blocks(nb, b)) ok = false;
  });
  // The new edges' metric length, integrated along them (the metric may vary fast across a
  // coarse edge: a short edge in the node's metric may cross a fine region).
  // An edge already longer than that may keep its apex as far as its own length.
  if (ok && max_length > 0) {
    const MetricField<2>& metric = front.metric();
    const double l_max = std::max(max_length, metric_length(metric, a, b, 5));
    ok = (closes_a || metric_length(metric, a, x, 5) <= l_max) && (closes_b || metric_length(metric, x, b, 5) <= l_max);
  }
  return ok;
}

bool clear_of_front(const OccurrenceFront& front, const Vec& x, const NodeMetric& m, double clearance) {
  const double r = clearance;
  const Mat m_inv = m.f_inv * m.f_inv;
  const double hx = r * std::sqrt(m_inv(0, 0)), hy = r * std::sqrt(m_inv(1, 1));
  bool ok = true;
  front.edges_near({x.x() - hx, x.y() - hy, x.x() + hx, x.y() + hy}, [&](int e) {
    if (ok && point_segment_distance(m.f * x, m.f * front.opt(e), m.f * front.opt(front.next(e))) < r) ok = false;
  });
  return ok;
}

}  // namespace plaf::volume
