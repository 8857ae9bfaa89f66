// SPDX-License-Identifier: MIT
// Implements the boundary geometry of K. J. Fidkowski, *Anisotropic Metric-Based Curved Meshing
// Using Prismatic Layers*, Sec. II.B: "clockwise loops of cubic splines, with corners allowed".
// Conventions are in spline_loop.h.
//
// Construction: every corner-to-corner run is interpolated in its chord-length parameter s by a
// C2 cubic spline with not-a-knot ends (de Boor, A Practical Guide to Splines, ch. IV, the slope
// form of the interpolation equations); a loop without corners is a periodic C2 spline. Piece i
// is then re-parametrised linearly by u = (s - s_i) / h_i in [0, 1], which keeps it a cubic and
// gives t = i + u.
#include "modules/geometry/spline_loop.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>

#include "modules/base/error.h"
#include "modules/metric/metric.h"

namespace plaf {
inline namespace geometry {

using Eigen::Vector2d;
using Piece = std::array<Vector2d, 4>;

namespace {

// Two points closer than this, relative to the loop's bounding-box diagonal, coincide.
constexpr double coincident_rel = 1e-13;
// The adaptive Gauss-Legendre arc length stops when the 8- and 16-point rules agree to this
// relative difference (the 16-point value is then accurate far beyond it).
constexpr double quadrature_rel = 1e-13;
constexpr int quadrature_max_depth = 30;
// The closest-point Newton iteration on a piece (u in [0, 1]) stops when its step is this small.
constexpr double newton_step_tol = 4 * std::numeric_limits<double>::epsilon();

double cross(const Vector2d& a, const Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Vector2d eval(const Piece& c, double u) {
  return c[0] + u * (c[1] + u * (c[2] + u * c[3]));
}
Vector2d eval_d1(const Piece& c, double u) {
  return c[1] + u * (2.0 * c[2] + u * (3.0 * c[3]));
}
Vector2d eval_d2(const Piece& c, double u) {
  return 2.0 * c[2] + (6.0 * u) * c[3];
}

// Tridiagonal solve (Thomas algorithm): sub[k] x[k-1] + diag[k] x[k] + super[k] x[k+1] = rhs[k].
// The systems here are diagonally dominant except for the not-a-knot end rows, whose first
// elimination step is exact (see run_slopes), so no pivoting is needed.
template <class T>
std::vector<T> solve_tridiagonal(const std::vector<double>& sub, std::vector<double> diag,
                                 const std::vector<double>& super, std::vector<T> rhs) {
  const size_t n = diag.size();
  for (size_t k = 1; k < n; ++k) {
    const double w = sub[k] / diag[k - 1];
    diag[k] -= w * super[k - 1];
    rhs[k] = rhs[k] - w * rhs[k - 1];
  }
  rhs[n - 1] = rhs[n - 1] / diag[n - 1];
  for (size_t k = n - 1; k-- > 0;) rhs[k] = (rhs[k] - super[k] * rhs[k + 1]) / diag[k];
  return rhs;
}

// Cyclic tridiagonal solve by Sherman-Morrison (Press et al., Numerical Recipes, Sec. 2.7):
// row 0 also has sub[0] at column n-1 and row n-1 has super[n-1] at column 0. Needs n >= 3.
std::vector<Vector2d> solve_cyclic(const std::vector<double>& sub, const std::vector<double>& diag,
                                   const std::vector<double>& super, const std::vector<Vector2d>& rhs) {
  const size_t n = diag.size();
  const double corner_top = sub[0];           // A(0, n-1)
  const double corner_bottom = super[n - 1];  // A(n-1, 0)
  const double gamma = -diag[0];
  std::vector<double> d = diag;
  d[0] -= gamma;
  d[n - 1] -= corner_bottom * corner_top / gamma;
  const std::vector<Vector2d> x = solve_tridiagonal(sub, d, super, rhs);
  std::vector<double> v(n, 0.0);
  v[0] = gamma;
  v[n - 1] = corner_bottom;
  const std::vector<double> z = solve_tridiagonal(sub, d, super, v);
  const Vector2d factor = (x[0] + corner_top * x[n - 1] / gamma) / (1.0 + z[0] + corner_top * z[n - 1] / gamma);
  std::vector<Vector2d> out(n);
  for (size_t k = 0; k < n; ++k) out[k] = x[k] - z[k] * factor;
  return out;
}

// Slopes d q / d s at the knots q_0..q_m of one corner-to-corner run (m pieces, chords h_k).
std::vector<Vector2d> run_slopes(const std::vector<Vector2d>& q, const std::vector<double>& h) {
  const size_t m = h.size();
  std::vector<Vector2d> delta(m);
  for (size_t k = 0; k < m; ++k) delta[k] = (q[k + 1] - q[k]) / h[k];
  if (m == 1) return {delta[0], delta[0]};  // a straight segment
  if (m == 2) {
    // Not-a-knot with one interior knot: the parabola through the three points.
    const Vector2d second = (delta[1] - delta[0]) / (h[0] + h[1]);
    return {delta[0] - h[0] * second, delta[0] + h[0] * second, delta[0] + (h[0] + 2.0 * h[1]) * second};
  }
  std::vector<double> sub(m + 1, 0.0), diag(m + 1), super(m + 1, 0.0);
  std::vector<Vector2d> rhs(m + 1);
  // Not-a-knot at q_1 (third derivative continuous), with the slope at q_2 eliminated by the
  // interior equation of q_1 (MATLAB's spline.m writes the same row).
  diag[0] = h[1];
  super[0] = h[0] + h[1];
  rhs[0] = ((3.0 * h[0] + 2.0 * h[1]) * h[1] * delta[0] + h[0] * h[0] * delta[1]) / (h[0] + h[1]);
  // Interior knots: second derivative continuous.
  for (size_t k = 1; k < m; ++k) {
    sub[k] = h[k];
    diag[k] = 2.0 * (h[k - 1] + h[k]);
    super[k] = h[k - 1];
    rhs[k] = 3.0 * (h[k] * delta[k - 1] + h[k - 1] * delta[k]);
  }
  // Not-a-knot at q_{m-1}, mirrored.
  sub[m] = h[m - 2] + h[m - 1];
  diag[m] = h[m - 2];
  rhs[m] = (h[m - 1] * h[m - 1] * delta[m - 2] + (2.0 * h[m - 2] + 3.0 * h[m - 1]) * h[m - 2] * delta[m - 1]) /
           (h[m - 2] + h[m - 1]);
  return solve_tridiagonal(sub, diag, super, rhs);
}

// Slopes d p / d s at every point of a loop without corners (periodic C2 spline).
std::vector<Vector2d> periodic_slopes(const std::vector<Vector2d>& p, const std::vector<double>& h) {
  const size_t n = p.size();
  std::vector<double> sub(n), diag(n), super(n);
  std::vector<Vector2d> rhs(n);
  for (size_t k = 0; k < n; ++k) {
    const size_t prev = (k + n - 1) % n;
    const Vector2d delta_prev = (p[k] - p[prev]) / h[prev];
    const Vector2d delta = (p[(k + 1) % n] - p[k]) / h[k];
    sub[k] = h[k];
    diag[k] = 2.0 * (h[prev] + h[k]);
    super[k] = h[prev];
    rhs[k] = 3.0 * (h[k] * delta_prev + h[prev] * delta);
  }
  return solve_cyclic(sub, diag, super, rhs);
}

// Cubic Hermite piece in u in [0,1] from its end points and chord-parameter slopes.
Piece hermite(const Vector2d& p0, const Vector2d& p1, const Vector2d& slope0, const Vector2d& slope1, double h) {
  const Vector2d t0 = h * slope0, t1 = h * slope1;
  return {p0, t0, 3.0 * (p1 - p0) - 2.0 * t0 - t1, 2.0 * (p0 - p1) + t0 + t1};
}

struct GaussRules {
  std::array<double, 8> x8{}, w8{};
  std::array<double, 16> x16{}, w16{};
};
const GaussRules& gauss_rules() {
  static const GaussRules rules = [] {
    GaussRules r;
    gauss_legendre_01(8, r.x8.data(), r.w8.data());
    gauss_legendre_01(16, r.x16.data(), r.w16.data());
    return r;
  }();
  return rules;
}

// Integral of |p'(u)| over [u0, u1], adaptive bisection on the 8/16-point Gauss-Legendre pair.
double integrate_speed(const Piece& c, double u0, double u1, int depth = 0) {
  const GaussRules& g = gauss_rules();
  const double w = u1 - u0;
  double coarse = 0.0, fine = 0.0;
  for (size_t k = 0; k < 8; ++k) coarse += g.w8[k] * eval_d1(c, u0 + w * g.x8[k]).norm();
  for (size_t k = 0; k < 16; ++k) fine += g.w16[k] * eval_d1(c, u0 + w * g.x16[k]).norm();
  coarse *= w;
  fine *= w;
  if (std::abs(fine - coarse) <= quadrature_rel * fine || depth >= quadrature_max_depth) return fine;
  const double mid = 0.5 * (u0 + u1);
  return integrate_speed(c, u0, mid, depth + 1) + integrate_speed(c, mid, u1, depth + 1);
}

// Bernstein coefficients of a quintic on a sub-interval, split at its midpoint (de Casteljau).
using Quintic = std::array<double, 6>;
std::pair<Quintic, Quintic> split_half(const Quintic& b) {
  Quintic left{}, right{};
  Quintic w = b;
  for (int level = 0; level < 6; ++level) {
    left[level] = w[0];
    right[5 - level] = w[5 - level];
    for (int k = 0; k < 5 - level; ++k) w[k] = 0.5 * (w[k] + w[k + 1]);
  }
  return {left, right};
}

// Power to Bernstein basis of degree 5: b_k = sum_{j<=k} C(k,j)/C(5,j) a_j.
Quintic bernstein_from_power(const Quintic& power) {
  static constexpr std::array<std::array<double, 6>, 6> binom = {{{1, 0, 0, 0, 0, 0},
                                                                  {1, 1, 0, 0, 0, 0},
                                                                  {1, 2, 1, 0, 0, 0},
                                                                  {1, 3, 3, 1, 0, 0},
                                                                  {1, 4, 6, 4, 1, 0},
                                                                  {1, 5, 10, 10, 5, 1}}};
  Quintic bern{};
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j <= k; ++j) bern[k] += binom[k][j] / binom[5][j] * power[j];
  return bern;
}

// The root of f in [lo, hi], where f changes sign once and has the sign f_lo_sign at lo:
// safeguarded Newton (a bisection step whenever Newton leaves the bracket).
template <class F, class DF>
double bracketed_root(double lo, double hi, double f_lo_sign, const F& f, const DF& df) {
  double u = 0.5 * (lo + hi);
  for (int iter = 0; iter < 100; ++iter) {
    const double fu = f(u);
    if (fu == 0.0) break;
    if ((fu > 0) == (f_lo_sign > 0))
      lo = u;
    else
      hi = u;
    const double d = df(u);
    // Converged: Newton approaches the root from one side, so the bracket need not shrink;
    // without this stop, rounding noise in f later sends the step out of the bracket and
    // the bisection fallback restarts from the bracket's far end.
    if (d != 0.0 && std::abs(fu / d) <= newton_step_tol) break;
    double next = d != 0.0 ? u - fu / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == u || hi - lo <= 2.0 * std::numeric_limits<double>::epsilon()) break;
    u = next;
  }
  return u;
}

// The roots in [0, 1] of the quintic f with Bernstein coefficients bern (df its derivative):
// root isolation by Bernstein subdivision (Descartes' rule of signs on the coefficients), then
// bracketed_root on each isolated root. Split points (a root may lie exactly on one) and
// intervals too small to split are returned as candidates too.
template <class F, class DF>
std::vector<double> quintic_roots_01(const Quintic& bern, const F& f, const DF& df) {
  std::vector<double> roots;
  struct Interval {
    double lo, hi;
    Quintic b;
    int depth;
  };
  std::vector<Interval> stack = {{0.0, 1.0, bern, 0}};
  while (!stack.empty()) {
    const Interval iv = stack.back();
    stack.pop_back();
    int changes = 0;
    double last_sign = 0.0;
    for (double b : iv.b) {
      if (b == 0.0) continue;
      const double sign = b > 0 ? 1.0 : -1.0;
      if (last_sign != 0.0 && sign != last_sign) ++changes;
      last_sign = sign;
    }
    if (changes == 0) continue;
    if (changes == 1 && iv.b[0] * iv.b[5] < 0.0) {
      roots.push_back(bracketed_root(iv.lo, iv.hi, iv.b[0] > 0 ? 1.0 : -1.0, f, df));
      continue;
    }
    if (iv.depth >= 50 || iv.hi - iv.lo <= 1e-14) {
      roots.push_back(0.5 * (iv.lo + iv.hi));
      continue;
    }
    const auto [left, right] = split_half(iv.b);
    const double mid = 0.5 * (iv.lo + iv.hi);
    roots.push_back(mid);  // a root exactly at the split point
    stack.push_back({iv.lo, mid, left, iv.depth + 1});
    stack.push_back({mid, iv.hi, right, iv.depth + 1});
  }
  return roots;
}

}  // namespace

// Bounding-volume hierarchy over runs of consecutive pieces. Each node bounds the Bezier control
// points of its run, hence the run itself (convex hull property), by a box aligned with the
// run's chord. The box is then only as thick as the run's sagitta (second order in its length),
// unlike an axis-aligned box whose slack is first order for oblique runs: that slack lets
// best-first search visit O(sqrt(n)) leaves for queries away from the curve instead of O(log n).
struct SplineLoop::Tree {
  struct Node {
    Vector2d axis{1.0, 0.0};  // unit chord direction; the box is [lo, hi] in (axis, left normal)
    Vector2d lo, hi;
    int child[2] = {-1, -1};
    int piece = -1;  // leaves only
    double squared_distance(const Vector2d& x) const {
      const Vector2d local(x.dot(axis), cross(axis, x));
      return (lo - local).cwiseMax(local - hi).cwiseMax(0.0).squaredNorm();
    }
  };
  std::vector<Node> nodes;  // nodes[0] is the root

