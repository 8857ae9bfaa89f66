// SPDX-License-Identifier: MIT
// Implements the metric post-optimisation of a 2D fill (optimize_2d.h).
#include "volume/optimize_2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector2d;
using Mat = Eigen::Matrix2d;
using Tri = std::array<NodeId, 3>;

// A triangle of at least this metric shape quality is fair: smoothing may trade some of its shape
// for unit edges, and swaps of fair pairs must also bring the diagonal nearer unit length.
constexpr double kFair = 0.5;
// Splits run in all passes but the last kPlacePasses (which place the new nodes).
constexpr int kPlacePasses = 2;
// A split (or a collapse) may make the worst triangle of its pair (ball) worse only down to this
// quality.
constexpr double kSplitFloor = 0.3;
constexpr double kLongSplitShare = 0.5;
// No split of an edge longer than this by its ends' metrics alone: such an edge marks a region the
// fronts left unresolved (the 30P-30N's gaps at h0 1e-6 c: edges of 120 units between fronts that
// met), where halving cascades over the passes multiplied non-unit edges (there the unit fraction
// fell from 0.81 to 0.79 with 10k splits; 0.89 with this bound), while an edge long only through
// its midpoint (a thin feature) or up to 16 units is resolved in the passes there are (bench_fill
// A: its longest edge 9.3 -> 1.7 units).
constexpr double kMaxSplitEnds = 16;
// Smoothing leaves a node whose target is nearer than this (metric units).
constexpr double kSettled = 0.02;
// edge_length_sampled reuses a midpoint's metric while the midpoint moved less than this (metric units).
constexpr double kMidpointReuse = 0.05;

class Optimizer {
 public:
  Optimizer(FillResult<2>& fill, std::size_t fixed, const MetricField<2>& metric)
      : x_(fill.nodes), t_(fill.simplices), fixed_(fixed), metric_(metric), m_(x_.size()) {
    for (std::size_t v = 0; v < x_.size(); ++v) m_[v] = metric_.evaluate(x_[v]).matrix();
  }

  // Metric shape quality of a triangle (1 equilateral, 0 flat, negative when clockwise).
  double quality(NodeId a, NodeId b, NodeId c) const { return quality_at(a, b, c, x_[a], x_[b], x_[c]); }
  double quality_at(NodeId a, NodeId b, NodeId c, const Vec& pa, const Vec& pb, const Vec& pc) const {
    return quality_in((m_[a] + m_[b] + m_[c]) / 3, pa, pb, pc);
  }
  static double quality_in(const Mat& m, const Vec& pa, const Vec& pb, const Vec& pc) {
    const Vec u = pb - pa, w = pc - pa, v = w - u;
    const double l2 = u.dot(m * u) + w.dot(m * w) + v.dot(m * v);
    const double area = 0.5 * (u.x() * w.y() - u.y() * w.x()) * std::sqrt(std::max(m.determinant(), 0.0));
    return l2 > 0 ? 4 * std::sqrt(3.0) * area / l2 : 0.0;
  }
  double edge_length(NodeId a, NodeId b) const {
    const Vec e = x_[b] - x_[a];
    return std::sqrt(e.dot(0.5 * (m_[a] + m_[b]) * e));
  }
  // The length with the metric also sampled at the midpoint (Simpson's rule on the length
  // density): an edge that jumps a feature thinner than itself (a shock band between two nodes
  // outside it) is long although its ends' metrics say it is not. One metric evaluation.
  double edge_length_sampled(NodeId a, NodeId b) const {
    return simpson(a, b, metric_.evaluate(0.5 * (x_[a] + x_[b])).matrix());
  }
  double simpson(NodeId a, NodeId b, const Mat& mid) const {
    const Vec e = x_[b] - x_[a];
    return (std::sqrt(e.dot(m_[a] * e)) + 4 * std::sqrt(e.dot(mid * e)) + std::sqrt(e.dot(m_[b] * e))) / 6;
  }
  // The same for side k of triangle i (side 3 i + k, from vertex k to k + 1), its midpoint metric
  // cached per side and reused while the triangle is unchanged and the midpoint stays within
  // kMidpointReuse metric units of where it was sampled (smoothing's later moves are small; a wall
  // distance metric costs a closest-point search per evaluation, a background one a point location).
  double side_length(std::size_t side) {
    const Tri& t = t_[side / 3];
    const NodeId a = t[side % 3], b = t[(side + 1) % 3];
    const Vec c = 0.5 * (x_[a] + x_[b]);
    if (side_mid_.size() < 3 * t_.size()) side_mid_.resize(3 * t_.size());
    MidSample& ms = side_mid_[side];
    if (!ms.valid || (c - ms.at).dot(ms.m * (c - ms.at)) > kMidpointReuse * kMidpointReuse)
      ms = {c, metric_.evaluate(c).matrix(), true};
    return simpson(a, b, ms.m);
  }
  // Triangle i changed: its sides' samples are stale.
  void changed(std::size_t i) {
    if (side_mid_.size() < 3 * t_.size()) side_mid_.resize(3 * t_.size());
    for (std::size_t k = 0; k < 3; ++k) side_mid_[3 * i + k].valid = false;
  }

