// SPDX-License-Identifier: MIT
// The metric-based advancing front (advancing_front_2d.h): the greedy loop, steps 1 to 5 and 7,
// over the occurrence front (occurrence_front.h); the triangle tests of step 6 are valid_apex.h,
// the fallback where the greedy step finds nothing is delaunay_apex.h.
#include "volume/advancing_front_2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/predicates.h"
#include "volume/delaunay_apex.h"
#include "volume/occurrence_front.h"
#include "volume/valid_apex.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;

class Filler {
 public:
  Filler(const LinearFront<2>& front, const MetricField<2>& metric, const AdvancingFrontParams& params)
      : params_(params), front_(front, metric) {
    for (int o = 0; o < front_.num_occurrences(); ++o) push(o);
  }

  AdvancingFrontResult run() {
    while (!heap_.empty()) {
      const HeapEntry e = heap_.top();
      heap_.pop();
      if (!front_.alive(e.occ) || version_[e.occ] != e.version) continue;
      ++stats_.steps;
      step(e.occ, e.key);  // the key is o's outer angle, current since its version is
      if (front_.num_triangles() > params_.max_triangles)
        throw MesherError("advancing front: more than " + std::to_string(params_.max_triangles) +
                          " triangles (fill.max_triangles); the metric asks for too many");
    }
    AdvancingFrontResult result = front_.take_result();
    result.stats.steps = stats_.steps;
    result.stats.merges = stats_.merges;
    result.stats.delaunay_apexes = stats_.delaunay_apexes;
    return result;
  }

 private:
  // The heap of occurrences by outer angle, with lazy deletion: an entry is current while its
  // version is the occurrence's.
  struct HeapEntry {
    double key;
    int occ;
    std::uint32_t version;
    bool operator>(const HeapEntry& o) const { return key > o.key || (key == o.key && occ > o.occ); }
  };

  // The ellipse outer angle of eq. (1) at occurrence o: the counter-clockwise angle from its next
  // edge to its previous edge after mapping by M^(1/2) of the node's metric, in (0, 2 pi].
  double outer_angle(int o) const {
    const Vec& v = front_.opt(o);
    const Vec& n = front_.opt(front_.next(o));
    const Vec& p = front_.opt(front_.prev(o));
    const Mat& f = front_.nm(front_.nd(o)).f;
    const Vec u = f * (n - v), w = f * (p - v);
    double a = std::atan2(std::abs(cross(u, w)), u.dot(w));  // in [0, pi]
    const double s = orient2d(v, n, p);                      // the exact side decides the half
    if (s < 0 || (s == 0 && u.dot(w) > 0)) a = 2 * std::numbers::pi - a;
    return a;
  }

  void push(int o) {
    if (static_cast<std::size_t>(o) >= version_.size()) version_.resize(static_cast<std::size_t>(o) + 1, 0);
    ++version_[o];
    heap_.push({outer_angle(o), o, version_[o]});
  }

  // Emits the triangle on the edge o with apex c; the occurrences whose angle changed get new keys.
  void advance(int o, const Apex& c) {
    for (int t : front_.advance(o, c))
      if (front_.alive(t)) push(t);
  }

  // The apex for the edge o: a front node near the ideal point x if one makes a valid triangle
  // (merging fronts), else x itself if valid and clear of the front; nullopt if neither.
  std::optional<Apex> choose_apex(int o, const Vec& x) {
    const NodeId a = front_.nd(o), b = front_.nd(front_.next(o));
    // Distances around the new point in the metric there: where a coarse front meets a fine
    // region, the node's metric would see every nearby fine node as close.
    const NodeMetric m = node_metric(front_.metric().evaluate(x));
    for (const auto& [d, v] : front_.nodes_near(x, params_.merge_radius, m, a, b)) {
      const Apex c{v, front_.occurrence_towards(v, 0.5 * (front_.opt(o) + front_.opt(front_.next(o)))), front_.pt(v)};
      if (c.occ >= 0 && valid_apex(front_, o, c, params_.min_quality, params_.max_length)) {
        ++stats_.merges;
        return c;
      }
    }
    const Apex c{-1, -1, x};
    // A new point is placed at unit metric length from the node: its edges are not length-checked
    // (a long front edge gets its triangle; it is a merge or a closing edge that could bridge a
    // fine region).
    if (clear_of_front(front_, x, m, params_.clearance) && valid_apex(front_, o, c, params_.min_quality)) return c;
    return std::nullopt;
  }