  // control: the Bezier control points of the pieces in order, 3 per piece plus the closing p_0.
  int build(const std::vector<Vector2d>& control, int begin, int end) {
    const int id = static_cast<int>(nodes.size());
    nodes.emplace_back();
    const Vector2d chord = control[3 * static_cast<size_t>(end)] - control[3 * static_cast<size_t>(begin)];
    Node node;
    if (chord.norm() > 0.0) node.axis = chord.normalized();
    node.lo = Vector2d::Constant(std::numeric_limits<double>::infinity());
    node.hi = -node.lo;
    for (size_t k = 3 * static_cast<size_t>(begin); k <= 3 * static_cast<size_t>(end); ++k) {
      const Vector2d local(control[k].dot(node.axis), cross(node.axis, control[k]));
      node.lo = node.lo.cwiseMin(local);
      node.hi = node.hi.cwiseMax(local);
    }
    if (end - begin == 1) {
      node.piece = begin;
    } else {
      const int mid = (begin + end) / 2;
      node.child[0] = build(control, begin, mid);
      node.child[1] = build(control, mid, end);
    }
    nodes[id] = node;
    return id;
  }
};

SplineLoop::SplineLoop(std::vector<Eigen::Vector2d> points, std::vector<int> corners, std::string name)
    : name_(std::move(name)), points_(std::move(points)), corners_(std::move(corners)) {
  const int n = num_points();
  if (n < 3) throw InputError(name_ + ": a spline loop needs at least 3 points, got " + std::to_string(n));
  Eigen::AlignedBox2d box;
  for (int i = 0; i < n; ++i) {
    if (!points_[i].allFinite()) throw InputError(name_ + ": point " + std::to_string(i) + " is not finite");
    box.extend(points_[i]);
  }
  const double coincident_abs = coincident_rel * box.diagonal().norm();
  std::vector<double> h(n);
  for (int i = 0; i < n; ++i) {
    h[i] = (points_[(i + 1) % n] - points_[i]).norm();
    if (!(h[i] > coincident_abs))
      throw InputError(name_ + ": points " + std::to_string(i) + " and " + std::to_string((i + 1) % n) + " coincide");
  }
  for (size_t k = 0; k < corners_.size(); ++k) {
    if (corners_[k] < 0 || corners_[k] >= n || (k > 0 && corners_[k] <= corners_[k - 1]))
      throw InputError(name_ + ": corner indices must be sorted, unique and in [0, " + std::to_string(n) + ")");
  }

  // Chord-parameter slopes at the start and the end of every piece (they differ at corners).
  std::vector<Vector2d> slope_start(n), slope_end(n);
  if (corners_.empty()) {
    const std::vector<Vector2d> s = periodic_slopes(points_, h);
    for (int i = 0; i < n; ++i) {
      slope_start[i] = s[i];
      slope_end[i] = s[(i + 1) % n];
    }
  } else {
    const int num_corners = static_cast<int>(corners_.size());
    for (int j = 0; j < num_corners; ++j) {
      const int first = corners_[j];
      const int pieces = j + 1 < num_corners ? corners_[j + 1] - first : corners_[0] + n - first;
      std::vector<Vector2d> q(pieces + 1);
      std::vector<double> hr(pieces);
      for (int r = 0; r <= pieces; ++r) q[r] = points_[(first + r) % n];
      for (int r = 0; r < pieces; ++r) hr[r] = h[(first + r) % n];
      const std::vector<Vector2d> s = run_slopes(q, hr);
      for (int r = 0; r < pieces; ++r) {
        slope_start[(first + r) % n] = s[r];
        slope_end[(first + r) % n] = s[r + 1];
      }
    }
  }
  coeffs_.resize(n);
  for (int i = 0; i < n; ++i)
    coeffs_[i] = hermite(points_[i], points_[(i + 1) % n], slope_start[i], slope_end[i], h[i]);

  cumulative_length_.assign(n + 1, 0.0);
  for (int i = 0; i < n; ++i) cumulative_length_[i + 1] = cumulative_length_[i] + integrate_speed(coeffs_[i], 0.0, 1.0);

  std::vector<Vector2d> control(3 * static_cast<size_t>(n) + 1);
  for (int i = 0; i < n; ++i) {
    const Piece& c = coeffs_[i];
    control[3 * i] = c[0];
    control[3 * i + 1] = c[0] + c[1] / 3.0;
    control[3 * i + 2] = c[0] + (2.0 * c[1] + c[2]) / 3.0;
  }
  control[3 * static_cast<size_t>(n)] = points_[0];
  auto tree = std::make_shared<Tree>();
  tree->nodes.reserve(2 * static_cast<size_t>(n));
  tree->build(control, 0, n);
  tree_ = std::move(tree);
}

std::pair<int, double> SplineLoop::locate(double t) const {
  const double n = period();
  double w = std::fmod(t, n);
  if (w < 0) w += n;
  if (w >= n) w = 0.0;
  const int i = std::min(static_cast<int>(w), num_points() - 1);
  return {i, w - i};
}

Eigen::Vector2d SplineLoop::point(double t) const {
  const auto [i, u] = locate(t);
  return eval(coeffs_[i], u);
}

Eigen::Vector2d SplineLoop::derivative(double t) const {
  const auto [i, u] = locate(t);
  return eval_d1(coeffs_[i], u);
}

Eigen::Vector2d SplineLoop::tangent(double t) const {
  return derivative(t).normalized();
}

Eigen::Vector2d SplineLoop::normal(double t) const {
  const Vector2d e = tangent(t);
  return {-e.y(), e.x()};
}

double SplineLoop::curvature(double t) const {
  const auto [i, u] = locate(t);
  const Vector2d d1 = eval_d1(coeffs_[i], u), d2 = eval_d2(coeffs_[i], u);
  return cross(d1, d2) / std::pow(d1.norm(), 3);
}

double SplineLoop::length_to(int piece, double u) const {
  return cumulative_length_[piece] + (u > 0.0 ? integrate_speed(coeffs_[piece], 0.0, u) : 0.0);
}

double SplineLoop::arc_length(double t0, double t1) const {
  if (t1 < t0) return -arc_length(t1, t0);
  const int n = num_points();
  const double total = cumulative_length_[n];
  const double periods = std::floor((t1 - t0) / period());
  const auto [i0, u0] = locate(t0);
  // Unwrapped end point relative to the start piece: piece index i1 may reach 2n - 1.
  const double span = (t1 - t0) - periods * period();  // in [0, period())
  const double w1 = (i0 + u0) + span;
  int i1 = static_cast<int>(std::floor(w1));
  double u1 = w1 - i1;
  if (i1 >= 2 * n) {  // rounding at the very end of the second lap
    i1 = 2 * n - 1;
    u1 = 1.0;
  }
  double s;
  if (i1 == i0) {
    s = integrate_speed(coeffs_[i0], u0, std::max(u0, u1));
  } else {
    const auto cum = [&](int k) { return k >= n ? total + cumulative_length_[k - n] : cumulative_length_[k]; };
    s = integrate_speed(coeffs_[i0], u0, 1.0) + (cum(i1) - cum(i0 + 1)) +
        (u1 > 0.0 ? integrate_speed(coeffs_[i1 % n], 0.0, u1) : 0.0);
  }
  return periods * total + s;
}

double SplineLoop::parameter_at(double t0, double s) const {
  if (s == 0.0) return t0;
  const int n = num_points();
  const double total = cumulative_length_[n];
  const auto [i0, u0] = locate(t0);
  const double base = t0 - (i0 + u0);  // t0 minus its position in [0, n)
  const double target = length_to(i0, u0) + s;
  const double laps = std::floor(target / total);
  double rest = target - laps * total;
  rest = std::clamp(rest, 0.0, total);
  // The piece holding arc position `rest`, then safeguarded Newton on its length function.
  const auto it = std::upper_bound(cumulative_length_.begin(), cumulative_length_.end(), rest);
  const int i = std::clamp(static_cast<int>(it - cumulative_length_.begin()) - 1, 0, n - 1);
  const Piece& c = coeffs_[i];
  const double want = rest - cumulative_length_[i];
  const double piece_length = cumulative_length_[i + 1] - cumulative_length_[i];
  double lo = 0.0, hi = 1.0;
  double u = std::clamp(want / piece_length, 0.0, 1.0);
  for (int iter = 0; iter < 100; ++iter) {
    const double g = integrate_speed(c, 0.0, u) - want;
    if (g > 0)
      hi = u;
    else
      lo = u;
    if (std::abs(g) <= 4.0 * std::numeric_limits<double>::epsilon() * piece_length) break;
    double next = u - g / eval_d1(c, u).norm();
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() || next == u) {
      u = next;
      break;
    }
    u = next;
  }
  const double t = base + laps * period() + i + u;
  return s > 0 ? std::max(t, t0) : std::min(t, t0);
}