  // Sum over the node's edges of (ln L)^2 (0 when every edge has unit metric length), and how
  // many of them are unit (L in [1/sqrt2, sqrt2]).
  std::pair<double, int> length_energy(NodeId v, const std::vector<NodeId>& nbr) const {
    double e = 0;
    int unit = 0;
    for (NodeId u : nbr) {
      const double len = edge_length(u, v), l = std::log(std::max(len, 1e-300));
      e += l * l;
      unit += is_unit(len) ? 1 : 0;
    }
    return {e, unit};
  }
  static bool is_unit(double l) { return l >= M_SQRT1_2 && l <= M_SQRT2; }

  // Splits and collapses never make a triangle worse than q (the fill's least quality at the
  // start, so the optimisation does not lower it; swaps and moves never lower a ball's least).
  void set_floor(double q) { floor_ = q; }

  std::size_t triangles() const { return t_.size(); }

  double min_quality() const {
    double q = 1;
    for (const Tri& t : t_) q = std::min(q, quality(t[0], t[1], t[2]));
    return t_.empty() ? 0 : q;
  }
  double unit_fraction() {
    std::size_t unit = 0, total = 0;
    for (std::size_t side : distinct_sides()) {
      const double l = side_length(side);
      ++total;
      if (l >= M_SQRT1_2 && l <= M_SQRT2) ++unit;
    }
    return total ? static_cast<double>(unit) / static_cast<double>(total) : 0;
  }

  // One sweep of swaps over the interior edges; each triangle changes at most once per sweep.
  std::size_t swaps() {
    const std::vector<std::array<int, 2>> interior = interior_edges();
    std::vector<std::uint8_t> touched(t_.size(), 0);
    std::size_t done = 0;
    for (const auto& [e1, e2] : interior) {
      const std::size_t i = static_cast<std::size_t>(e1 / 3), j = static_cast<std::size_t>(e2 / 3);
      if (touched[i] || touched[j]) continue;
      const int k = e1 % 3, l = e2 % 3;
      // Triangle i = (p, q, r) with the edge p -> q; triangle j has it as q -> p, apex s.
      const NodeId p = t_[i][static_cast<std::size_t>(k)], q = t_[i][static_cast<std::size_t>((k + 1) % 3)],
                   r = t_[i][static_cast<std::size_t>((k + 2) % 3)], s = t_[j][static_cast<std::size_t>((l + 2) % 3)];
      if (r == s) continue;
      // The new edge r - s: triangles (r, p, s) and (s, q, r), both strictly counter-clockwise.
      if (!(orient2d(x_[r], x_[p], x_[s]) > 0) || !(orient2d(x_[s], x_[q], x_[r]) > 0)) continue;
      const double before = std::min(quality(p, q, r), quality(q, p, s));
      const double after = std::min(quality(r, p, s), quality(s, q, r));
      if (!(after > before * (1 + 1e-9) + 1e-12)) continue;
      // A fair pair (both triangles above kFair) is swapped only toward the diagonal nearer unit
      // length, so the swaps that only polish shape do not trade unit edges away.
      if (before >= kFair && (std::abs(std::log(edge_length(r, s))) > std::abs(std::log(edge_length(p, q))) ||
                              (is_unit(edge_length(p, q)) && !is_unit(edge_length(r, s)))))
        continue;
      t_[i] = {r, p, s};
      t_[j] = {s, q, r};
      changed(i);
      changed(j);
      touched[i] = touched[j] = 1;
      ++done;
    }
    return done;
  }

