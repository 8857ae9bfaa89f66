// SPDX-License-Identifier: MIT
// The metric-based advancing front (advancing_front_2d.h).
//
// The front is a set of occurrences: an occurrence is one appearance of a node on a front loop,
// with its previous and next occurrence. A node appears more than once where fronts touch after a
// merge (a pinch); the free angle of each occurrence is the counter-clockwise sector from its
// next edge to its previous edge. Every change of the front is one operation, advance(o, c): the
// triangle (a, b, c) on the front edge a -> b of occurrence o, with c a new point or an existing
// front node; a -> b becomes a -> c -> b, and zero-area spikes (x -> y -> x) are removed, which is
// how loops close, merge and split.
#include "volume/advancing_front_2d.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <queue>
#include <sstream>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;

struct Box {
  double x0, y0, x1, y1;
  bool intersects(const Box& o) const { return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
};

Box segment_box(const Vec& a, const Vec& b) {
  return {std::min(a.x(), b.x()), std::min(a.y(), b.y()), std::max(a.x(), b.x()), std::max(a.y(), b.y())};
}

// A loose quadtree of boxes: an item lives in the deepest cell whose half-size is at least its
// extent and which contains its centre; a cell's loose box (twice its size) then contains the
// item. Items of any size mix well: an item is found by visiting O(depth) cells plus those near
// the query.
class LooseQuadtree {
 public:
  explicit LooseQuadtree(const Box& domain) {
    const double half = 0.5 * std::max(domain.x1 - domain.x0, domain.y1 - domain.y0) * 1.01 + 1e-300;
    cells_.push_back({0.5 * (domain.x0 + domain.x1), 0.5 * (domain.y0 + domain.y1), half, {-1, -1, -1, -1}, {}});
  }

  void insert(int id, const Box& b) {
    if (static_cast<std::size_t>(id) >= where_.size()) {
      where_.resize(2 * static_cast<std::size_t>(id) + 16, {-1, -1});
      boxes_.resize(where_.size());
    }
    boxes_[id] = b;
    const double ext = std::max(b.x1 - b.x0, b.y1 - b.y0);
    const double cx = 0.5 * (b.x0 + b.x1), cy = 0.5 * (b.y0 + b.y1);
    int c = 0;
    const Cell& root = cells_[0];
    const bool inside = std::abs(cx - root.cx) <= root.half && std::abs(cy - root.cy) <= root.half;
    for (int depth = 0; inside && depth < 60; ++depth) {
      const double h = 0.5 * cells_[c].half;
      if (ext > h) break;
      const int q = (cx >= cells_[c].cx ? 1 : 0) + (cy >= cells_[c].cy ? 2 : 0);
      if (cells_[c].child[q] < 0) {
        const Cell child{cells_[c].cx + (q & 1 ? h : -h), cells_[c].cy + (q & 2 ? h : -h), h, {-1, -1, -1, -1}, {}};
        cells_[c].child[q] = static_cast<int>(cells_.size());
        cells_.push_back(child);
      }
      c = cells_[c].child[q];
    }
    where_[id] = {c, static_cast<int>(cells_[c].items.size())};
    cells_[c].items.push_back(id);
  }

  void remove(int id) {
    if (static_cast<std::size_t>(id) >= where_.size() || where_[id].first < 0) return;
    auto [c, slot] = where_[id];
    std::vector<int>& items = cells_[c].items;
    items[slot] = items.back();
    where_[items[slot]].second = slot;
    items.pop_back();
    where_[id] = {-1, -1};
  }

  // Calls f(id) for every item whose box intersects q.
  template <class F>
  void query(const Box& q, F&& f) const {
    stack_.clear();
    stack_.push_back(0);
    while (!stack_.empty()) {
      const int c = stack_.back();
      stack_.pop_back();
      const Cell& cell = cells_[c];
      // The root holds items outside its box too: never skip it.
      if (c != 0) {
        const double l = 2 * cell.half;
        if (!Box{cell.cx - l, cell.cy - l, cell.cx + l, cell.cy + l}.intersects(q)) continue;
      }
      for (int id : cell.items)
        if (boxes_[id].intersects(q)) f(id);
      for (int ch : cell.child)
        if (ch >= 0) stack_.push_back(ch);
    }
  }