double SplineLoop::signed_area() const {
  // Shoelace formula over the polygon of the interpolated points.
  const int n = num_points();
  double twice = 0.0;
  for (int i = 0; i < n; ++i) twice += cross(points_[i], points_[(i + 1) % n]);
  return 0.5 * twice;
}

SplineLoop::Closest SplineLoop::closest_point_on_piece(int piece, const Eigen::Vector2d& x) const {
  const Piece& c = coeffs_[piece];
  // f(u) = (p(u) - x) . p'(u) vanishes at every interior critical point of the squared distance.
  const auto f = [&](double u) { return (eval(c, u) - x).dot(eval_d1(c, u)); };
  const auto df = [&](double u) {
    const Vector2d d1 = eval_d1(c, u);
    return d1.squaredNorm() + (eval(c, u) - x).dot(eval_d2(c, u));
  };
  const Vector2d e = c[0] - x;
  const Quintic power = {e.dot(c[1]),
                         2.0 * e.dot(c[2]) + c[1].squaredNorm(),
                         3.0 * e.dot(c[3]) + 3.0 * c[1].dot(c[2]),
                         4.0 * c[1].dot(c[3]) + 2.0 * c[2].squaredNorm(),
                         5.0 * c[2].dot(c[3]),
                         3.0 * c[3].squaredNorm()};
  // The squared distance is critical at the ends and at the roots of f.
  std::vector<double> candidates = {0.0, 1.0};
  const std::vector<double> roots = quintic_roots_01(bernstein_from_power(power), f, df);
  candidates.insert(candidates.end(), roots.begin(), roots.end());

  Closest best{0.0, c[0], std::numeric_limits<double>::infinity()};
  for (double u : candidates) {
    const Vector2d p = eval(c, u);
    const double d = (p - x).norm();
    if (d < best.distance) best = {u, p, d};
  }
  best.t = piece + best.t;
  if (best.t >= period()) best.t -= period();
  return best;
}