  // One sweep of splits: an interior edge longer than sqrt 2 (edge_length_sampled) gets its
  // midpoint, a new free node, and its two triangles become four (each with half the old one's
  // area and its orientation, so all stay counter-clockwise; checked exactly all the same). The
  // halves of a 1.4-2 edge are unit, a longer edge is split again in a later sweep; smoothing
  // then places the midpoints. Each triangle splits at most once per sweep.
  std::size_t splits() {
    const std::vector<std::array<int, 2>> interior = interior_edges();
    std::vector<std::uint8_t> touched(t_.size(), 0);
    std::size_t done = 0;
    for (const auto& [e1, e2] : interior) {
      const std::size_t i = static_cast<std::size_t>(e1 / 3), j = static_cast<std::size_t>(e2 / 3);
      if (touched[i] || touched[j]) continue;
      const int k = e1 % 3, l = e2 % 3;
      const NodeId p = t_[i][static_cast<std::size_t>(k)], q = t_[i][static_cast<std::size_t>((k + 1) % 3)],
                   r = t_[i][static_cast<std::size_t>((k + 2) % 3)], s = t_[j][static_cast<std::size_t>((l + 2) % 3)];
      const double len = side_length(static_cast<std::size_t>(e1));
      if (!(len > M_SQRT2)) continue;
      if (edge_length(p, q) > kMaxSplitEnds) continue;
      const Vec mid = 0.5 * (x_[p] + x_[q]);
      if (!(orient2d(x_[p], mid, x_[r]) > 0) || !(orient2d(mid, x_[q], x_[r]) > 0) ||
          !(orient2d(x_[q], mid, x_[s]) > 0) || !(orient2d(mid, x_[p], x_[s]) > 0))
        continue;
      const NodeId m = static_cast<NodeId>(x_.size());
      x_.push_back(mid);
      m_.push_back(metric_.evaluate(mid).matrix());
      // Not at the cost of the worst shape: the four new triangles stay above the pair's least
      // quality or kSplitFloor. The old pair is measured with the midpoint's metric in its mean
      // too, as the new triangles are: an edge across a feature thinner than its triangles (bench_fill
      // A's shock band: 9 units between two nodes whose metrics say 1) has triangles that only
      // their vertices' metrics call fair.
      const auto q4 = [&](NodeId a, NodeId b, NodeId c) {
        return quality_in((m_[a] + m_[b] + m_[c] + m_[m]) / 4, x_[a], x_[b], x_[c]);
      };
      const double q_old = std::min(q4(p, q, r), q4(q, p, s));
      const double q_new = std::min({quality(p, m, r), quality(m, q, r), quality(q, m, s), quality(m, p, s)});
      const double floor = len > 2 * M_SQRT2 ? std::min(kLongSplitShare * q_old, kSplitFloor) : std::min(q_old, kSplitFloor);
      if (q_new < std::max(floor, floor_)) {
        x_.pop_back();
        m_.pop_back();
        continue;
      }
      t_[i] = {p, m, r};
      t_[j] = {q, m, s};
      t_.push_back({m, q, r});
      t_.push_back({m, p, s});
      changed(i);
      changed(j);
      changed(t_.size() - 2);
      changed(t_.size() - 1);
      touched[i] = touched[j] = 1;
      touched.push_back(1);
      touched.push_back(1);
      ++done;
    }
    return done;
  }