 private:
  struct Cell {
    double cx, cy, half;
    std::array<int, 4> child;
    std::vector<int> items;
  };
  std::vector<Cell> cells_;
  std::vector<Box> boxes_;
  std::vector<std::pair<int, int>> where_;  // id -> (cell, slot); cell -1: absent
  mutable std::vector<int> stack_;
};

// M^(1/2) and M^(-1/2) of a node's metric: the map to the space where the metric is Euclidean.
struct NodeMetric {
  Mat f;
  Mat f_inv;
};

NodeMetric node_metric(const Metric<2>& m) {
  Eigen::SelfAdjointEigenSolver<Mat> es;
  es.computeDirect(m.matrix());
  const Eigen::Vector2d s = es.eigenvalues().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt();
  const Mat& q = es.eigenvectors();
  return {q * s.asDiagonal() * q.transpose(), q * s.cwiseInverse().asDiagonal() * q.transpose()};
}

double cross(const Vec& u, const Vec& w) { return u.x() * w.y() - u.y() * w.x(); }

// Is the direction q - v strictly inside the counter-clockwise sector from n - v to p - v?
bool in_sector(const Vec& v, const Vec& n, const Vec& p, const Vec& q) {
  const double s_np = orient2d(v, n, p);
  const bool left_of_n = orient2d(v, n, q) > 0;
  const bool right_of_p = orient2d(v, q, p) > 0;
  if (s_np > 0) return left_of_n && right_of_p;
  if (s_np < 0) return left_of_n || right_of_p;
  if ((n - v).dot(p - v) < 0) return left_of_n;  // a straight angle: the half-plane
  // n and p on one ray: the full turn but that ray.
  return !(orient2d(v, n, q) == 0 && (q - v).dot(n - v) > 0);
}

bool in_closed_triangle(const Vec& a, const Vec& b, const Vec& c, const Vec& q) {
  return orient2d(a, b, q) >= 0 && orient2d(b, c, q) >= 0 && orient2d(c, a, q) >= 0;
}

double point_segment_distance(const Vec& x, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((x - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - x).norm();
}

std::string point_text(const Vec& p) {
  std::ostringstream s;
  s.precision(9);
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

class Filler {
 public:
  Filler(const LinearFront<2>& front, const MetricField<2>& metric, const AdvancingFrontParams& params)
      : metric_(metric), params_(params), index_(domain_box(front)) {
    const Box b = domain_box(front);
    root_extent_ = std::max(b.x1 - b.x0, b.y1 - b.y0);
    result_.nodes = front.nodes;
    metrics_.resize(front.nodes.size());
    has_metric_.assign(front.nodes.size(), 0);
    head_.assign(front.nodes.size(), -1);
    build_front(front);
  }

  AdvancingFrontResult run() {
    while (!heap_.empty()) {
      const HeapEntry e = heap_.top();
      heap_.pop();
      if (!occ_[e.occ].alive || occ_[e.occ].version != e.version) continue;
      ++result_.stats.steps;
      step(e.occ, e.key);  // the key is o's outer angle, current since its version is
      if (result_.triangles.size() > params_.max_triangles)
        throw MesherError("advancing front: more than " + std::to_string(params_.max_triangles) +
                          " triangles (fill.max_triangles); the metric asks for too many");
    }
    return std::move(result_);
  }

 private:
  struct Occ {
    NodeId node;
    int prev, next;
    int same;  // the next occurrence of the same node, -1 at the end
    std::uint32_t version;
    bool alive;
  };
  struct HeapEntry {
    double key;
    int occ;
    std::uint32_t version;
    bool operator>(const HeapEntry& o) const { return key > o.key || (key == o.key && occ > o.occ); }
  };
  // A triangle's third corner: an existing front node (occ >= 0) or a new point.
  struct Apex {
    NodeId node = -1;
    int occ = -1;
    Vec point;
  };

  static Box domain_box(const LinearFront<2>& front) {
    Box b{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (const LinearLoop& front_loop : front.loops)
      for (NodeId v : front_loop.nodes) {
        if (v < 0 || static_cast<std::size_t>(v) >= front.nodes.size())
          throw MesherError("advancing front: node id " + std::to_string(v) + " out of range");
        const Vec& p = front.nodes[v];
        if (!p.allFinite()) throw MesherError("advancing front: front node " + std::to_string(v) + " is not finite");
        b = {std::min(b.x0, p.x()), std::min(b.y0, p.y()), std::max(b.x1, p.x()), std::max(b.y1, p.y())};
      }
    if (!(b.x1 >= b.x0)) throw MesherError("advancing front: no front loops");
    return b;
  }

  const Vec& pt(NodeId v) const { return result_.nodes[v]; }
  const Vec& opt(int o) const { return result_.nodes[occ_[o].node]; }
  NodeId nd(int o) const { return occ_[o].node; }

  const NodeMetric& nm(NodeId v) {
    if (!has_metric_[v]) {
      metrics_[v] = node_metric(metric_.evaluate(pt(v)));
      has_metric_[v] = 1;
    }
    return metrics_[v];
  }

  NodeId add_node(const Vec& p) {
    result_.nodes.push_back(p);
    metrics_.emplace_back();
    has_metric_.push_back(0);
    head_.push_back(-1);
    ++result_.stats.new_points;
    return static_cast<NodeId>(result_.nodes.size() - 1);
  }

  int add_occ(NodeId v, int prev, int next) {
    const int o = static_cast<int>(occ_.size());
    occ_.push_back({v, prev, next, head_[v], 0, true});
    head_[v] = o;
    return o;
  }

  void kill(int o) {
    occ_[o].alive = false;
    index_.remove(o);
    --front_edges_;
    int* link = &head_[occ_[o].node];
    while (*link != o) link = &occ_[*link].same;
    *link = occ_[o].same;
  }

  // Re-files the edge o -> next(o) in the index (its end moved).
  void reindex(int o) {
    index_.remove(o);
    index_.insert(o, segment_box(opt(o), opt(occ_[o].next)));
  }

  // The ellipse outer angle of eq. (1) at occurrence o: the counter-clockwise angle from its next
  // edge to its previous edge after mapping by M^(1/2) of the node's metric, in (0, 2 pi].
  double outer_angle(int o) {
    const Vec& v = opt(o);
    const Vec& n = opt(occ_[o].next);
    const Vec& p = opt(occ_[o].prev);
    const Mat& f = nm(nd(o)).f;
    const Vec u = f * (n - v), w = f * (p - v);
    double a = std::atan2(std::abs(cross(u, w)), u.dot(w));  // in [0, pi]
    const double s = orient2d(v, n, p);                       // the exact side decides the half
    if (s < 0 || (s == 0 && u.dot(w) > 0)) a = 2 * std::numbers::pi - a;
    return a;
  }

  void push(int o) {
    ++occ_[o].version;
    heap_.push({outer_angle(o), o, occ_[o].version});
  }

  void build_front(const LinearFront<2>& front) {
    std::vector<std::uint8_t> used(front.nodes.size(), 0);
    double area = 0;
    for (const LinearLoop& front_loop : front.loops) {
      const std::vector<NodeId>& loop = front_loop.nodes;
      if (loop.size() < 3) throw MesherError("advancing front: a front loop has fewer than 3 nodes");
      const int first = static_cast<int>(occ_.size());
      const int n = static_cast<int>(loop.size());
      for (int k = 0; k < n; ++k) {
        if (used[loop[k]]) throw MesherError("advancing front: front node " + point_text(pt(loop[k])) +
                                             " appears twice on the fronts");
        used[loop[k]] = 1;
        add_occ(loop[k], first + (k + n - 1) % n, first + (k + 1) % n);
        area += cross(pt(loop[k]), pt(loop[(k + 1) % n]));
      }
    }
    if (!(area > 0))
      throw MesherError("advancing front: the front loops enclose no region (the region must lie on the left of "
                        "every loop: bodies clockwise, the farfield counter-clockwise)");
    for (int o = 0; o < static_cast<int>(occ_.size()); ++o) reindex(o);
    front_edges_ = occ_.size();
    // The loops must neither cross nor touch: every edge against the edges near it.
    for (int o = 0; o < static_cast<int>(occ_.size()); ++o) {
      const int on = occ_[o].next;
      const Vec &a = opt(o), &b = opt(on);
      index_.query(segment_box(a, b), [&](int e) {
        if (e == o) return;
        const int en = occ_[e].next;
        const Vec &c = opt(e), &d = opt(en);
        bool bad;
        if (e == on)
          bad = point_on_open_segment(d, a, b) || point_on_open_segment(a, c, d);  // folds back
        else if (en == o)
          bad = point_on_open_segment(c, a, b) || point_on_open_segment(b, c, d);
        else
          bad = segments_intersect(a, b, c, d);
        if (bad)
          throw MesherError("advancing front: the front loops cross or touch near " + point_text(a) +
                            " (edges " + point_text(a) + "-" + point_text(b) + " and " + point_text(c) + "-" +
                            point_text(d) + ")");
      });
    }
    check_nesting(front);
    for (int o = 0; o < static_cast<int>(occ_.size()); ++o) push(o);
    result_.stats.max_front = front_edges_;
  }

  // Each loop must be oriented as its nesting requires: counter-clockwise (it bounds the region
  // from outside) when inside an even number of other loops, clockwise (a hole) when odd.
  void check_nesting(const LinearFront<2>& front) {
    if (front.loops.size() < 2) return;
    for (std::size_t i = 0; i < front.loops.size(); ++i) {
      const Vec& q = pt(front.loops[i].nodes[0]);
      int inside = 0;
      double area = 0;
      for (std::size_t j = 0; j < front.loops.size(); ++j) {
        const std::vector<NodeId>& l = front.loops[j].nodes;
        bool in = false;
        for (std::size_t k = 0; k < l.size(); ++k) {
          const Vec &a = pt(l[k]), &b = pt(l[(k + 1) % l.size()]);
          if (j == i) {
            area += cross(a, b);
            continue;
          }
          if ((a.y() > q.y()) != (b.y() > q.y())) {
            const bool upward = b.y() > a.y();
            if ((orient2d(a, b, q) > 0) == upward) in = !in;
          }
        }
        if (j != i && in) ++inside;
      }
      if ((area > 0) != (inside % 2 == 0))
        throw MesherError("advancing front: the front loop through " + point_text(q) + " is oriented the wrong way for " +
                          (inside % 2 == 0 ? "an outer boundary (it must run counter-clockwise)"
                                           : "a hole (it must run clockwise)"));
    }
  }

  // Is (a, b, c) a valid triangle on the front edge o: a -> b, with c the apex (an existing front
  // occurrence, or a new point)? Counter-clockwise, inside the free angle at a, b and c, crossing
  // and touching no front edge, with no front node inside or on it.
  bool valid(int o, const Apex& c, double min_quality, double max_length = 0) {
    const int ob = occ_[o].next;
    const Vec &a = opt(o), &b = opt(ob), &x = c.point;
    if (!(orient2d(a, b, x) > 0)) return false;
    if (min_quality > 0 && shape_quality(a, b, x, nm(nd(o)).f) < min_quality) return false;
    const int op = occ_[o].prev, obn = occ_[ob].next;
    const bool closes_a = c.occ >= 0 && c.node == nd(op);   // a -> c is the front edge c -> a
    const bool closes_b = c.occ >= 0 && c.node == nd(obn);  // c -> b is the front edge b -> c
    if (!closes_a && !in_sector(a, b, opt(op), x)) return false;
    if (!closes_b && !in_sector(b, opt(obn), a, x)) return false;
    if (c.occ >= 0 && !in_sector(x, opt(occ_[c.occ].next), opt(occ_[c.occ].prev), 0.5 * (a + b))) return false;
    const NodeId na = nd(o), nb = nd(ob);
    Box box = segment_box(a, b);
    box = {std::min(box.x0, x.x()), std::min(box.y0, x.y()), std::max(box.x1, x.x()), std::max(box.y1, x.y())};
    bool ok = true;
    index_.query(box, [&](int e) {
      if (!ok) return;
      const int en = occ_[e].next;
      const NodeId s = nd(e), t = nd(en);
      const Vec &ps = opt(e), &pt_ = opt(en);
      // Front nodes inside or on the triangle.
      for (const auto& [v, p] : {std::pair{s, &ps}, std::pair{t, &pt_}})
        if (v != na && v != nb && v != c.node && in_closed_triangle(a, b, x, *p)) ok = false;
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
      const double l_max = std::max(max_length, metric_length(metric_, a, b, 5));
      ok = (closes_a || metric_length(metric_, a, x, 5) <= l_max) && (closes_b || metric_length(metric_, x, b, 5) <= l_max);
    }
    return ok;
  }

  // 4 sqrt(3) A / (l1^2 + l2^2 + l3^2) in the metric space of f: 1 for an equilateral triangle.
  static double shape_quality(const Vec& a, const Vec& b, const Vec& c, const Mat& f) {
    const Vec u = f * (b - a), w = f * (c - a), v = w - u;
    const double l2 = u.squaredNorm() + w.squaredNorm() + v.squaredNorm();
    return l2 > 0 ? 2 * std::sqrt(3.0) * cross(u, w) / l2 : 0.0;
  }

  // Is the new point x at least `clearance` (metric of node v) from every front edge?
  bool clear(const Vec& x, const NodeMetric& m) {
    const double r = params_.clearance;
    const Mat m_inv = m.f_inv * m.f_inv;
    const double hx = r * std::sqrt(m_inv(0, 0)), hy = r * std::sqrt(m_inv(1, 1));
    bool ok = true;
    index_.query({x.x() - hx, x.y() - hy, x.x() + hx, x.y() + hy}, [&](int e) {
      if (ok && point_segment_distance(m.f * x, m.f * opt(e), m.f * opt(occ_[e].next)) < r) ok = false;
    });
    return ok;
  }

  // The occurrence of node v whose free angle contains the direction to q, or -1.
  int occurrence_towards(NodeId v, const Vec& q) {
    int found = -1;
    for (int o = head_[v]; o >= 0; o = occ_[o].same) {
      if (found < 0) found = o;
      if (in_sector(pt(v), opt(occ_[o].next), opt(occ_[o].prev), q)) return o;
    }
    return found;
  }

  // Front nodes near x (within `radius` in the metric m), nearest first, but a and b.
  std::vector<std::pair<double, NodeId>> nodes_near(const Vec& x, double radius, const NodeMetric& m, NodeId a,
                                                    NodeId b) {
    const Mat m_inv = m.f_inv * m.f_inv;
    const double hx = radius * std::sqrt(m_inv(0, 0)), hy = radius * std::sqrt(m_inv(1, 1));
    std::vector<std::pair<double, NodeId>> out;
    index_.query({x.x() - hx, x.y() - hy, x.x() + hx, x.y() + hy}, [&](int e) {
      for (NodeId v : {nd(e), nd(occ_[e].next)}) {
        if (v == a || v == b) continue;
        const double d = (m.f * (pt(v) - x)).norm();
        if (d < radius) out.emplace_back(d, v);
      }
    });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end(), [](auto& l, auto& r) { return l.second == r.second; }), out.end());
    return out;
  }

  // The apex for the edge o: a front node near the ideal point x if one makes a valid triangle
  // (merging fronts), else x itself if valid and clear of the front; false if neither.
  bool choose_apex(int o, const Vec& x, Apex& apex) {
    const NodeId a = nd(o), b = nd(occ_[o].next);
    // Distances around the new point in the metric there: where a coarse front meets a fine
    // region, the node's metric would see every nearby fine node as close.
    const NodeMetric m = node_metric(metric_.evaluate(x));
    for (const auto& [d, v] : nodes_near(x, params_.merge_radius, m, a, b)) {
      Apex c{v, occurrence_towards(v, 0.5 * (opt(o) + opt(occ_[o].next))), pt(v)};
      if (c.occ >= 0 && valid(o, c, params_.min_quality, params_.max_length)) {
        apex = c;
        ++result_.stats.merges;
        return true;
      }
    }
    const Apex c{-1, -1, x};
    // A new point is placed at unit metric length from the node: its edges are not length-checked
    // (a long front edge gets its triangle; it is a merge or a closing edge that could bridge a
    // fine region).
    if (clear(x, m) && valid(o, c, params_.min_quality)) {
      apex = c;
      return true;
    }
    return false;
  }

  // The constrained-Delaunay apex of the edge o in the metric of its start: among the front
  // nodes left of the edge, those whose circumcircle with the edge reaches least far to the left
  // first, the first that makes a valid triangle. The search box doubles until one is found.
  bool delaunay_apex(int o, Apex& apex) {
    const int ob = occ_[o].next;
    const NodeId na = nd(o), nb = nd(ob);
    const Vec &a = opt(o), &b = opt(ob);
    const Mat& f = nm(na).f;
    const Vec fa = f * a, fb = f * b, mid = 0.5 * (fa + fb);
    const Vec normal = Vec(-(fb - fa).y(), (fb - fa).x()).normalized();
    const double half_ab = 0.5 * (fb - fa).norm();
    double r = (b - a).norm();
    std::vector<std::pair<double, NodeId>> cand;
    for (int round = 0; round < 80; ++round, r *= 2) {
      cand.clear();
      const Vec c0 = 0.5 * (a + b);
      index_.query({c0.x() - r, c0.y() - r, c0.x() + r, c0.y() + r}, [&](int e) {
        for (NodeId v : {nd(e), nd(occ_[e].next)}) {
          if (v == na || v == nb || !(orient2d(a, b, pt(v)) > 0)) continue;
          // Centre of the circle through a, b, v (metric space) along the normal: k with
          // |w - (mid + k n)|^2 = half_ab^2 + k^2.
          const Vec w = f * pt(v) - mid;
          const double k = (w.squaredNorm() - half_ab * half_ab) / (2 * w.dot(normal));
          cand.emplace_back(k, v);
        }
      });
      std::sort(cand.begin(), cand.end());
      cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
      // The best-shaped valid apex first; then a new point on the edge's metric-equilateral
      // apex, lowered step by step; a sliver only when nothing else is valid.
      for (const auto& [q_min, l_max] : {std::pair{params_.min_quality, params_.max_length}, std::pair{1e-3, 0.0},
                                          std::pair{-1.0, 0.0}, std::pair{0.0, 0.0}}) {
        if (q_min < 0) {
          if (round > 0) continue;  // new points once, near the edge
          const Mat f_inv = nm(na).f_inv;
          for (double height : {0.866, 0.5, 0.25, 0.125, 0.0625}) {
            const Apex c{-1, -1, f_inv * (mid + height * 2 * half_ab * normal)};
            if (valid(o, c, 1e-3)) {
              apex = c;
              return true;
            }
          }
          continue;
        }
        for (const auto& [k, v] : cand) {
          const Apex c{v, occurrence_towards(v, 0.5 * (a + b)), pt(v)};
          if (c.occ >= 0 && valid(o, c, q_min, l_max)) {
            apex = c;
            return true;
          }
        }
      }
      if (r > 2 * root_extent_) break;
    }
    return false;
  }

  // Emits (a, b, c) on the front edge o: a -> b and updates the front.
  void advance(int o, const Apex& c) {
    const int ob = occ_[o].next;
    result_.triangles.push_back({nd(o), nd(ob), c.node >= 0 ? c.node : static_cast<NodeId>(result_.nodes.size())});
    touched_.clear();
    if (c.occ < 0) {
      const NodeId v = c.node >= 0 ? c.node : add_node(c.point);
      result_.triangles.back()[2] = v;
      const int oc = add_occ(v, o, ob);
      occ_[o].next = oc;
      occ_[ob].prev = oc;
      reindex(o);
      reindex(oc);
      ++front_edges_;
      touched_ = {o, oc, ob};
    } else {
      // The free angle of c splits in two: (next(c) .. a) stays with c's occurrence, and
      // (b .. prev(c)) goes to a new occurrence of c.
      const int oc = c.occ, opc = occ_[oc].prev;
      occ_[oc].prev = o;
      occ_[o].next = oc;
      const int oc2 = add_occ(c.node, opc, ob);
      occ_[opc].next = oc2;
      occ_[ob].prev = oc2;
      reindex(o);
      reindex(oc2);
      ++front_edges_;
      touched_ = {o, oc, oc2, ob, opc};
    }
    for (std::size_t k = 0; k < touched_.size(); ++k) remove_spikes(touched_[k]);
    for (int t : touched_)
      if (occ_[t].alive) push(t);
    result_.stats.max_front = std::max(result_.stats.max_front, front_edges_);
  }

  // Removes x -> y -> x spikes at occurrence x (zero-area parts of the front), repeatedly.
  void remove_spikes(int x) {
    while (occ_[x].alive) {
      const int p = occ_[x].prev, n = occ_[x].next;
      if (nd(p) != nd(n)) return;
      if (p == n) {  // a loop of two edges: gone
        kill(x);
        kill(p);
        return;
      }
      const int nn = occ_[n].next;
      kill(x);
      kill(n);
      if (nn == p) {  // p was all that was left of the loop
        kill(p);
        return;
      }
      occ_[p].next = nn;
      occ_[nn].prev = p;
      reindex(p);
      touched_.push_back(p);
      touched_.push_back(nn);
      x = p;
    }
  }

  // The new point at angle t (counter-clockwise from the next edge, in the metric space of the
  // node) at unit metric length: first in the node's metric, then corrected twice with the
  // metric integrated along the segment.
  Vec ideal_point(int o, const NodeMetric& m, double t) {
    const Vec p0 = opt(o);
    const Vec u = (m.f * (opt(occ_[o].next) - p0)).normalized();
    const Vec dir = m.f_inv * Vec(std::cos(t) * u.x() - std::sin(t) * u.y(), std::sin(t) * u.x() + std::cos(t) * u.y());
    double s = 1;
    for (int it = 0; it < 2; ++it) {
      const double l = metric_length(metric_, p0, Vec(p0 + s * dir), 3);
      if (!(l > 0)) break;
      s = std::clamp(s / l, 0.25 * s, 4 * s);
    }
    return p0 + s * dir;
  }

  // One greedy step at occurrence o (the front node of minimum outer angle `angle`).
  void step(int o, double angle) {
    const NodeId v = nd(o);
    const NodeMetric m = nm(v);
    const int n_new = std::clamp(static_cast<int>(std::floor(3 * angle / std::numbers::pi - 0.5)), 0, 5);
    bool progressed = false;
    if (n_new > 0) {
      // The new points: sub-angle directions in the metric space of v, at unit metric length.
      std::array<Vec, 5> ideal;
      for (int j = 1; j <= n_new; ++j) ideal[j - 1] = ideal_point(o, m, angle * j / (n_new + 1));
      for (int j = 0; j < n_new; ++j) {
        Apex c;
        if (!choose_apex(o, ideal[j], c)) break;
        advance(o, c);
        progressed = true;
        if (!occ_[o].alive) return;
      }
    }
    // Close the angle at v with the triangle (prev, v, next).
    const int op = occ_[o].prev;
    const Apex close{nd(op), op, opt(op)};
    if (valid(o, close, params_.min_quality, params_.max_length)) {
      advance(o, close);
      return;
    }
    if (progressed) {
      push(o);  // v's angle shrank; it comes back when it is the smallest
      return;
    }
    // Nothing done yet (the closing edge is too long in the metric, or a front node is in the
    // way): one new point on the bisector, as for n_new = 1.
    {
      Apex c;
      if (choose_apex(o, ideal_point(o, m, 0.5 * angle), c)) {
        advance(o, c);
        if (occ_[o].alive) push(o);
        return;
      }
    }
    Apex c;
    if (!delaunay_apex(o, c))
      throw MesherError("advancing front: no valid triangle on the front edge " + point_text(opt(o)) + " - " +
                        point_text(opt(occ_[o].next)) + " (is the front a valid polygon?)");
    ++result_.stats.delaunay_apexes;
    advance(o, c);
  }

  const MetricField<2>& metric_;
  AdvancingFrontParams params_;
  LooseQuadtree index_;
  double root_extent_ = 0;
  AdvancingFrontResult result_;
  std::vector<NodeMetric> metrics_;
  std::vector<std::uint8_t> has_metric_;
  std::vector<int> head_;  // first occurrence of each node, -1 if none
  std::vector<Occ> occ_;
  std::size_t front_edges_ = 0;
  std::vector<int> touched_;
  std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<HeapEntry>> heap_;
};

}  // namespace

AdvancingFrontResult advancing_front_fill(const LinearFront<2>& front, const MetricField<2>& metric,
                                          const AdvancingFrontParams& params) {
  Filler f(front, metric, params);
  return f.run();
}

}  // namespace plaf::volume
