// SPDX-License-Identifier: MIT
// Exact orientation predicates: a filtered double evaluation, then an exact evaluation with
// floating-point expansions (Shewchuk 1997, cited in the header), and the segment and triangle
// intersection tests built on their signs.
#include "modules/geometry/predicates.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <initializer_list>
#include <limits>

#include <Eigen/Geometry>

namespace plaf {
inline namespace geometry {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// The error-free transformations below need IEEE binary64 with round-to-nearest and no excess
// precision (x87 extended registers would break two_sum).
static_assert(std::numeric_limits<double>::is_iec559, "predicates need IEEE 754 doubles");
static_assert(FLT_EVAL_METHOD == 0, "predicates need double expressions evaluated in double");

constexpr double kEps = 0x1p-53;  // unit roundoff of round-to-nearest

// Forward error bounds of the double evaluations below, relative to the computed permanent (the
// same expression with every product and sum replaced by its absolute value). With
// gamma_k = (1 + eps)^k - 1: each term of orient2d carries 3 roundings (two differences, one
// product), so |computed - exact| <= gamma_3 * permanent before the last subtraction; the last
// subtraction, the evaluation of the permanent (4 roundings) and of the bound itself (2) add
// factors (1 + eps)/(1 - eps)^6, giving 3 eps + 24 eps^2 + O(eps^3) <= (3 + 32 eps) eps. For
// orient3d each triple product carries 6 roundings and the first of the two outer sums one more
// (gamma_7), the permanent 8 and the bound 2: 7 eps + 98 eps^2 + O(eps^3) <= (7 + 128 eps) eps.
constexpr double kOrient2dBound = (3.0 + 32.0 * kEps) * kEps;
constexpr double kOrient3dBound = (7.0 + 128.0 * kEps) * kEps;
// The relative bounds ignore underflow: a product that rounds into the subnormal range has an
// absolute error up to 2^-1075, and in orient3d that error is then multiplied by an outer
// difference. This term (times 1 in orient2d, times 1 + the sum of the outer |differences| in
// orient3d) covers both with a wide margin; results this close to zero take the exact path. It
// is the smallest normal power of two that keeps the term normal: subnormal operands cost
// ~100 cycles each on x86, which made orient3d 3x slower with 2^-1060.
constexpr double kUnderflowBound = 0x1p-1020;

// Knuth's two_sum: s + e == a + b exactly, with s = fl(a + b).
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double b_virtual = s - a;
  const double a_virtual = s - b_virtual;
  e = (a - a_virtual) + (b - b_virtual);
}

// p + e == a * b exactly, with p = fl(a * b) (exact unless e underflows; see the header).
inline void two_product(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// The difference a - b held exactly as the sum of two doubles.
inline std::array<double, 2> exact_diff(double a, double b) {
  std::array<double, 2> d;
  two_sum(a, -b, d[0], d[1]);
  return d;
}

// A nonoverlapping floating-point expansion with components sorted by increasing magnitude and
// no zero components (Shewchuk's expansions): its value is the exact sum of the components, and its
// sign is the sign of the last (largest) component. Each add() grows it by at most one component.
template <int Capacity>
class Expansion {
 public:
  // Shewchuk's Grow-Expansion with zero elimination: adds b exactly. In place: component i is read
  // before slot k <= i is written.
  void add(double b) {
    if (b == 0.0) return;
    assert(n_ < Capacity);
    double q = b;
    int k = 0;
    for (int i = 0; i < n_; ++i) {
      double sum, err;
      two_sum(q, h_[i], sum, err);
      if (err != 0.0) h_[k++] = err;
      q = sum;
    }
    if (q != 0.0) h_[k++] = q;
    n_ = k;
  }

  // Adds a * b exactly (2 components).
  void add_product(double a, double b) {
    if (a == 0.0 || b == 0.0) return;
    double p, e;
    two_product(a, b, p, e);
    add(e);
    add(p);
  }

  // Adds a * b * c exactly (4 components): (p + e) * c with p + e == a * b.
  void add_product(double a, double b, double c) {
    if (a == 0.0 || b == 0.0 || c == 0.0) return;
    double p, e;
    two_product(a, b, p, e);
    add_product(e, c);
    add_product(p, c);
  }

  // A double with exactly the sign of the expansion and close to its value: the sum of the
  // components from the smallest up; in the rare case where rounding loses the sign (the smaller
  // components nearly cancel the largest), the largest component itself.
  double estimate() const {
    if (n_ == 0) return 0.0;
    double sum = 0.0;
    for (int i = 0; i < n_; ++i) sum += h_[i];
    const double top = h_[n_ - 1];
    return (sum > 0.0) == (top > 0.0) && sum != 0.0 ? sum : top;
  }

 private:
  std::array<double, Capacity> h_{};
  int n_ = 0;
};

// The power-of-two exponent that brings the largest |x| into [0.5, 1). Scaling every coordinate by
// 2^shift multiplies a determinant of degree k by the positive factor 2^(k shift), keeps the
// exact stage far from overflow, and is exact within the dynamic range stated in the header.
// Returns false if some coordinate is not finite or all are zero.
bool unit_shift(std::initializer_list<double> coords, int& shift) {
  double max_abs = 0.0;
  for (double x : coords) {
    if (!std::isfinite(x)) return false;
    max_abs = std::max(max_abs, std::abs(x));
  }
  if (max_abs == 0.0) return false;
  shift = -std::ilogb(max_abs) - 1;
  return true;
}

// x -> x 2^shift: one multiplication when 2^shift is a normal double (always, except for inputs
// whose largest magnitude is subnormal), std::ldexp otherwise. Both round the same way.
class PowerOfTwo {
 public:
  explicit PowerOfTwo(int shift)
      : shift_(shift), factor_(shift >= -1022 && shift <= 1023 ? std::ldexp(1.0, shift) : 0.0) {}
  double operator()(double x) const { return factor_ != 0.0 ? x * factor_ : std::ldexp(x, shift_); }

 private:
  int shift_;
  double factor_;
};

bool all_finite(std::initializer_list<double> coords) {
  for (double x : coords)
    if (!std::isfinite(x)) return false;
  return true;
}

// Undoes the scaling of an exact-stage result, keeping its sign even where the true magnitude
// underflows the double range.
double unscale(double value, int exponent) {
  const double r = std::ldexp(value, exponent);
  if (r == 0.0 && value != 0.0) return std::copysign(std::numeric_limits<double>::denorm_min(), value);
  return r;
}

double orient2d_exact(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  int shift = 0;
  if (!unit_shift({a.x(), a.y(), b.x(), b.y(), c.x(), c.y()}, shift)) {
    return all_finite({a.x(), a.y(), b.x(), b.y(), c.x(), c.y()}) ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  }
  const PowerOfTwo s(shift);
  const double ax = s(a.x()), ay = s(a.y());
  const auto bax = exact_diff(s(b.x()), ax), bay = exact_diff(s(b.y()), ay);
  const auto cax = exact_diff(s(c.x()), ax), cay = exact_diff(s(c.y()), ay);
  // bax * cay - bay * cax, every partial product of the two-term differences added exactly.
  Expansion<16> det;
  for (double u : bax)
    for (double v : cay) det.add_product(u, v);
  for (double u : bay)
    for (double v : cax) det.add_product(-u, v);
  return unscale(det.estimate(), -2 * shift);
}

double orient3d_exact(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  int shift = 0;
  if (!unit_shift({a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()}, shift)) {
    return all_finite({a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()})
               ? 0.0
               : std::numeric_limits<double>::quiet_NaN();
  }
  const PowerOfTwo s(shift);
  const double dx = s(d.x()), dy = s(d.y()), dz = s(d.z());
  const auto adx = exact_diff(s(a.x()), dx), ady = exact_diff(s(a.y()), dy), adz = exact_diff(s(a.z()), dz);
  const auto bdx = exact_diff(s(b.x()), dx), bdy = exact_diff(s(b.y()), dy), bdz = exact_diff(s(b.z()), dz);
  const auto cdx = exact_diff(s(c.x()), dx), cdy = exact_diff(s(c.y()), dy), cdz = exact_diff(s(c.z()), dz);
  // The six signed triple products of the cofactor expansion along z (as in orient3d below), each
  // factor a two-term difference: at most 6 * 8 partial products of 4 components each. With exact
  // differences (lo == 0, the usual case for nearby points) only 6 * 4 components are added.
  Expansion<192> det;
  const auto add = [&det](double sign, const std::array<double, 2>& u, const std::array<double, 2>& v,
                          const std::array<double, 2>& w) {
    for (double x : u)
      for (double y : v)
        for (double z : w) det.add_product(sign * x, y, z);
  };
  add(+1.0, adz, bdx, cdy);
  add(-1.0, adz, bdy, cdx);
  add(+1.0, bdz, cdx, ady);
  add(-1.0, bdz, cdy, adx);
  add(+1.0, cdz, adx, bdy);
  add(-1.0, cdz, ady, bdx);
  return unscale(det.estimate(), -3 * shift);
}

int sign_of(double x) {
  return (x > 0.0) - (x < 0.0);
}

// Lexicographic (x, then y, then z) order. On a line it is the order along the line (or its
// reverse), which makes betweenness of collinear points a pair of comparisons.
template <typename Vector>
bool lex_less(const Vector& p, const Vector& q) {
  for (int i = 0; i < p.size(); ++i) {
    if (p[i] != q[i]) return p[i] < q[i];
  }
  return false;
}

template <typename Vector>
const Vector& lex_min(const Vector& p, const Vector& q) {
  return lex_less(q, p) ? q : p;
}

template <typename Vector>
const Vector& lex_max(const Vector& p, const Vector& q) {
  return lex_less(p, q) ? q : p;
}

// Closed segments ab and cd whose four points are known to be collinear share a point.
template <typename Vector>
bool collinear_segments_overlap(const Vector& a, const Vector& b, const Vector& c, const Vector& d) {
  const Vector& lo = lex_less(lex_min(a, b), lex_min(c, d)) ? lex_min(c, d) : lex_min(a, b);
  const Vector& hi = lex_less(lex_max(a, b), lex_max(c, d)) ? lex_max(a, b) : lex_max(c, d);
  return !lex_less(hi, lo);
}

// p with coordinate `axis` dropped (the other two in cyclic order).
Vector2d drop(const Vector3d& p, int axis) {
  return {p[(axis + 1) % 3], p[(axis + 2) % 3]};
}

// An axis whose dropping maps the plane of a, b, c one-to-one onto the remaining coordinate plane
// (the projected triangle is not degenerate, i.e. the plane's normal has a nonzero component on
// that axis), or -1 if a, b, c are collinear. Such a projection is an affine bijection of the
// plane, so it preserves every incidence and intersection question asked within the plane.
int projection_axis(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  // The axis of the normal's largest component (in floating point) first: its projection's
  // orient2d is that component, far from 0 for any triangle that is not nearly collinear, so the
  // filter decides it; the axes in a fixed order (z, y, x) only after. (A triangle in a plane
  // containing the z axis, common on a body's symmetry plane or an extruded section, sent every
  // call through the exact orient2d first: 9 % of a sphere's layer stage, issue 33.)
  if (a == b || b == c || c == a) return -1;  // two vertices in one point: collinear, no need to ask
  const Vector3d n = (b - a).cross(c - a);
  int first = 2;
  if (std::abs(n.y()) > std::abs(n[first])) first = 1;
  if (std::abs(n.x()) > std::abs(n[first])) first = 0;
  if (sign_orient2d(drop(a, first), drop(b, first), drop(c, first)) != 0) return first;
  for (int axis = 2; axis >= 0; --axis) {
    if (axis != first && sign_orient2d(drop(a, axis), drop(b, axis), drop(c, axis)) != 0) return axis;
  }
  return -1;
}

// The closed 2D triangle abc (not degenerate) contains p.
bool triangle_contains_2d(const Vector2d& p, const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const int s1 = sign_orient2d(a, b, p), s2 = sign_orient2d(b, c, p), s3 = sign_orient2d(c, a, p);
  const bool has_neg = s1 < 0 || s2 < 0 || s3 < 0;
  const bool has_pos = s1 > 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

// The closed segments pq and rs in 3D (either may be a point) share a point.
bool segments_intersect_3d(const Vector3d& p, const Vector3d& q, const Vector3d& r, const Vector3d& s) {
  if (sign_orient3d(p, q, r, s) != 0) return false;  // skew lines
  // Coplanar: project along an axis that keeps a non-collinear triple (hence their common plane)
  // one-to-one; if there is none, all four points are collinear.
  for (const std::array<const Vector3d*, 3>& t :
       {std::array{&p, &q, &r}, std::array{&p, &q, &s}, std::array{&r, &s, &p}, std::array{&r, &s, &q}}) {
    const int axis = projection_axis(*t[0], *t[1], *t[2]);
    if (axis >= 0) return segments_intersect(drop(p, axis), drop(q, axis), drop(r, axis), drop(s, axis));
  }
  return collinear_segments_overlap(p, q, r, s);
}

// The closed segment pq (p == q allowed) meets the closed triangle abc (not degenerate).
bool segment_meets_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b,
                            const Vector3d& c) {
  const int sp = sign_orient3d(a, b, c, p), sq = sign_orient3d(a, b, c, q);
  if (sp * sq > 0) return false;  // both strictly on one side of the plane
  if (sp == 0 && sq == 0) {
    // In the plane: a one-to-one projection turns this into the 2D question.
    const int axis = projection_axis(a, b, c);
    const Vector2d p2 = drop(p, axis), q2 = drop(q, axis);
    const Vector2d a2 = drop(a, axis), b2 = drop(b, axis), c2 = drop(c, axis);
    return triangle_contains_2d(p2, a2, b2, c2) || triangle_contains_2d(q2, a2, b2, c2) ||
           segments_intersect(p2, q2, a2, b2) || segments_intersect(p2, q2, b2, c2) ||
           segments_intersect(p2, q2, c2, a2);
  }
  // The line pq crosses the plane at one point X of the closed segment. Writing p = X + s w and
  // q = X + t w, orient3d(p, q, a, b) = (s - t) det[w, X - b, a - b], whose sign is a factor
  // common to the three edges times the in-plane orientation of X against edge ab; so X lies in
  // the closed triangle iff the three signs are not of both strict kinds.
  const int s1 = sign_orient3d(p, q, a, b), s2 = sign_orient3d(p, q, b, c), s3 = sign_orient3d(p, q, c, a);
  const bool has_neg = s1 < 0 || s2 < 0 || s3 < 0;
  const bool has_pos = s1 > 0 || s2 > 0 || s3 > 0;
  return !(has_neg && has_pos);
}

// A closed 3D triangle with collinear vertices is the segment between its lexicographic extremes
// (a point if they coincide).
std::array<Vector3d, 2> degenerate_hull(const Vector3d* t) {
  const Vector3d& lo = lex_min(lex_min(t[0], t[1]), t[2]);
  const Vector3d& hi = lex_max(lex_max(t[0], t[1]), t[2]);
  return {lo, hi};
}

// All three vertices of t lie strictly on one side of the plane of u (u not degenerate).
bool strictly_one_side(const Vector3d* u, const Vector3d* t) {
  const int s0 = sign_orient3d(u[0], u[1], u[2], t[0]);
  const int s1 = sign_orient3d(u[0], u[1], u[2], t[1]);
  const int s2 = sign_orient3d(u[0], u[1], u[2], t[2]);
  return s0 != 0 && s0 == s1 && s1 == s2;
}

}  // namespace

double orient2d(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const double bax = b.x() - a.x(), bay = b.y() - a.y();
  const double cax = c.x() - a.x(), cay = c.y() - a.y();
  const double left = bax * cay, right = bay * cax;
  const double det = left - right;
  // Overflow makes det or the bound inf or NaN, and the comparison false. One comparison of |det|,
  // not two of det, keeps the branch predictable when the signs are random.
  const double bound = kOrient2dBound * (std::abs(left) + std::abs(right)) + kUnderflowBound;
  if (std::abs(det) > bound) return det;
  // Two points in one (exactly, finite): the determinant is 0, no need for the exact sum (a
  // triangle pair sharing a vertex, or a front triangle of a collapsed column: issue 33).
  if ((a == b || b == c || c == a) && std::isfinite(det)) return 0.0;
  return orient2d_exact(a, b, c);
}

double orient3d(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  const double adx = a.x() - d.x(), ady = a.y() - d.y(), adz = a.z() - d.z();
  const double bdx = b.x() - d.x(), bdy = b.y() - d.y(), bdz = b.z() - d.z();
  const double cdx = c.x() - d.x(), cdy = c.y() - d.y(), cdz = c.z() - d.z();
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  // Cofactor expansion of det [a - d; b - d; c - d] along the z column.
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double abs_adz = std::abs(adz), abs_bdz = std::abs(bdz), abs_cdz = std::abs(cdz);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * abs_adz +
                           (std::abs(cdxady) + std::abs(adxcdy)) * abs_bdz +
                           (std::abs(adxbdy) + std::abs(bdxady)) * abs_cdz;
  const double bound = kOrient3dBound * permanent + kUnderflowBound * (abs_adz + abs_bdz + abs_cdz + 1.0);
  if (std::abs(det) > bound) return det;
  if ((a == b || a == c || a == d || b == c || b == d || c == d) && std::isfinite(det)) return 0.0;  // as orient2d
  return orient3d_exact(a, b, c, d);
}

int sign_orient2d(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return sign_of(orient2d(a, b, c));
}

int sign_orient3d(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  return sign_of(orient3d(a, b, c, d));
}

bool segments_cross_properly(const Vector2d& a, const Vector2d& b, const Vector2d& c, const Vector2d& d) {
  const int abc = sign_orient2d(a, b, c), abd = sign_orient2d(a, b, d);
  if (abc * abd >= 0) return false;
  const int cda = sign_orient2d(c, d, a), cdb = sign_orient2d(c, d, b);
  return cda * cdb < 0;
}

bool segments_intersect(const Vector2d& a, const Vector2d& b, const Vector2d& c, const Vector2d& d) {
  const int abc = sign_orient2d(a, b, c), abd = sign_orient2d(a, b, d);
  if (abc * abd > 0) return false;  // c and d strictly on one side of line ab
  const int cda = sign_orient2d(c, d, a), cdb = sign_orient2d(c, d, b);
  if (cda * cdb > 0) return false;
  // abc == abd == 0 forces cda == cdb == 0 and conversely (if c != d, line cd is line ab; if
  // c == d, cda and cdb vanish): either all four points are collinear, or the segments' lines meet
  // at one point, which both closed segments contain.
  if (abc == 0 && abd == 0 && cda == 0 && cdb == 0) return collinear_segments_overlap(a, b, c, d);
  return true;
}

bool point_on_open_segment(const Vector2d& p, const Vector2d& a, const Vector2d& b) {
  if (sign_orient2d(a, b, p) != 0) return false;
  return lex_less(lex_min(a, b), p) && lex_less(p, lex_max(a, b));
}

bool triangles_intersect(const Vector3d* t1, const Vector3d* t2) {
  const bool flat1 = projection_axis(t1[0], t1[1], t1[2]) < 0;
  const bool flat2 = projection_axis(t2[0], t2[1], t2[2]) < 0;
  if (flat1 && flat2) {
    const auto h1 = degenerate_hull(t1), h2 = degenerate_hull(t2);
    return segments_intersect_3d(h1[0], h1[1], h2[0], h2[1]);
  }
  if (flat1 || flat2) {
    const Vector3d* tri = flat1 ? t2 : t1;
    const auto h = degenerate_hull(flat1 ? t1 : t2);
    return segment_meets_triangle(h[0], h[1], tri[0], tri[1], tri[2]);
  }
  if (strictly_one_side(t1, t2) || strictly_one_side(t2, t1)) return false;
  // Two closed convex sets meet iff the relative boundary of one meets the other: for
  // non-coplanar triangles both cut the line of the two planes in intervals whose endpoints lie on
  // the edges, and two intervals meet iff one contains an endpoint of the other; for coplanar
  // ones, a path inside one triangle from a common point leaves the other across its boundary,
  // unless it is contained, and then its own edges lie in the other.
  for (int i = 0; i < 3; ++i) {
    if (segment_meets_triangle(t1[i], t1[(i + 1) % 3], t2[0], t2[1], t2[2])) return true;
    if (segment_meets_triangle(t2[i], t2[(i + 1) % 3], t1[0], t1[1], t1[2])) return true;
  }
  return false;
}

bool inside_polygon(const Eigen::Vector2d& x, const std::vector<Eigen::Vector2d>& polygon) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < a.x() + (x.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
      inside = !inside;
  }
  return inside;
}

}  // namespace geometry
}  // namespace plaf