  // One sweep of collapses: an edge shorter than 1/sqrt 2 (edge_length_sampled) with a free end v
  // loses v, which merges into the other end u; the two triangles on the edge vanish and v's other
  // triangles take u instead. Only when
  //  - u and v share exactly the edge's two apexes as neighbours (the link condition: the mesh
  //    stays a triangulation of the same region, no edge doubled) and v is not on a front;
  //  - every changed triangle stays strictly counter-clockwise (exact orient2d);
  //  - no new edge of u is longer than sqrt 2 and the changed triangles' least quality stays at
  //    least min(the ball's old least quality, kSplitFloor).
  // Each node takes part in at most one collapse per sweep; the dead triangles are dropped at the
  // end of the sweep and the dead nodes at the end of the optimisation (compact()).
  std::size_t collapses() {
    std::vector<std::vector<int>> ball(x_.size());
    for (std::size_t i = 0; i < t_.size(); ++i)
      for (NodeId v : t_[i]) ball[static_cast<std::size_t>(v)].push_back(static_cast<int>(i));
    std::vector<std::uint8_t> touched(x_.size(), 0), dead(t_.size(), 0);
    std::size_t done = 0;
    std::vector<NodeId> nu, nv;
    const auto neighbours = [&](NodeId v, std::vector<NodeId>& out) {
      out.clear();
      for (int i : ball[static_cast<std::size_t>(v)])
        for (NodeId w : t_[static_cast<std::size_t>(i)])
          if (w != v) out.push_back(w);
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    };
    for (const auto& [e1, e2] : interior_edges()) {
      const std::size_t i = static_cast<std::size_t>(e1 / 3), j = static_cast<std::size_t>(e2 / 3);
      if (dead[i] || dead[j]) continue;
      const int k = e1 % 3;
      const NodeId p = t_[i][static_cast<std::size_t>(k)], q = t_[i][static_cast<std::size_t>((k + 1) % 3)];
      if (touched[p] || touched[q]) continue;
      // (An edge unit or longer by its ends' metrics is not sampled: a midpoint coarser than
      // both ends is rare, and a collapse it misses only leaves a short edge.)
      if (!(edge_length(p, q) < 1) || !(side_length(static_cast<std::size_t>(e1)) < M_SQRT1_2)) continue;
      // Try removing q (into p), then p (into q); only free nodes go.
      for (const auto& [u, v] : {std::pair{p, q}, std::pair{q, p}}) {
        if (static_cast<std::size_t>(v) < fixed_) continue;
        neighbours(u, nu);
        neighbours(v, nv);
        std::vector<NodeId> common;
        std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
        if (common.size() != 2) continue;
        bool ok = true;
        double q_old = 1, q_new = 1;
        for (int b : ball[static_cast<std::size_t>(v)]) {
          const Tri& t = t_[static_cast<std::size_t>(b)];
          q_old = std::min(q_old, quality(t[0], t[1], t[2]));
          if (static_cast<std::size_t>(b) == i || static_cast<std::size_t>(b) == j) continue;
          Tri n = t;
          for (NodeId& w : n)
            if (w == v) w = u;
          if (!(orient2d(x_[n[0]], x_[n[1]], x_[n[2]]) > 0)) {
            ok = false;
            break;
          }
          q_new = std::min(q_new, quality(n[0], n[1], n[2]));
        }
        if (!ok || q_new < std::max(std::min(q_old, kSplitFloor), floor_)) continue;
        for (NodeId w : nv)
          if (w != u && !std::binary_search(common.begin(), common.end(), w) && edge_length_sampled(u, w) > M_SQRT2) {
            ok = false;
            break;
          }
        if (!ok) continue;
        dead[i] = dead[j] = 1;
        for (int b : ball[static_cast<std::size_t>(v)]) {
          if (dead[static_cast<std::size_t>(b)]) continue;
          for (NodeId& w : t_[static_cast<std::size_t>(b)])
            if (w == v) w = u;
          changed(static_cast<std::size_t>(b));
        }
        // Every vertex of v's old ball is touched now, so no ball read later in this sweep holds
        // a dead or changed triangle: the balls need no update.
        touched[u] = touched[v] = 1;
        for (NodeId w : nv) touched[w] = 1;
        ++done;
        break;
      }
    }
    if (done) {
      std::size_t n = 0;
      for (std::size_t b = 0; b < t_.size(); ++b)
        if (!dead[b]) {
          for (std::size_t k = 0; k < 3; ++k) side_mid_[3 * n + k] = side_mid_[3 * b + k];
          t_[n++] = t_[b];
        }
      t_.resize(n);
      side_mid_.resize(3 * n);
    }
    return done;
  }

