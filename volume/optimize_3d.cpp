// SPDX-License-Identifier: MIT
// Implements the metric optimisation of a 3D fill (optimize_3d.h).
#include "volume/optimize_3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/base/parallel.h"
#include "modules/geometry/predicates.h"
#include "volume/tetgen_fill.h"

namespace plaf::volume {

namespace {

using Vec = Eigen::Vector3d;
using Mat = Eigen::Matrix3d;
using Tet = std::array<NodeId, 4>;

// No collapse makes a tet worse than this or than the worst tet it replaces (a split: kSplitShare).
constexpr double kFloor = 0.2;
// A split may make the worst tet of its ring worse down to this share of it (halving a needle's
// long edge makes two needles of about the same shape, a little worse, which the next splits,
// swaps and moves mend; without it the anisotropic box test keeps edges of 6 units).
constexpr double kSplitShare = 0.5;
// No split or collapse makes a tet worse than this, whatever it replaces: split, a flat tet
// leaves flat children around the midpoint that no move of it can then lift (a move that lifts
// one inverts another; on the published 717 wing a front sliver split so left two free nodes
// stuck in tets of quality 1e-10), and a collapse in a sliver's ball spreads it alike.
constexpr double kSliver = 0.05;
// A swap must raise the worst quality of the tets it replaces by at least this.
constexpr double kGain = 1e-4;
// Swaps are tried on the tets worse than this (a regular tet is 1; TetGen's radius-edge bound
// leaves most above 0.5, its slivers near 0).
constexpr double kSwapBelow = 0.5;
// Splits and collapses run in all passes but the last kPlacePasses (which swap and smooth).
constexpr int kPlacePasses = 2;
// A collapse that removes a sliver may make edges up to this long (metric units) and tets down
// to this quality (on the published 717 wing, TetGen's Steiner point in a front triangle's plane:
// its best collapse makes a tet of 0.04 and an edge of 2.25 units, for two of 1e-10).
constexpr double kRepairLength = 2.5;
// Step 4 repairs the tets under this that the swaps left (from under 0.05 to under 0.15: the M6
// hybrid's least dihedral angle in the metric 0.62 -> 1.36 degrees, its unit edges 91.2 -> 91.9 %,
// the wake's 90.5 -> 91.0 %, the box's 95.41 -> 95.43 %).
constexpr double kRepairBelow = 0.15;
constexpr double kRepairFloor = 0.01;
// A collapse of a short edge may make edges up to this long (metric units): sqrt 2 leaves most
// short edges across an anisotropic metric's long sizes (above the M6's layers, 85k of about 750k
// edges, the new edge to a neighbour one size away in the short direction and a little along
// being just over); the next split sweep halves a longer edge into two unit ones (the last
// collapse sweep's longer edges stay: the last kPlacePasses passes only swap and smooth). Measured on the
// shipped hybrids, unit edges at sqrt 2 -> 1.6: M6 86.9 -> 89.9 %, box 93.2 -> 95.4 %, sphere 92.9 ->
// 95.5 %; the M6 at 1.5, 1.7 and 1.9: 89.0, 89.9 and 88.7 %.
constexpr double kCollapseLength = 1.6;
// A moved node keeps its metric until it is this far (metric units) from where it was evaluated.
constexpr double kMetricReuse = 0.05;
// Edge removal rings of up to this many tets.
constexpr std::size_t kMaxRing = 7;

std::uint64_t edge_key(NodeId a, NodeId b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}
NodeId key_lo(std::uint64_t k) { return static_cast<NodeId>(k >> 32); }
NodeId key_hi(std::uint64_t k) { return static_cast<NodeId>(k & 0xffffffffu); }

bool contains(const Tet& t, NodeId v) { return t[0] == v || t[1] == v || t[2] == v || t[3] == v; }

bool is_unit(double l) { return l >= std::numbers::sqrt2 / 2 && l <= std::numbers::sqrt2; }

// Mean ratio of the tet in the metric m: 12 (3 V_M)^(2/3) / sum L_M^2, signed by the volume
// (positive in plaf's order, hybrid_mesh.h).
double mean_ratio(const Mat& m, const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  const std::array<Vec, 6> e{b - a, c - a, d - a, c - b, d - b, d - c};
  double l2 = 0;
  for (const Vec& v : e) l2 += v.dot(m * v);
  if (!(l2 > 0)) return 0;
  const double vol = e[0].dot(e[1].cross(e[2])) / 6 * std::sqrt(std::max(m.determinant(), 0.0));
  const double r = 12 * std::cbrt(9 * vol * vol) / l2;
  return vol < 0 ? -r : r;
}

// The stretch FillShape3::Stretched counts from.
constexpr double kStretched = 10;

// A metric's largest size over its smallest: sqrt of its largest eigenvalue over its smallest.
double metric_stretch_of(const Mat& m) {
  const Eigen::SelfAdjointEigenSolver<Mat> es(m, Eigen::EigenvaluesOnly);
  const Vec l = es.eigenvalues();
  return l[0] > 0 ? std::sqrt(l[2] / l[0]) : std::numeric_limits<double>::infinity();
}

// A tet's own stretch (FillShape3::Stretched): the condition number of the affine map from the
// regular tet of unit edges onto it; infinite for a flat one.
double tet_stretch(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  static const Mat regular_inverse = [] {
    Mat r;
    r.col(0) = Vec(1, 0, 0);
    r.col(1) = Vec(0.5, std::sqrt(3.0) / 2, 0);
    r.col(2) = Vec(0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0));
    return Mat(r.inverse());
  }();
  Mat e;
  e.col(0) = b - a;
  e.col(1) = c - a;
  e.col(2) = d - a;
  const Eigen::JacobiSVD<Mat> svd(e * regular_inverse);
  const Vec sv = svd.singularValues();
  return sv[2] > 0 ? sv[0] / sv[2] : std::numeric_limits<double>::infinity();
}

// The measures of optimize_3d.h's FillShape3, from the nodes' metric matrices.
FillShape3 measure(const std::vector<Vec>& x, const std::vector<Tet>& tets, const std::vector<char>* dead,
                   const std::vector<Mat>& m, std::size_t fixed) {
  FillShape3 s;
  s.quality_min = std::numeric_limits<double>::infinity();
  s.quality_min_inner = 1;
  s.length_min = std::numeric_limits<double>::infinity();
  double dmin = std::numbers::pi, dinner = std::numbers::pi, mmin = std::numbers::pi, minner = std::numbers::pi;
  std::vector<std::uint64_t> edges;
  std::vector<double> metric_stretch, own_stretch, stretched_quality;
  for (std::size_t i = 0; i < tets.size(); ++i) {
    if (dead && (*dead)[i]) continue;
    const Tet& t = tets[i];
    ++s.tets;
    const Mat mt = (m[t[0]] + m[t[1]] + m[t[2]] + m[t[3]]) / 4;
    const double q = mean_ratio(mt, x[t[0]], x[t[1]], x[t[2]], x[t[3]]);
    if (const double ms = metric_stretch_of(mt); ms >= kStretched) {
      metric_stretch.push_back(ms);
      own_stretch.push_back(tet_stretch(x[t[0]], x[t[1]], x[t[2]], x[t[3]]));
      stretched_quality.push_back(q);
    }
    s.quality_min = std::min(s.quality_min, q);
    const double dihedral = tet_shape({x[t[0]], x[t[1]], x[t[2]], x[t[3]]}).first;
    dmin = std::min(dmin, dihedral);
    const bool inner = std::all_of(t.begin(), t.end(), [fixed](NodeId v) { return static_cast<std::size_t>(v) >= fixed; });
    if (inner) dinner = std::min(dinner, dihedral), s.quality_min_inner = std::min(s.quality_min_inner, q);
    const double deg = dihedral * 180 / std::numbers::pi;
    s.below_5deg += deg < 5 ? 1 : 0;
    s.below_10deg += deg < 10 ? 1 : 0;
    const Eigen::LLT<Mat> llt(mt);
    const Mat lt = llt.matrixU();  // M = U^T U: |U e| is e's metric length
    // (A mean of SPD metrics is SPD; should its factor fail, the tet counts as flat in the metric.)
    const double in_metric = llt.info() == Eigen::Success
                                 ? tet_shape({lt * x[t[0]], lt * x[t[1]], lt * x[t[2]], lt * x[t[3]]}).first
                                 : 0.0;
    if (in_metric < mmin) s.metric_min_dihedral_at = (x[t[0]] + x[t[1]] + x[t[2]] + x[t[3]]) / 4;
    mmin = std::min(mmin, in_metric);
    if (inner) minner = std::min(minner, in_metric);
    const double mdeg = in_metric * 180 / std::numbers::pi;
    s.metric_below_5deg += mdeg < 5 ? 1 : 0;
    s.metric_below_10deg += mdeg < 10 ? 1 : 0;
    s.flat += positive_tet(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) ? 0 : 1;
    s.volume_max = std::max(s.volume_max, (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).dot(x[t[3]] - x[t[0]]) / 6);
    for (int k = 0; k < 4; ++k)
      for (int l = k + 1; l < 4; ++l) edges.push_back(edge_key(t[k], t[l]));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::size_t unit = 0;
  for (std::uint64_t k : edges) {
    const NodeId a = key_lo(k), b = key_hi(k);
    const Vec e = x[b] - x[a];
    const double l = std::sqrt(e.dot(0.5 * (m[a] + m[b]) * e));
    unit += is_unit(l) ? 1 : 0;
    s.length_min = std::min(s.length_min, l);
    if (l > s.length_max) s.length_max_at = (x[a] + x[b]) / 2;
    s.length_max = std::max(s.length_max, l);
    if (static_cast<std::size_t>(b) >= fixed) s.length_max_free = std::max(s.length_max_free, l);  // b > a
  }
  if (s.tets == 0) s.quality_min = 0;
  if (edges.empty()) s.length_min = 0;
  s.unit_fraction = edges.empty() ? 0 : static_cast<double>(unit) / static_cast<double>(edges.size());
  s.min_dihedral_deg = s.tets ? dmin * 180 / std::numbers::pi : 0;
  s.min_dihedral_inner_deg = dinner * 180 / std::numbers::pi;
  s.metric_min_dihedral_deg = s.tets ? mmin * 180 / std::numbers::pi : 0;
  s.metric_min_dihedral_inner_deg = minner * 180 / std::numbers::pi;
  if (!own_stretch.empty()) {
    auto pct = [](std::vector<double>& v, double f) {
      const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(f * static_cast<double>(v.size())));
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
      return v[k];
    };
    s.stretched.tets = own_stretch.size();
    s.stretched.at_least_10 = static_cast<double>(std::count_if(own_stretch.begin(), own_stretch.end(), [](double r) { return r >= kStretched; })) /
                              static_cast<double>(own_stretch.size());
    s.stretched.metric_p50 = pct(metric_stretch, 0.5);
    s.stretched.stretch_p10 = pct(own_stretch, 0.1);
    s.stretched.stretch_p50 = pct(own_stretch, 0.5);
    s.stretched.stretch_p90 = pct(own_stretch, 0.9);
    s.stretched.quality_p50 = pct(stretched_quality, 0.5);
  }
  return s;
}

std::vector<Mat> node_metrics(const std::vector<Vec>& x, const MetricField<3>& metric) {
  std::vector<Mat> m(x.size());
  parallel_chunks(x.size(), 4096, [&](unsigned, std::size_t lo, std::size_t hi) {
    for (std::size_t v = lo; v < hi; ++v) m[v] = metric.evaluate(x[v]).matrix();
  });
  return m;
}

class Optimizer3 {
 public:
  Optimizer3(FillResult<3>& fill, std::size_t fixed, const MetricField<3>& metric,
             const std::vector<std::pair<NodeId, int>>& in_plane = {}, double max_volume = 0)
      : fill_(fill), x_(fill.nodes), t_(fill.simplices), fixed_(fixed), metric_(metric), max_volume_(max_volume) {
    // x_ and t_ are copies: the fill is written back only at the end (compact), so an exception
    // (a metric that throws) leaves it as it was.
    for (const Tet& t : t_)
      for (NodeId v : t)
        if (v < 0 || static_cast<std::size_t>(v) >= x_.size())
          throw InputError("optimize 3d: a tet uses node " + std::to_string(v) + " of " + std::to_string(x_.size()));
    m_ = node_metrics(x_, metric_);
    m_at_ = x_;
    ball_.resize(x_.size());
    gone_.assign(x_.size(), 0);
    dead_.assign(t_.size(), 0);
    touched_.assign(x_.size(), 1);
    q_.resize(t_.size());
    for (std::size_t i = 0; i < t_.size(); ++i) {
      for (NodeId v : t_[i]) ball_[v].push_back(static_cast<std::uint32_t>(i));
      q_[i] = quality(t_[i]);
    }
    plane_axis_.assign(x_.size(), -1);
    for (const auto& [v, axis] : in_plane) {
      if (v < 0 || static_cast<std::size_t>(v) >= x_.size() || axis < 0 || axis > 2)
        throw InputError("optimize 3d: in-plane node " + std::to_string(v) + " or axis " + std::to_string(axis) + " out of range");
      plane_axis_[static_cast<std::size_t>(v)] = axis;
    }
    // The boundary: the faces of one tet (the fronts, the farfield, the planes, whether or not
    // fill.boundary lists them: the layers' outer front is an interface of the hybrid mesh).
    frozen_.assign(x_.size(), 0);
    std::fill(frozen_.begin(), frozen_.begin() + static_cast<std::ptrdiff_t>(std::min(fixed_, x_.size())), 1);
    std::vector<std::array<NodeId, 3>> faces;
    faces.reserve(4 * t_.size());
    for (const Tet& t : t_)
      for (int k = 0; k < 4; ++k) {
        std::array<NodeId, 3> f{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
        std::sort(f.begin(), f.end());
        faces.push_back(f);
      }
    std::sort(faces.begin(), faces.end());
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j] == faces[i]) ++j;
      if (j - i == 1)
        for (int k = 0; k < 3; ++k) {
          boundary_edges_.insert(edge_key(faces[i][k], faces[i][(k + 1) % 3]));
          frozen_[static_cast<std::size_t>(faces[i][k])] = 1;  // a boundary node stays, fixed or not
          // A sliding node's boundary triangles all lie in its plane.
          if (const int axis = plane_axis_[static_cast<std::size_t>(faces[i][k])]; axis >= 0) {
            const double c = x_[static_cast<std::size_t>(faces[i][k])][axis];
            for (NodeId w : faces[i])
              if (x_[static_cast<std::size_t>(w)][axis] != c)
                throw InputError("optimize 3d: in-plane node " + std::to_string(faces[i][k]) +
                                 " lies on a boundary triangle off its plane");
          }
        }
      i = j;
    }
  }

  FillShape3 shape() const { return measure(x_, t_, &dead_, m_, fixed_); }

  Optimize3Stats run(int passes, const std::function<void(int, int)>& on_pass) {
    Optimize3Stats st;
    st.before = shape();
    for (int pass = 0; pass < passes; ++pass) {
      const std::size_t changes_before = st.splits + st.collapses + st.swaps + st.moves + st.repairs;
      if (pass < passes - kPlacePasses) {
        st.splits += split_sweep();
        st.collapses += collapse_sweep();
      }
      st.swaps += swap_sweep();
      st.repairs += sliver_sweep();
      st.moves += smooth_sweep();
      st.swaps += swap_sweep();
      const std::size_t changes = st.splits + st.collapses + st.swaps + st.moves + st.repairs - changes_before;
      drop_dead_tets();
      if (on_pass) on_pass(pass + 1, passes);
      if (pass >= passes - kPlacePasses && changes * 1000 < alive_tets()) break;
    }
    compact();
    return st;
  }

 private:
  // --- The mesh -------------------------------------------------------------------------------
  std::size_t alive_tets() const { return static_cast<std::size_t>(std::count(dead_.begin(), dead_.end(), 0)); }
  // A tetrahedron a step may make: positive (exact orient3d) and within fill.max_volume.
  bool admissible(const Tet& t) const {
    if (!positive_tet(x_[t[0]], x_[t[1]], x_[t[2]], x_[t[3]])) return false;
    return !(max_volume_ > 0) ||
           (x_[t[1]] - x_[t[0]]).cross(x_[t[2]] - x_[t[0]]).dot(x_[t[3]] - x_[t[0]]) <= 6 * max_volume_;
  }
  double quality(const Tet& t) const {
    return mean_ratio((m_[t[0]] + m_[t[1]] + m_[t[2]] + m_[t[3]]) / 4, x_[t[0]], x_[t[1]], x_[t[2]], x_[t[3]]);
  }
  double length(NodeId a, NodeId b) const {
    const Vec e = x_[b] - x_[a];
    return std::sqrt(e.dot(0.5 * (m_[a] + m_[b]) * e));
  }
  void add(const Tet& t) {
    const auto i = static_cast<std::uint32_t>(t_.size());
    t_.push_back(t);
    dead_.push_back(0);
    q_.push_back(quality(t));
    if (touched_.size() < x_.size()) touched_.resize(x_.size(), 1);
    for (NodeId v : t) ball_[v].push_back(i), touched_[v] = 1;
  }
  void kill(std::uint32_t i) {
    dead_[i] = 1;
    for (NodeId v : t_[i]) {
      touched_[v] = 1;
      std::vector<std::uint32_t>& b = ball_[v];
      *std::find(b.begin(), b.end(), i) = b.back();
      b.pop_back();
    }
  }
  // The tets around edge ab, into `out`.
  void ring(NodeId a, NodeId b, std::vector<std::uint32_t>& out) const {
    out.clear();
    for (std::uint32_t i : ball_[a])
      if (contains(t_[i], b)) out.push_back(i);
  }
  bool has_edge(NodeId a, NodeId b) const {
    const NodeId s = ball_[a].size() <= ball_[b].size() ? a : b, o = s == a ? b : a;
    return std::any_of(ball_[s].begin(), ball_[s].end(), [&](std::uint32_t i) { return contains(t_[i], o); });
  }
  bool has_triangle(NodeId a, NodeId b, NodeId c) const {
    return std::any_of(ball_[a].begin(), ball_[a].end(),
                       [&](std::uint32_t i) { return contains(t_[i], b) && contains(t_[i], c); });
  }
  double worst(const std::vector<std::uint32_t>& tets) const {
    double q = std::numeric_limits<double>::infinity();
    for (std::uint32_t i : tets) q = std::min(q, q_[i]);
    return q;
  }
  std::vector<std::uint64_t> edges() const {
    std::vector<std::uint64_t> e;
    for (std::size_t i = 0; i < t_.size(); ++i)
      if (!dead_[i])
        for (int k = 0; k < 4; ++k)
          for (int l = k + 1; l < 4; ++l) e.push_back(edge_key(t_[i][k], t_[i][l]));
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    return e;
  }

  // Node v moved: its metric is evaluated again once it is kMetricReuse metric units from where it
  // last was (a wall distance metric costs a closest-point search per evaluation; smoothing's
  // moves are mostly small).
  void refresh_metric(NodeId v) {
    const Vec d = x_[v] - m_at_[v];
    if (d.dot(m_[v] * d) > kMetricReuse * kMetricReuse) {
      m_[v] = metric_.evaluate(x_[v]).matrix();
      m_at_[v] = x_[v];
    }
  }

  // Node v moved: its metric followed (refresh_metric), its tets' qualities measured again, and
  // every node of its ball touched (smoothing tries a node again only once its ball changed).
  void after_move(NodeId v) {
    refresh_metric(v);
    for (std::uint32_t i : ball_[v]) {
      q_[i] = quality(t_[i]);
      for (NodeId w : t_[i]) touched_[w] = 1;
    }
  }

  // --- Splits and collapses -------------------------------------------------------------------
  std::size_t split_sweep() {
    std::vector<std::pair<double, std::uint64_t>> longs;
    for (std::uint64_t k : edges()) {
      const double l = length(key_lo(k), key_hi(k));
      if (l > std::numbers::sqrt2 && !boundary_edges_.count(k)) longs.emplace_back(-l, k);
    }
    std::sort(longs.begin(), longs.end());
    std::size_t n = 0;
    for (const auto& [l, k] : longs) n += split(key_lo(k), key_hi(k)) ? 1 : 0;
    return n;
  }

  // Edge ab split at its midpoint; with `lift` (a sliver's repair) the midpoint then goes to
  // the centre of its ball's kernel (kernel_point), and the new tets need only kRepairFloor.
  bool split(NodeId a, NodeId b, bool lift = false) {
    ring(a, b, ring_);
    if (ring_.empty()) return false;  // gone with an earlier change
    const double w = worst(ring_);
    // A lifted split must better its ring's worst (by kGain at least, doubling it up to
    // kRepairFloor).
    const double floor = lift ? std::max(w + kGain, std::min(kRepairFloor, 2 * w))
                              : std::max(kSliver, std::min(kFloor, kSplitShare * w));
    const auto mid = static_cast<NodeId>(x_.size());
    x_.push_back(0.5 * (x_[a] + x_[b]));
    // The ends' mean metric while the split is judged, the field's once it is made (a wall
    // distance metric costs a closest-point search per evaluation).
    m_.push_back(0.5 * (m_[a] + m_[b]));
    m_at_.push_back(x_.back());
    ball_.emplace_back();
    gone_.push_back(0);
    frozen_.push_back(0);
    plane_axis_.push_back(-1);
    made_.clear();
    for (std::uint32_t i : ring_) {
      Tet ta = t_[i], tb = t_[i];
      std::replace(ta.begin(), ta.end(), b, mid);
      std::replace(tb.begin(), tb.end(), a, mid);
      made_.push_back(ta), made_.push_back(tb);
    }
    bool ok = true;
    if (lift) {
      const std::optional<Vec> to = kernel_point(mid, made_);
      ok = to.has_value();
      if (ok) x_[mid] = *to, m_at_[mid] = *to;
    }
    for (std::size_t j = 0; j < made_.size() && ok; ++j) ok = admissible(made_[j]) && quality(made_[j]) >= floor;
    if (!ok) {
      x_.pop_back(), m_.pop_back(), m_at_.pop_back(), ball_.pop_back(), gone_.pop_back(), frozen_.pop_back();
      plane_axis_.pop_back();
      return false;
    }
    m_[mid] = metric_.evaluate(x_[mid]).matrix();
    for (std::uint32_t i : ring_) kill(i);
    for (const Tet& t : made_) add(t);
    return true;
  }

  std::size_t collapse_sweep() {
    std::vector<std::pair<double, std::uint64_t>> shorts;
    for (std::uint64_t k : edges()) {
      const double l = length(key_lo(k), key_hi(k));
      if (l < std::numbers::sqrt2 / 2) shorts.emplace_back(l, k);
    }
    std::sort(shorts.begin(), shorts.end());
    std::size_t n = 0;
    for (const auto& [l, k] : shorts) {
      const NodeId a = key_lo(k), b = key_hi(k);
      if (gone_[a] || gone_[b]) continue;
      // The higher id first: of two free ends, the one the fill made later.
      n += (collapse(b, a, kCollapseLength) || collapse(a, b, kCollapseLength)) ? 1 : 0;
    }
    return n;
  }

  // Node a (free) merged into b, no new edge longer than max_length, no new tet worse than
  // least (nor than kFloor or the worst it replaces).
  bool collapse(NodeId a, NodeId b, double max_length, double least = kSliver) {
    if (frozen_[a] || gone_[a]) return false;
    ring(a, b, ring_);
    if (ring_.empty()) return false;
    // Link condition: every vertex and edge the links of a and b share is in the link of ab.
    std::vector<NodeId>& ab_link = scratch_nodes_;
    ab_link.clear();
    for (std::uint32_t i : ring_)
      for (NodeId v : t_[i])
        if (v != a && v != b) ab_link.push_back(v);
    others_.clear();
    for (std::uint32_t i : ball_[a])
      if (!contains(t_[i], b)) others_.push_back(i);
    const double floor = std::max(least, std::min(kFloor, std::min(worst(ring_), worst(others_))));
    auto in_ab_link = [&](NodeId v) { return std::find(ab_link.begin(), ab_link.end(), v) != ab_link.end(); };
    made_.clear();
    for (std::uint32_t i : others_) {
      const Tet& t = t_[i];
      std::array<NodeId, 3> o{};
      int n = 0;
      for (NodeId v : t)
        if (v != a) o[n++] = v;
      for (NodeId v : o)
        if (!in_ab_link(v) && has_edge(b, v)) return false;  // a vertex in both links, not in ab's
      for (int k = 0; k < 3; ++k)  // an edge in both links, not in ab's
        if (has_triangle(b, o[k], o[(k + 1) % 3]) && !has_tet(a, b, o[k], o[(k + 1) % 3])) return false;
      if (has_tet(b, o[0], o[1], o[2])) return false;  // a triangle in both links
      Tet nt = t;
      std::replace(nt.begin(), nt.end(), a, b);
      if (!admissible(nt) || quality(nt) < floor) return false;
      for (NodeId v : o)
        if (length(b, v) > max_length) return false;
      made_.push_back(nt);
    }
    for (std::uint32_t i : ring_) kill(i);
    for (std::uint32_t i : others_) kill(i);
    for (const Tet& t : made_) add(t);
    gone_[a] = 1;
    return true;
  }
  bool has_tet(NodeId a, NodeId b, NodeId c, NodeId d) const {
    return std::any_of(ball_[a].begin(), ball_[a].end(), [&](std::uint32_t i) {
      return contains(t_[i], b) && contains(t_[i], c) && contains(t_[i], d);
    });
  }

  // --- Swaps ----------------------------------------------------------------------------------
  std::size_t swap_sweep() {
    std::size_t n = 0;
    const std::size_t count = t_.size();
    for (std::size_t i = 0; i < count; ++i) {
      if (dead_[i] || q_[i] >= kSwapBelow) continue;
      const Tet t = t_[i];
      bool done = false;
      for (int k = 0; k < 4 && !done; ++k)
        for (int l = k + 1; l < 4 && !done; ++l) done = remove_edge(t[k], t[l]);
      for (int k = 0; k < 4 && !done; ++k) done = swap23(static_cast<std::uint32_t>(i), k);
      n += done ? 1 : 0;
    }
    return n;
  }

  // A sliver (a tet under kRepairBelow) that no swap mended loses a free vertex, merged into another
  // of its vertices (a Steiner point of TetGen's in a front triangle's plane sits in two slivers
  // on opposite sides: every move lifting one inverts the other). New edges up to 2 units.
  std::size_t sliver_sweep() {
    std::size_t n = 0;
    const std::size_t count = t_.size();
    for (std::size_t i = 0; i < count; ++i) {
      if (dead_[i] || q_[i] >= kRepairBelow) continue;
      const Tet t = t_[i];
      // A repair must at least double the sliver's quality, up to kRepairFloor: at a front
      // triangle of aspect ratio 1e4 (a fan's sector strip, issue 31) no tet is better than a
      // sliver, and the kernel's centre is the best one.
      const double least = std::min(kRepairFloor, 2 * q_[i]);
      bool done = false;
      for (int k = 0; k < 4 && !done; ++k)
        if (!frozen_[t[k]]) done = kernel_move(t[k]);
      for (int k = 0; k < 4 && !done; ++k) {
        const NodeId a = t[k];
        if (frozen_[a]) continue;
        std::vector<NodeId>& nbr = scratch_nbr_;
        nbr.clear();
        for (std::uint32_t c : ball_[a])
          for (NodeId b : t_[c])
            if (b != a) nbr.push_back(b);
        std::sort(nbr.begin(), nbr.end());
        nbr.erase(std::unique(nbr.begin(), nbr.end()), nbr.end());
        for (std::size_t j = 0; j < nbr.size() && !done; ++j) done = collapse(a, nbr[j], kRepairLength, least);
      }
      // A sliver of fixed nodes (two front triangles in a shallow valley and the two vertices
      // across it): an interior edge of it split, its midpoint lifted into its kernel.
      for (int k = 0; k < 4 && !done; ++k)
        for (int l = k + 1; l < 4 && !done; ++l)
          if (!boundary_edges_.count(edge_key(t[k], t[l]))) done = split(t[k], t[l], true);
      n += done ? 1 : 0;
    }
    return n;
  }

  // Free node v of a sliver to the point of its ball's kernel farthest from the faces around it
  // (max over x of min over the ball of the distance from x to the face opposite v, on its
  // positive side: a max-min of linear functions, by subgradient steps). Smoothing's targets
  // are means; a Steiner point of TetGen's on a front triangle's edge, between tets that wrap
  // around it, has none that every tet accepts, but its kernel's centre is one. Kept when the
  // ball's worst tet gets better (exact orient3d on every tet).
  bool kernel_move(NodeId v) {
    made_.clear();
    for (std::uint32_t i : ball_[v]) made_.push_back(t_[i]);
    if (made_.empty()) return false;
    const std::optional<Vec> to = kernel_point(v, made_);
    if (!to) return false;
    const double old_min = worst(ball_[v]);
    const Vec from = x_[v];
    x_[v] = *to;
    double q_min = std::numeric_limits<double>::infinity();
    for (const Tet& t : made_) {
      if (!admissible(t)) {
        x_[v] = from;
        return false;
      }
      q_min = std::min(q_min, quality(t));
    }
    if (!(q_min > old_min)) {
      x_[v] = from;
      return false;
    }
    after_move(v);
    return true;
  }

  // The point x maximising the least distance from x to the faces opposite v in `tets` (all
  // holding v), on their positive side; none if every point leaves one on the wrong side.
  std::optional<Vec> kernel_point(NodeId v, const std::vector<Tet>& tets) {
    // Per tet: 6 V(x) = g . x + c, positive when valid; stored with |g| = 1.
    std::vector<std::pair<Vec, double>>& planes = scratch_planes_;
    planes.clear();
    double size = 0;
    for (const Tet& t : tets) {
      int k = 0;
      while (t[k] != v) ++k;
      const Vec& p = x_[t[(k + 1) % 4]];
      const Vec& q = x_[t[(k + 2) % 4]];
      const Vec& r = x_[t[(k + 3) % 4]];
      // With v first, 6 V = det [p - x, q - x, r - x], of gradient -(q - p) x (r - p); moving v
      // from place k to the front is a rotation by k places, odd for k = 1 and 3 (a 4-cycle).
      Vec g = (q - p).cross(r - p);
      if (k % 2 == 0) g = -g;
      const double gn = g.norm();
      if (!(gn > 0)) return std::nullopt;
      planes.emplace_back(g / gn, -g.dot(p) / gn);
      size = std::max({size, (q - p).norm(), (r - q).norm(), (p - r).norm()});
    }
    auto margin = [&](const Vec& y, std::size_t* arg) {
      double m = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < planes.size(); ++j) {
        const double d = planes[j].first.dot(y) + planes[j].second;
        if (d < m) m = d, *arg = j;
      }
      return m;
    };
    Vec x = x_[v], best = x;
    std::size_t arg = 0;
    double best_margin = margin(x, &arg);
    for (int it = 0; it < 200; ++it) {  // subgradient ascent of the least distance
      x += planes[arg].first * (0.1 * size / (1 + 0.1 * it));
      const double m = margin(x, &arg);
      if (m > best_margin) best_margin = m, best = x;
    }
    if (!(best_margin > 0)) return std::nullopt;
    return best;
  }

  // The face of tet i opposite its vertex k, shared with one other tet, becomes the edge between
  // their apexes (three tets).
  bool swap23(std::uint32_t i, int k) {
    const Tet t = t_[i];
    const NodeId d = t[k];
    const NodeId f0 = t[(k + 1) % 4], f1 = t[(k + 2) % 4], f2 = t[(k + 3) % 4];
    std::uint32_t j = 0;
    bool found = false;
    for (std::uint32_t c : ball_[f0])
      if (c != i && contains(t_[c], f1) && contains(t_[c], f2)) j = c, found = true;
    if (!found) return false;  // a boundary triangle
    NodeId e = t_[j][0];
    for (NodeId v : t_[j])
      if (v != f0 && v != f1 && v != f2) e = v;
    if (has_edge(d, e)) return false;
    const double old = std::min(q_[i], q_[j]);
    made_.clear();
    double q = std::numeric_limits<double>::infinity();
    for (int p = 0; p < 4; ++p) {
      if (p == k) continue;
      Tet nt = t;
      nt[p] = e;
      if (!admissible(nt)) return false;
      q = std::min(q, quality(nt));
      made_.push_back(nt);
    }
    if (!(q > old + kGain)) return false;
    kill(i), kill(j);
    for (const Tet& nt : made_) add(nt);
    return true;
  }

  // The interior edge ab of 3..kMaxRing tets goes; its ring polygon is triangulated by the fan
  // from one of its vertices (the best), each triangle making a tet with a and one with b.
  bool remove_edge(NodeId a, NodeId b) {
    if (boundary_edges_.count(edge_key(a, b))) return false;
    ring(a, b, ring_);
    const std::size_t n = ring_.size();
    if (n < 3 || n > kMaxRing) return false;
    // The ring's vertices in cyclic order.
    std::array<std::array<NodeId, 2>, kMaxRing> pairs{};
    for (std::size_t r = 0; r < n; ++r) {
      int c = 0;
      for (NodeId v : t_[ring_[r]])
        if (v != a && v != b) pairs[r][c++] = v;
    }
    std::array<NodeId, kMaxRing> u{};
    std::array<bool, kMaxRing> used{};
    u[0] = pairs[0][0], u[1] = pairs[0][1], used[0] = true;
    for (std::size_t s = 2; s <= n; ++s) {
      bool next = false;
      for (std::size_t r = 0; r < n && !next; ++r) {
        if (used[r]) continue;
        for (int c = 0; c < 2 && !next; ++c)
          if (pairs[r][c] == u[s - 1]) {
            used[r] = next = true;
            if (s < n) u[s] = pairs[r][1 - c];
            else if (pairs[r][1 - c] != u[0]) return false;  // not one closed ring
          }
      }
      if (!next) return false;  // an open ring: the edge is on the boundary
    }
    const double old = worst(ring_);
    double best = old + kGain;
    std::vector<Tet> chosen;
    for (std::size_t apex = 0; apex < (n == 3 ? 1 : n); ++apex) {
      bool diagonals_free = true;
      for (std::size_t k = 2; k + 1 < n && diagonals_free; ++k)
        diagonals_free = !has_edge(u[apex], u[(apex + k) % n]);
      if (!diagonals_free) continue;
      for (int dir = 0; dir < 2; ++dir) {
        made_.clear();
        double q = std::numeric_limits<double>::infinity();
        bool ok = true;
        for (std::size_t k = 1; k + 1 < n && ok; ++k) {
          NodeId p = u[apex], s = u[(apex + k) % n], r = u[(apex + k + 1) % n];
          if (dir) std::swap(s, r);
          const Tet ta{p, s, r, a}, tb{s, p, r, b};
          ok = admissible(ta) && admissible(tb);
          if (ok) {
            q = std::min({q, quality(ta), quality(tb)});
            made_.push_back(ta), made_.push_back(tb);
          }
        }
        if (ok && q > best) best = q, chosen = made_;
        if (ok) break;  // the other direction is the mirror: inverted
      }
    }
    if (chosen.empty()) return false;
    const std::vector<std::uint32_t> gone = ring_;
    for (std::uint32_t i : gone) kill(i);
    for (const Tet& t : chosen) add(t);
    return true;
  }

  // --- Smoothing ------------------------------------------------------------------------------
  std::size_t smooth_sweep() {
    std::size_t n = 0;
    for (std::size_t v = 0; v < x_.size(); ++v)
      if ((!frozen_[v] || plane_axis_[v] >= 0) && !gone_[v] && touched_[v]) {
        touched_[v] = 0;
        n += smooth(static_cast<NodeId>(v)) ? 1 : 0;
      }
    return n;
  }

  bool smooth(NodeId v) {
    const std::vector<std::uint32_t>& ball = ball_[v];
    if (ball.empty()) return false;
    const Eigen::LLT<Mat> llt(m_[v]);
    if (llt.info() != Eigen::Success) return false;
    const Mat lt = llt.matrixU();  // M = U^T U: y = U x measures in the metric
    const Vec yv = lt * x_[v];
    // Each tet's ideal point for v: over its opposite face, at the height that makes it regular
    // in the metric (the face's mean edge as its edge).
    Vec mean = Vec::Zero(), worst_ideal = x_[v];
    double old_min = std::numeric_limits<double>::infinity(), old_sum = 0;
    for (std::uint32_t i : ball) {
      std::array<Vec, 3> f;
      int c = 0;
      for (NodeId w : t_[i])
        if (w != v) f[c++] = lt * x_[w];
      Vec nrm = (f[1] - f[0]).cross(f[2] - f[0]);
      if (nrm.dot(yv - f[0]) < 0) nrm = -nrm;
      const double nn = nrm.norm();
      if (!(nn > 0)) return false;
      const double side = ((f[1] - f[0]).norm() + (f[2] - f[1]).norm() + (f[0] - f[2]).norm()) / 3;
      const Vec ideal = (f[0] + f[1] + f[2]) / 3 + nrm / nn * side * std::sqrt(2.0 / 3.0);
      mean += ideal;
      const double q = q_[i];
      if (q < old_min) old_min = q, worst_ideal = ideal;
      old_sum += q;
    }
    const auto back = lt.triangularView<Eigen::Upper>();
    const Vec from = x_[v];
    auto accept = [&](const Vec& to) {
      x_[v] = to;
      double q_min = std::numeric_limits<double>::infinity(), q_sum = 0;
      for (std::uint32_t i : ball) {
        if (!admissible(t_[i])) return false;
        const double q = quality(t_[i]);
        q_min = std::min(q_min, q), q_sum += q;
      }
      return q_min > old_min || (q_min >= old_min && q_sum > old_sum + 1e-9 * static_cast<double>(ball.size()));
    };
    // Toward the mean of the ideal points (the ball's shape), then, in a poor ball, toward the
    // worst tet's own ideal point by shorter and shorter steps (a sliver next to its neighbours
    // of fair shape: the mean leaves it or inverts a neighbour).
    // A plane's node keeps its coordinate across the plane, exactly.
    const int axis = plane_axis_[static_cast<std::size_t>(v)];
    auto in_plane = [&](Vec p) {
      if (axis >= 0) p[axis] = from[axis];
      return p;
    };
    const Vec target = in_plane(back.solve(Vec(mean / static_cast<double>(ball.size()))));
    bool moved = false;
    for (double step : {1.0, 0.5, 0.25})
      if (!moved) moved = accept(from + step * (target - from));
    if (!moved && old_min < kSwapBelow) {
      const Vec lift = in_plane(back.solve(worst_ideal));
      for (double step : {1.0, 0.5, 0.25, 0.1, 0.03, 0.01})
        if (!moved) moved = accept(from + step * (lift - from));
    }
    if (!moved) {
      x_[v] = from;
      return false;
    }
    after_move(v);
    return true;
  }

  // Drops the dead tets from t_ (every sweep scans it; the changes leave several dead per live
  // one), renumbering the balls.
  void drop_dead_tets() {
    std::vector<std::uint32_t> id(t_.size(), 0);
    std::size_t n = 0;
    for (std::size_t i = 0; i < t_.size(); ++i)
      if (!dead_[i]) {
        id[i] = static_cast<std::uint32_t>(n);
        t_[n] = t_[i], q_[n] = q_[i];
        ++n;
      }
    t_.resize(n), q_.resize(n);
    dead_.assign(n, 0);
    for (std::vector<std::uint32_t>& b : ball_)
      for (std::uint32_t& i : b) i = id[i];
  }

  // Writes the fill back without the dead tets and the collapsed nodes; the fixed nodes keep
  // their ids.
  void compact() {
    std::vector<NodeId> id(x_.size(), -1);
    std::vector<Vec> nodes;
    nodes.reserve(x_.size());
    for (std::size_t v = 0; v < x_.size(); ++v)
      if (v < fixed_ || !gone_[v]) {
        id[v] = static_cast<NodeId>(nodes.size());
        nodes.push_back(x_[v]);
      }
    std::vector<Tet> tets;
    tets.reserve(t_.size());
    for (std::size_t i = 0; i < t_.size(); ++i)
      if (!dead_[i]) tets.push_back({id[t_[i][0]], id[t_[i][1]], id[t_[i][2]], id[t_[i][3]]});
    std::vector<Mat> m;
    m.reserve(nodes.size());
    for (std::size_t v = 0; v < x_.size(); ++v)
      if (id[v] >= 0) m.push_back(m_[v]);
    fill_.nodes = std::move(nodes);
    fill_.simplices = std::move(tets);
    m_ = std::move(m);
  }

 public:
  const std::vector<Mat>& metrics() const { return m_; }

 private:
  FillResult<3>& fill_;
  std::vector<Vec> x_;
  std::vector<Tet> t_;
  std::vector<char> frozen_;  // per node: fixed (the first fixed_) or on a boundary triangle
  std::vector<int> plane_axis_;  // per node: the axis of the plane it may move in (step 5), or -1
  std::size_t fixed_;
  const MetricField<3>& metric_;
  double max_volume_ = 0;  // Optimize3Params::max_volume
  std::vector<Mat> m_;
  std::vector<Vec> m_at_;  // where each node's metric was evaluated
  std::vector<std::vector<std::uint32_t>> ball_;
  std::vector<char> gone_, dead_;
  std::vector<double> q_;       // per tet: its quality (kept current by add and after_move)
  std::vector<char> touched_;   // per node: its ball changed since smoothing last tried it
  std::unordered_set<std::uint64_t> boundary_edges_;
  std::vector<std::uint32_t> ring_, others_;
  std::vector<NodeId> scratch_nodes_, scratch_nbr_;
  std::vector<std::pair<Vec, double>> scratch_planes_;
  std::vector<Tet> made_;
};

}  // namespace

FillShape3 measure_fill_3d(const FillResult<3>& fill, std::size_t fixed_nodes, const MetricField<3>& metric) {
  return measure(fill.nodes, fill.simplices, nullptr, node_metrics(fill.nodes, metric), fixed_nodes);
}

Optimize3Stats optimize_fill_3d(FillResult<3>& fill, std::size_t fixed_nodes, const MetricField<3>& metric,
                                const Optimize3Params& params) {
  Optimizer3 opt(fill, fixed_nodes, metric, params.in_plane, params.max_volume);
  if (params.passes <= 0) {
    Optimize3Stats st;
    st.before = st.after = opt.shape();
    return st;
  }
  Optimize3Stats st = opt.run(params.passes, params.on_pass);
  st.after = measure(fill.nodes, fill.simplices, nullptr, opt.metrics(), fixed_nodes);
  return st;
}

}  // namespace plaf::volume