SplineLoop::Closest SplineLoop::closest_point(const Eigen::Vector2d& x) const {
  // Best-first descent: a box farther than the best distance so far cannot hold a closer point.
  using Entry = std::pair<double, int>;  // squared box distance, node
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  const auto& nodes = tree_->nodes;
  queue.emplace(nodes[0].squared_distance(x), 0);
  Closest best{0.0, points_[0], std::numeric_limits<double>::infinity()};
  double best_sq = std::numeric_limits<double>::infinity();
  while (!queue.empty()) {
    const auto [dist_sq, id] = queue.top();
    queue.pop();
    if (dist_sq >= best_sq) break;
    const Tree::Node& node = nodes[id];
    if (node.piece >= 0) {
      const Closest c = closest_point_on_piece(node.piece, x);
      if (c.distance < best.distance) {
        best = c;
        best_sq = c.distance * c.distance;
      }
      continue;
    }
    for (int child : node.child) {
      const double d = nodes[child].squared_distance(x);
      if (d < best_sq) queue.emplace(d, child);
    }
  }
  return best;
}

double turning_angle(const std::vector<Eigen::Vector2d>& points, int i) {
  const int n = static_cast<int>(points.size());
  const Vector2d in = points[i] - points[(i + n - 1) % n];
  const Vector2d out = points[(i + 1) % n] - points[i];
  return std::atan2(cross(in, out), in.dot(out));
}

std::vector<int> detect_corners(const std::vector<Eigen::Vector2d>& points, double threshold_deg) {
  const double threshold = threshold_deg * M_PI / 180.0;
  std::vector<int> corners;
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    if (std::abs(turning_angle(points, i)) > threshold) corners.push_back(i);
  return corners;
}

}  // namespace geometry
}  // namespace plaf