  // Drops the nodes no triangle uses any more (collapsed ones; never a front node, which are all
  // below fixed_) and renumbers the triangles.
  void compact() {
    std::vector<NodeId> renum(x_.size(), -1);
    for (std::size_t v = 0; v < fixed_; ++v) renum[v] = static_cast<NodeId>(v);
    std::vector<std::uint8_t> used(x_.size(), 0);
    for (const Tri& t : t_)
      for (NodeId v : t) used[static_cast<std::size_t>(v)] = 1;
    std::size_t n = fixed_;
    for (std::size_t v = fixed_; v < x_.size(); ++v)
      if (used[v]) {
        renum[v] = static_cast<NodeId>(n);
        x_[n] = x_[v];
        m_[n] = m_[v];
        ++n;
      }
    x_.resize(n);
    m_.resize(n);
    for (Tri& t : t_)
      for (NodeId& v : t) v = renum[static_cast<std::size_t>(v)];
  }

  // One smoothing sweep over the free nodes.
  std::size_t smooth() {
    std::vector<std::vector<int>> ball(x_.size());
    for (std::size_t i = 0; i < t_.size(); ++i)
      for (NodeId v : t_[i])
        if (static_cast<std::size_t>(v) >= fixed_) ball[static_cast<std::size_t>(v)].push_back(static_cast<int>(i));
    std::size_t moved = 0;
    std::vector<NodeId> nbr;
    for (std::size_t v = fixed_; v < x_.size(); ++v) {
      const std::vector<int>& b = ball[v];
      if (b.empty()) continue;
      nbr.clear();
      for (int i : b)
        for (NodeId u : t_[static_cast<std::size_t>(i)])
          if (static_cast<std::size_t>(u) != v) nbr.push_back(u);
      std::sort(nbr.begin(), nbr.end());
      nbr.erase(std::unique(nbr.begin(), nbr.end()), nbr.end());
      const NodeId id = static_cast<NodeId>(v);
      const Vec x0 = x_[v];
      Vec target = Vec::Zero();
      for (NodeId u : nbr) {
        const double l = edge_length(u, id);
        target += l > 0 ? Vec(x_[u] + (x0 - x_[u]) / l) : x0;
      }
      target /= static_cast<double>(nbr.size());
      // Converged: a node whose target is within kSettled metric units stays (most nodes after
      // the first passes; each trial costs a metric evaluation and the ball's checks).
      if ((target - x0).dot(m_[v] * (target - x0)) < kSettled * kSettled) continue;
      double q_old = 1;
      for (int i : b) q_old = std::min(q_old, quality(t_[i][0], t_[i][1], t_[i][2]));
      const auto [e_old, unit_old] = length_energy(id, nbr);
      const Mat m_old = m_[v];
      for (double w : {0.5, 0.25}) {
        const Vec y = x0 + w * (target - x0);
        x_[v] = y;
        m_[v] = metric_.evaluate(y).matrix();
        bool ok = true;
        double q_new = 1;
        for (int i : b) {
          const Tri& t = t_[static_cast<std::size_t>(i)];
          if (!(orient2d(x_[t[0]], x_[t[1]], x_[t[2]]) > 0)) {
            ok = false;
            break;
          }
          q_new = std::min(q_new, quality(t[0], t[1], t[2]));
        }
        // Kept when no edge of the node leaves the unit range on balance and either the edges
        // get nearer unit length without the ball's worst triangle losing more than a tenth (nor
        // going below kFair; a worse one may not drop at all), or that triangle improves without
        // the lengths worsening much.
        const auto [e_new, unit_new] = ok ? length_energy(id, nbr) : std::pair<double, int>{0, 0};
        const double q_floor = q_old < kFair ? q_old : std::max(kFair, 0.9 * q_old);
        if (ok && unit_new >= unit_old &&
            ((e_new < e_old && q_new >= q_floor) || (q_new > q_old && e_new <= 1.1 * e_old))) {
          ++moved;
          break;
        }
        x_[v] = x0;
        m_[v] = m_old;
      }
    }
    return moved;
  }

