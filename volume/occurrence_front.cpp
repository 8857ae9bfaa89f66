// SPDX-License-Identifier: MIT
// Implements the occurrence front of the 2D advancing front (occurrence_front.h): its
// construction and checks from the input loops, the per-node metrics, the searches near a point,
// and the one operation that changes it, advance.
#include "volume/occurrence_front.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/predicates.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;

// The bounding box of the front's loops; checks their node ids and coordinates.
Box domain_box(const LinearFront<2>& front) {
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

}  // namespace

NodeMetric node_metric(const Metric<2>& m) {
  Eigen::SelfAdjointEigenSolver<Mat> es;
  es.computeDirect(m.matrix());
  const Eigen::Vector2d s = es.eigenvalues().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt();
  const Mat& q = es.eigenvectors();
  return {q * s.asDiagonal() * q.transpose(), q * s.cwiseInverse().asDiagonal() * q.transpose()};
}

double cross(const Vec& u, const Vec& w) {
  return u.x() * w.y() - u.y() * w.x();
}

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

OccurrenceFront::OccurrenceFront(const LinearFront<2>& front, const MetricField<2>& metric)
    : metric_(metric), index_(domain_box(front)) {
  const Box b = domain_box(front);
  root_extent_ = std::max(b.x1 - b.x0, b.y1 - b.y0);
  nodes_ = front.nodes;
  metrics_.resize(front.nodes.size());
  has_metric_.assign(front.nodes.size(), 0);
  head_.assign(front.nodes.size(), -1);
  build(front);
}

const NodeMetric& OccurrenceFront::nm(NodeId v) const {
  if (!has_metric_[v]) {
    metrics_[v] = node_metric(metric_.evaluate(pt(v)));
    has_metric_[v] = 1;
  }
  return metrics_[v];
}

NodeId OccurrenceFront::add_node(const Vec& p) {
  nodes_.push_back(p);
  metrics_.emplace_back();
  has_metric_.push_back(0);
  head_.push_back(-1);
  ++new_points_;
  return static_cast<NodeId>(nodes_.size() - 1);
}

int OccurrenceFront::add_occ(NodeId v, int prev, int next) {
  const int o = static_cast<int>(occ_.size());
  occ_.push_back({v, prev, next, head_[v], true});
  head_[v] = o;
  return o;
}

void OccurrenceFront::kill(int o) {
  occ_[o].alive = false;
  index_.remove(o);
  --front_edges_;
  int* link = &head_[occ_[o].node];
  while (*link != o) link = &occ_[*link].same;
  *link = occ_[o].same;
}

// Re-files the edge o -> next(o) in the index (its end moved).
void OccurrenceFront::reindex(int o) {
  index_.remove(o);
  index_.insert(o, segment_box(opt(o), opt(occ_[o].next)));
}

// The occurrences of every loop, then the checks: the loops enclose a region, do not cross or
// touch, and are oriented as they nest.
void OccurrenceFront::build(const LinearFront<2>& front) {
  std::vector<std::uint8_t> used(front.nodes.size(), 0);
  double area = 0;
  for (const LinearLoop& front_loop : front.loops) {
    const std::vector<NodeId>& loop = front_loop.nodes;
    if (loop.size() < 3) throw MesherError("advancing front: a front loop has fewer than 3 nodes");
    const int first = static_cast<int>(occ_.size());
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) {
      if (used[loop[k]])
        throw MesherError("advancing front: front node " + point_text(pt(loop[k])) + " appears twice on the fronts");
      used[loop[k]] = 1;
      add_occ(loop[k], first + (k + n - 1) % n, first + (k + 1) % n);
      area += cross(pt(loop[k]), pt(loop[(k + 1) % n]));
    }
  }
  if (!(area > 0))
    throw MesherError(
        "advancing front: the front loops enclose no region (the region must lie on the left of "
        "every loop: bodies clockwise, the farfield counter-clockwise)");
  for (int o = 0; o < static_cast<int>(occ_.size()); ++o) reindex(o);
  front_edges_ = occ_.size();
  check_crossings();
  check_nesting(front);
  max_front_ = front_edges_;
}

// The loops must neither cross nor touch: every edge against the edges near it.
void OccurrenceFront::check_crossings() const {
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
        throw MesherError("advancing front: the front loops cross or touch near " + point_text(a) + " (edges " +
                          point_text(a) + "-" + point_text(b) + " and " + point_text(c) + "-" + point_text(d) + ")");
    });
  }
}

// Each loop must be oriented as its nesting requires: counter-clockwise (it bounds the region
// from outside) when inside an even number of other loops, clockwise (a hole) when odd.
void OccurrenceFront::check_nesting(const LinearFront<2>& front) const {
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
      throw MesherError(
          "advancing front: the front loop through " + point_text(q) + " is oriented the wrong way for " +
          (inside % 2 == 0 ? "an outer boundary (it must run counter-clockwise)" : "a hole (it must run clockwise)"));
  }
}

int OccurrenceFront::occurrence_towards(NodeId v, const Vec& q) const {
  int found = -1;
  for (int o = head_[v]; o >= 0; o = occ_[o].same) {
    if (found < 0) found = o;
    if (in_sector(pt(v), opt(occ_[o].next), opt(occ_[o].prev), q)) return o;
  }
  return found;
}

std::vector<std::pair<double, NodeId>> OccurrenceFront::nodes_near(const Vec& x, double radius, const NodeMetric& m,
                                                                   NodeId a, NodeId b) const {
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

const std::vector<int>& OccurrenceFront::advance(int o, const Apex& c) {
  const int ob = occ_[o].next;
  triangles_.push_back({nd(o), nd(ob), c.node >= 0 ? c.node : static_cast<NodeId>(nodes_.size())});
  touched_.clear();
  if (c.occ < 0) {
    const NodeId v = c.node >= 0 ? c.node : add_node(c.point);
    triangles_.back()[2] = v;
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
  max_front_ = std::max(max_front_, front_edges_);
  return touched_;
}

// Removes x -> y -> x spikes at occurrence x (zero-area parts of the front), repeatedly.
void OccurrenceFront::remove_spikes(int x) {
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

AdvancingFrontResult OccurrenceFront::take_result() {
  AdvancingFrontResult r;
  r.nodes = std::move(nodes_);
  r.simplices = std::move(triangles_);
  r.stats.new_points = new_points_;
  r.stats.max_front = max_front_;
  return r;
}

}  // namespace plaf::volume