  // The new point at angle t (counter-clockwise from the next edge, in the metric space of the
  // node) at unit metric length: first in the node's metric, then corrected twice with the
  // metric integrated along the segment.
  Vec ideal_point(int o, const NodeMetric& m, double t) const {
    const Vec p0 = front_.opt(o);
    const Vec u = (m.f * (front_.opt(front_.next(o)) - p0)).normalized();
    const Vec dir = m.f_inv * Vec(std::cos(t) * u.x() - std::sin(t) * u.y(), std::sin(t) * u.x() + std::cos(t) * u.y());
    double s = 1;
    for (int it = 0; it < 2; ++it) {
      const double l = metric_length(front_.metric(), p0, Vec(p0 + s * dir), 3);
      if (!(l > 0)) break;
      s = std::clamp(s / l, 0.25 * s, 4 * s);
    }
    return p0 + s * dir;
  }

  // One greedy step at occurrence o (the front node of minimum outer angle `angle`).
  void step(int o, double angle) {
    const NodeId v = front_.nd(o);
    const NodeMetric m = front_.nm(v);
    const int n_new = std::clamp(static_cast<int>(std::floor(3 * angle / std::numbers::pi - 0.5)), 0, 5);
    bool progressed = false;
    if (n_new > 0) {
      // The new points: sub-angle directions in the metric space of v, at unit metric length.
      std::array<Vec, 5> ideal;
      for (int j = 1; j <= n_new; ++j) ideal[j - 1] = ideal_point(o, m, angle * j / (n_new + 1));
      for (int j = 0; j < n_new; ++j) {
        const std::optional<Apex> c = choose_apex(o, ideal[j]);
        if (!c) break;
        advance(o, *c);
        progressed = true;
        if (!front_.alive(o)) return;
      }
    }
    // Close the angle at v with the triangle (prev, v, next).
    const int op = front_.prev(o);
    const Apex close{front_.nd(op), op, front_.opt(op)};
    if (valid_apex(front_, o, close, params_.min_quality, params_.max_length)) {
      advance(o, close);
      return;
    }
    if (progressed) {
      push(o);  // v's angle shrank; it comes back when it is the smallest
      return;
    }
    // Nothing done yet (the closing edge is too long in the metric, or a front node is in the
    // way): one new point on the bisector, as for n_new = 1.
    if (const std::optional<Apex> c = choose_apex(o, ideal_point(o, m, 0.5 * angle))) {
      advance(o, *c);
      if (front_.alive(o)) push(o);
      return;
    }
    const std::optional<Apex> c = delaunay_apex(front_, o, params_);
    if (!c)
      throw MesherError("advancing front: no valid triangle on the front edge " + point_text(front_.opt(o)) + " - " +
                        point_text(front_.opt(front_.next(o))) + " (is the front a valid polygon?)");
    ++stats_.delaunay_apexes;
    advance(o, *c);
  }

  AdvancingFrontParams params_;
  OccurrenceFront front_;
  std::vector<std::uint32_t> version_;  // per occurrence: the version of its current heap entry
  std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<HeapEntry>> heap_;
  AdvancingFrontStats stats_;  // steps, merges and delaunay_apexes; the front counts the rest
};

}  // namespace

AdvancingFrontResult advancing_front_fill(const LinearFront<2>& front, const MetricField<2>& metric,
                                          const AdvancingFrontParams& params) {
  Filler f(front, metric, params);
  return f.run();
}

}  // namespace plaf::volume