 private:
  static std::uint64_t key(NodeId a, NodeId b) {
    const std::uint64_t lo = static_cast<std::uint32_t>(std::min(a, b)), hi = static_cast<std::uint32_t>(std::max(a, b));
    return lo << 32 | hi;
  }
  // The edges shared by two triangles, each as its two sides (triangle * 3 + local edge k, the
  // edge from vertex k to k + 1).
  std::vector<std::array<int, 2>> interior_edges() const {
    // Sorted (edge key, side) pairs: a shared edge's two sides end up adjacent (no hash map: it
    // allocated a node per edge on every sweep, most of the optimisation's time at 60k triangles).
    std::vector<std::pair<std::uint64_t, int>> sides;
    sides.reserve(t_.size() * 3);
    for (std::size_t i = 0; i < t_.size(); ++i)
      for (int k = 0; k < 3; ++k)
        sides.emplace_back(key(t_[i][static_cast<std::size_t>(k)], t_[i][static_cast<std::size_t>((k + 1) % 3)]),
                           static_cast<int>(i) * 3 + k);
    std::sort(sides.begin(), sides.end());
    std::vector<std::array<int, 2>> interior;
    interior.reserve(sides.size() / 2);
    for (std::size_t a = 0; a + 1 < sides.size(); ++a)
      if (sides[a].first == sides[a + 1].first) {
        interior.push_back({sides[a].second, sides[a + 1].second});
        ++a;
      }
    return interior;
  }
  // One side (3 i + k) of every distinct edge.
  std::vector<std::size_t> distinct_sides() const {
    std::vector<std::pair<std::uint64_t, std::size_t>> sides;
    sides.reserve(t_.size() * 3);
    for (std::size_t i = 0; i < t_.size(); ++i)
      for (std::size_t k = 0; k < 3; ++k) sides.emplace_back(key(t_[i][k], t_[i][(k + 1) % 3]), 3 * i + k);
    std::sort(sides.begin(), sides.end());
    std::vector<std::size_t> out;
    for (std::size_t a = 0; a < sides.size(); ++a)
      if (a == 0 || sides[a].first != sides[a - 1].first) out.push_back(sides[a].second);
    return out;
  }

  std::vector<Vec>& x_;
  std::vector<Tri>& t_;
  const std::size_t fixed_;
  const MetricField<2>& metric_;
  std::vector<Mat> m_;  // the metric at every node
  double floor_ = 0;  // no split or collapse makes a triangle worse than this (set_floor)
  struct MidSample {
    Vec at = Vec::Zero();
    Mat m = Mat::Zero();
    bool valid = false;
  };
  std::vector<MidSample> side_mid_;  // side_length's midpoint metrics, per triangle side
};

}  // namespace

OptimizeStats optimize_fill(FillResult<2>& fill, std::size_t fixed_nodes, const MetricField<2>& metric,
                            const OptimizeParams& params) {
  OptimizeStats st;
  if (params.passes <= 0) return st;
  // The sweeps name a triangle's side as triangle * 3 + k in an int, and nodes are 32-bit ids.
  if (fill.simplices.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3 - 4) ||
      fill.nodes.size() > static_cast<std::size_t>(std::numeric_limits<NodeId>::max() / 2))
    throw MesherError("fill: " + std::to_string(fill.simplices.size()) +
                      " triangles are more than the post-optimisation can index; set fill.optimize_passes: 0");
  Optimizer o(fill, fixed_nodes, metric);
  st.quality_min_before = o.min_quality();
  o.set_floor(st.quality_min_before);
  st.unit_fraction_before = o.unit_fraction();
  bool topology = true;
  for (int pass = 0; pass < params.passes; ++pass) {
    std::size_t a = 0, b = 0;
    if (pass < std::max(1, params.passes - kPlacePasses) && topology) {
      st.splits += a = o.splits();
      st.collapses += b = o.collapses();
    }
    st.swaps += o.swaps();
    // The splits and collapses stop once a pass changes fewer than 1 in 1000 triangles (a sweep
    // costs a sampled length per edge; the last passes of bench_fill A found a few dozen each).
    if (pass > 0 && (a + b) * 1000 < o.triangles()) topology = false;
    st.moves += o.smooth();
  }
  if (params.passes > 0) st.swaps += o.swaps();
  o.compact();
  st.quality_min_after = o.min_quality();
  st.unit_fraction_after = o.unit_fraction();
  return st;
}

}  // namespace plaf::volume
