// SPDX-License-Identifier: MIT
// Exact predicates: signs checked against exact integer arithmetic (__int128) on inputs built to
// be (near-)degenerate, where plain double evaluation is known to fail, and the intersection tests
// against hand-made cases and a brute-force separating-axis reference.
#include "modules/geometry/predicates.h"

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

using namespace plaf;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

// GCC/Clang's 128-bit integer (__extension__ silences -Wpedantic): exact for the references below.
__extension__ typedef __int128 Int;

int sign_of(Int x) {
  return (x > 0) - (x < 0);
}

// The plain double formula, each rounding forced (volatile) so that no FMA contraction hides the
// failures these tests rely on.
double naive_orient2d(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  volatile double left = (b.x() - a.x()) * (c.y() - a.y());
  volatile double right = (b.y() - a.y()) * (c.x() - a.x());
  return left - right;
}

double naive_orient3d(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  const Vector3d ad = a - d, bd = b - d, cd = c - d;
  volatile double p1 = bd.x() * cd.y(), p2 = cd.x() * bd.y();
  volatile double p3 = cd.x() * ad.y(), p4 = ad.x() * cd.y();
  volatile double p5 = ad.x() * bd.y(), p6 = bd.x() * ad.y();
  volatile double t1 = ad.z() * (p1 - p2), t2 = bd.z() * (p3 - p4), t3 = cd.z() * (p5 - p6);
  return t1 + t2 + t3;
}

// Exact orient2d of integer points (|coordinates| < 2^62 keeps every product in range).
int exact_sign2(const std::array<Int, 2>& a, const std::array<Int, 2>& b, const std::array<Int, 2>& c) {
  return sign_of((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

// Exact orient3d = det [a - d; b - d; c - d] of integer points (|coordinates| < 2^41).
int exact_sign3(const std::array<Int, 3>& a, const std::array<Int, 3>& b, const std::array<Int, 3>& c,
                const std::array<Int, 3>& d) {
  const Int adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  const Int bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  const Int cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  return sign_of(adz * (bdx * cdy - bdy * cdx) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - ady * bdx));
}

// A random double in [0.5, 1) with `bits` significant bits, i.e. a multiple of 2^-bits.
double random_unit(std::mt19937_64& rng, int bits) {
  std::uniform_int_distribution<std::int64_t> n(std::int64_t{1} << (bits - 1), (std::int64_t{1} << bits) - 1);
  return std::ldexp(static_cast<double>(n(rng)), -bits);
}

// x moved by k units of its last place.
double nudge_ulps(double x, int k) {
  for (; k > 0; --k) x = std::nextafter(x, 1e300);
  for (; k < 0; ++k) x = std::nextafter(x, -1e300);
  return x;
}

// x * 2^unit_log2 as an exact integer (x must be a multiple of 2^-unit_log2).
Int scaled_int(double x, int unit_log2) {
  const double n = std::ldexp(x, unit_log2);
  REQUIRE(n == std::floor(n));
  REQUIRE(std::abs(n) < 0x1p62);
  return static_cast<Int>(static_cast<std::int64_t>(n));
}

// Parity of a permutation given as indices.
template <std::size_t N>
int parity(const std::array<int, N>& perm) {
  int inversions = 0;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j) inversions += perm[i] > perm[j];
  return inversions % 2 == 0 ? 1 : -1;
}

}  // namespace

TEST_CASE("predicates: orient2d on the grid around (0.5, 0.5) is exact where the plain formula fails") {
  // Kettner et al., "Classroom examples of robustness problems in geometric computations", CGTA 40
  // (2008), Fig. 1: p = (0.5 + i u, 0.5 + j u), u = 2^-53, against q = (12, 12) and r = (24, 24).
  // orient2d(p, q, r) = (r - q) (py - px) = 12 (j - i) u, so the exact sign is sign(j - i).
  const double u = 0x1p-53;
  const Vector2d q(12, 12), r(24, 24);
  int naive_wrong = 0;
  for (int i = 0; i < 256; ++i) {
    for (int j = 0; j < 256; ++j) {
      const Vector2d p(0.5 + i * u, 0.5 + j * u);
      const int expected = (j > i) - (j < i);
      // The same with __int128 on the coordinates times 2^53.
      const Int one = Int{1} << 53;
      const std::array<Int, 2> pi{one / 2 + i, one / 2 + j}, qi{12 * one, 12 * one}, ri{24 * one, 24 * one};
      REQUIRE(exact_sign2(pi, qi, ri) == expected);
      CHECK(sign_orient2d(p, q, r) == expected);
      CHECK(sign_orient2d(q, r, p) == expected);
      CHECK(sign_orient2d(r, p, q) == expected);
      CHECK(sign_orient2d(q, p, r) == -expected);
      const double naive = naive_orient2d(p, q, r);
      if ((naive > 0) - (naive < 0) != expected) ++naive_wrong;
    }
  }
  // The experiment is meaningful: plain doubles misclassify many of these points.
  CHECK(naive_wrong > 1000);
}

TEST_CASE(
    "predicates: orient2d matches exact integer arithmetic on near-collinear points at scales 2^-1000 to 2^1000") {
  // Kettner-style triples: s v for three of s = 1, 2, 4, ..., 32 and a random v in [0.5, 1)^2 are
  // exactly collinear, at distances large against the ulps of the nearer points; half of the
  // triples then get every coordinate moved by up to 3 ulps. All coordinates are multiples of
  // 2^-53 below 32, so the exact reference fits __int128.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> pick(0, 5), nudge(-3, 3), coin(0, 1);
  int zeros = 0, naive_wrong = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Vector2d v(random_unit(rng, 53), random_unit(rng, 53));
    std::array<int, 3> s;
    do {
      for (int& x : s) x = pick(rng);
    } while (s[0] == s[1] || s[1] == s[2] || s[0] == s[2]);
    const bool moved = coin(rng) == 1;
    std::array<Vector2d, 3> base;
    std::array<std::array<Int, 2>, 3> ints;
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 2; ++k) {
        base[i][k] = std::ldexp(v[k], s[i]);
        if (moved) base[i][k] = nudge_ulps(base[i][k], nudge(rng));
        ints[i][k] = scaled_int(base[i][k], 53);
      }
    }
    const int expected = exact_sign2(ints[0], ints[1], ints[2]);
    zeros += expected == 0;
    const double naive = naive_orient2d(base[0], base[1], base[2]);
    naive_wrong += (naive > 0) - (naive < 0) != expected;
    for (int scale : {-1000, -500, -30, 0, 30, 500, 1000}) {
      std::array<Vector2d, 3> pts;
      for (int i = 0; i < 3; ++i) pts[i] = Vector2d(std::ldexp(base[i].x(), scale), std::ldexp(base[i].y(), scale));
      // Every permutation: the sign times the permutation's parity is the exact sign.
      std::array<int, 3> perm = {0, 1, 2};
      do {
        CHECK(sign_orient2d(pts[perm[0]], pts[perm[1]], pts[perm[2]]) == parity(perm) * expected);
      } while (std::next_permutation(perm.begin(), perm.end()));
    }
  }
  CHECK(zeros > 1000);       // the unmoved triples are exactly collinear,
  CHECK(naive_wrong > 100);  // and plain doubles get many signs wrong
}

TEST_CASE("predicates: orient3d matches exact integer arithmetic on near-coplanar points at scales 2^-1000 to 2^1000") {
  // Four points among s p and s q (s = 1, 2, 4, 8, 16) lie exactly on the plane through the origin
  // spanned by p and q; half of the quadruples then get every coordinate moved by up to 2 units of
  // 2^-36. p and q have 36 significant bits, so every coordinate is a multiple of 2^-36 below 16
  // and the exact reference fits __int128.
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> pick(0, 9), nudge(-2, 2), coin(0, 1);
  int zeros = 0, naive_wrong = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vector3d p(random_unit(rng, 36), random_unit(rng, 36), random_unit(rng, 36));
    const Vector3d q(random_unit(rng, 36), random_unit(rng, 36), random_unit(rng, 36));
    std::array<int, 4> s;
    do {
      for (int& x : s) x = pick(rng);
    } while (s[0] == s[1] || s[0] == s[2] || s[0] == s[3] || s[1] == s[2] || s[1] == s[3] || s[2] == s[3]);
    const bool moved = coin(rng) == 1;
    std::array<Vector3d, 4> base;
    std::array<std::array<Int, 3>, 4> ints;
    for (int i = 0; i < 4; ++i) {
      const Vector3d& dir = s[i] < 5 ? p : q;
      for (int k = 0; k < 3; ++k) {
        base[i][k] = std::ldexp(dir[k], s[i] % 5);
        if (moved) base[i][k] += std::ldexp(nudge(rng), -36);
        ints[i][k] = scaled_int(base[i][k], 36);
      }
    }
    const int expected = exact_sign3(ints[0], ints[1], ints[2], ints[3]);
    zeros += expected == 0;
    const double naive = naive_orient3d(base[0], base[1], base[2], base[3]);
    naive_wrong += (naive > 0) - (naive < 0) != expected;
    for (int scale : {-1000, -300, 0, 300, 1000}) {
      std::array<Vector3d, 4> pts;
      for (int i = 0; i < 4; ++i) {
        for (int k = 0; k < 3; ++k) pts[i][k] = std::ldexp(base[i][k], scale);
      }
      std::array<int, 4> perm = {0, 1, 2, 3};
      do {
        CHECK(sign_orient3d(pts[perm[0]], pts[perm[1]], pts[perm[2]], pts[perm[3]]) == parity(perm) * expected);
      } while (std::next_permutation(perm.begin(), perm.end()));
    }
  }
  CHECK(zeros > 1000);
  CHECK(naive_wrong > 100);
}

TEST_CASE("predicates: exactly collinear and coplanar points with decimal-looking coordinates give exactly 0") {
  // Multiples of one vector by 0, -1 and powers of two are exact, so these points lie exactly on a
  // line through the origin, although 0.1 and 0.7 are not short binary fractions.
  const Vector2d v(0.1, 0.7);
  const std::vector<double> factors = {-0.5, -1.0, 0.0, 1.0, 2.0, 4.0, 1024.0};
  int naive_nonzero = 0;
  for (double f : factors)
    for (double g : factors)
      for (double h : factors) {
        if (f == g || g == h || f == h) continue;
        CHECK(orient2d(f * v, g * v, h * v) == 0.0);
        naive_nonzero += naive_orient2d(f * v, g * v, h * v) != 0.0;
      }
  CHECK(naive_nonzero > 0);
  // The same on the line y = x through awkward values, and far from the origin.
  CHECK(orient2d({0.1, 0.1}, {0.7, 0.7}, {1e10 + 0.3, 1e10 + 0.3}) == 0.0);
  CHECK(orient2d({-1e-300, -1e-300}, {3.3e-7, 3.3e-7}, {1e300, 1e300}) == 0.0);

  // Points s p and s q (s in {0, -1, powers of two}) lie exactly on the plane through the origin
  // spanned by p and q.
  const Vector3d p(0.1, 0.7, 0.3), q(-1.3, 0.2, 2.9);
  const std::vector<Vector3d> pts = {p, -p, 2 * p, 0.5 * p, q, -0.5 * q, 4 * q, Vector3d::Zero()};
  naive_nonzero = 0;
  for (std::size_t a = 0; a < pts.size(); ++a)
    for (std::size_t b = 0; b < pts.size(); ++b)
      for (std::size_t c = 0; c < pts.size(); ++c)
        for (std::size_t d = 0; d < pts.size(); ++d) {
          if (a == b || a == c || a == d || b == c || b == d || c == d) continue;
          CHECK(orient3d(pts[a], pts[b], pts[c], pts[d]) == 0.0);
          naive_nonzero += naive_orient3d(pts[a], pts[b], pts[c], pts[d]) != 0.0;
        }
  CHECK(naive_nonzero > 0);
}

TEST_CASE("predicates: the conventions of the header, and values of well-conditioned determinants") {
  // orient2d is twice the signed area, positive counter-clockwise.
  CHECK(orient2d({0, 0}, {1, 0}, {0, 1}) == 1.0);
  CHECK(orient2d({0, 0}, {0, 1}, {1, 0}) == -1.0);
  CHECK(orient2d({1, 1}, {4, 1}, {1, 3}) == 6.0);
  // orient3d > 0 when d is below the plane of a counter-clockwise (seen from above) a, b, c.
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  CHECK(orient3d(a, b, c, {0.25, 0.5, -1}) == 1.0);
  CHECK(orient3d(a, b, c, {0.25, 0.5, 2}) == -2.0);
  CHECK(sign_orient3d(a, b, c, {5, -7, 0}) == 0);
  // orient3d(a, b, c, d) = det [a - d; b - d; c - d] = -det [b - a; c - a; d - a]: a tet with
  // positive right-handed volume has orient3d < 0.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Vector3d, 4> t;
    for (auto& x : t) x = Vector3d(coord(rng), coord(rng), coord(rng));
    Eigen::Matrix3d rows, cols;
    rows << (t[0] - t[3]).transpose(), (t[1] - t[3]).transpose(), (t[2] - t[3]).transpose();
    cols << t[1] - t[0], t[2] - t[0], t[3] - t[0];
    const double value = orient3d(t[0], t[1], t[2], t[3]);
    CHECK(value == doctest::Approx(rows.determinant()).epsilon(1e-9));
    CHECK(value == doctest::Approx(-cols.determinant()).epsilon(1e-9));
    Eigen::Matrix2d m;
    m << t[1].x() - t[0].x(), t[1].y() - t[0].y(), t[2].x() - t[0].x(), t[2].y() - t[0].y();
    CHECK(orient2d(t[0].head<2>(), t[1].head<2>(), t[2].head<2>()) == doctest::Approx(m.determinant()).epsilon(1e-9));
  }
}

TEST_CASE("predicates: signs survive where the plain formula overflows or underflows") {
  const double big = 1e200, tiny = 1e-200;
  // det = big (next(big) - big) > 0; the plain products are inf (or 0 for tiny) and say nothing.
  CHECK(std::isnan(naive_orient2d({0, 0}, {big, big}, {big, std::nextafter(big, 2 * big)})));
  CHECK(sign_orient2d({0, 0}, {big, big}, {big, std::nextafter(big, 2 * big)}) == 1);
  CHECK(naive_orient2d({0, 0}, {tiny, tiny}, {tiny, std::nextafter(tiny, 1.0)}) == 0.0);
  CHECK(sign_orient2d({0, 0}, {tiny, tiny}, {tiny, std::nextafter(tiny, 1.0)}) == 1);
  CHECK(sign_orient2d({0, 0}, {tiny, tiny}, {std::nextafter(tiny, 1.0), tiny}) == -1);
  CHECK(sign_orient2d({std::numeric_limits<double>::max(), 0}, {0, std::numeric_limits<double>::max()},
                      {-std::numeric_limits<double>::max(), 0}) == 1);
  for (double s : {big, tiny, 1e-300, 1e300}) {
    const Vector3d a(0, 0, 0), b(s, 0, 0), c(0, s, 0);
    CHECK(sign_orient3d(a, b, c, {s, s, -s}) == 1);
    CHECK(sign_orient3d(a, b, c, {s, s, std::ldexp(s, -40)}) == -1);
    CHECK(sign_orient3d(a, b, c, {s, s, 0}) == 0);
  }
  // Non-finite input has no sign.
  CHECK(std::isnan(orient2d({0, 0}, {1, 0}, {std::numeric_limits<double>::infinity(), 1})));
  CHECK(sign_orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, std::nan("")}) == 0);
}

TEST_CASE("predicates: segment crossing, touching, collinear overlap and disjoint cases") {
  struct Case {
    Vector2d a, b, c, d;
    bool cross_properly, intersect;
  };
  const double u = 0x1p-52;
  const Case cases[] = {
      {{0, 0}, {2, 2}, {0, 2}, {2, 0}, true, true},                           // X crossing at (1, 1)
      {{0, 0}, {2, 0}, {1, 0}, {1, 5}, false, true},                          // T: c on the interior of ab
      {{0, 0}, {2, 0}, {2, 0}, {3, 7}, false, true},                          // shared endpoint
      {{0, 0}, {4, 4}, {2, 2}, {6, 6}, false, true},                          // collinear overlap
      {{0, 0}, {4, 4}, {1, 1}, {2, 2}, false, true},                          // collinear containment
      {{0, 0}, {4, 4}, {4, 4}, {6, 6}, false, true},                          // collinear, touching at one point
      {{0, 0}, {4, 4}, {5, 5}, {6, 6}, false, false},                         // collinear disjoint
      {{0, 0}, {4, 0}, {0, 1}, {4, 1}, false, false},                         // parallel
      {{0, 0}, {4, 0}, {5, -1}, {5, 1}, false, false},                        // lines cross outside ab
      {{0, 0}, {4, 0}, {2, 0}, {2, 0}, false, true},                          // a point on ab
      {{0, 0}, {4, 0}, {2, u}, {2, u}, false, false},                         // a point just off ab
      {{1, 1}, {1, 1}, {1, 1}, {1, 1}, false, true},                          // two equal points
      {{0.5, 0.5}, {12, 12}, {24, 24}, {0.5, 0.5 + u}, false, false},         // near-collinear, disjoint
      {{0.5, 0.5}, {24, 24}, {12, 12 - 16 * u}, {0.5, 0.5 + u}, true, true},  // crossing by ulps
  };
  for (const Case& k : cases) {
    CAPTURE(k.a.transpose());
    CAPTURE(k.c.transpose());
    // The answer does not depend on the order of the segments or of their endpoints.
    for (int variant = 0; variant < 8; ++variant) {
      Vector2d a = k.a, b = k.b, c = k.c, d = k.d;
      if (variant & 1) std::swap(a, b);
      if (variant & 2) std::swap(c, d);
      if (variant & 4) {
        std::swap(a, c);
        std::swap(b, d);
      }
      CHECK(segments_cross_properly(a, b, c, d) == k.cross_properly);
      CHECK(segments_intersect(a, b, c, d) == k.intersect);
    }
  }
}

TEST_CASE("predicates: point_on_open_segment is exact and excludes the endpoints") {
  const Vector2d a(0.1, 0.7), b(0.4, 2.8);         // b = 4 a exactly
  CHECK(point_on_open_segment({0.2, 1.4}, a, b));  // 2 a, exactly on the segment
  CHECK(point_on_open_segment({0.2, 1.4}, b, a));
  CHECK_FALSE(point_on_open_segment({0.2, std::nextafter(1.4, 2.0)}, a, b));
  CHECK_FALSE(point_on_open_segment(a, a, b));
  CHECK_FALSE(point_on_open_segment(b, a, b));
  CHECK_FALSE(point_on_open_segment({0.8, 5.6}, a, b));  // 8 a: on the line, beyond b
  CHECK_FALSE(point_on_open_segment({-0.1, -0.7}, a, b));
  CHECK_FALSE(point_on_open_segment(a, a, a));
  CHECK(point_on_open_segment({3, 5}, {3, 0}, {3, 9}));  // vertical
  CHECK_FALSE(point_on_open_segment({3, 10}, {3, 0}, {3, 9}));
}

namespace {

using Tri = std::array<Vector3d, 3>;

// Answers must not depend on the order of the triangles or of their vertices.
void check_triangles(const Tri& t1, const Tri& t2, bool expected) {
  std::array<int, 3> p1 = {0, 1, 2};
  do {
    const Tri u1 = {t1[p1[0]], t1[p1[1]], t1[p1[2]]};
    const Tri u2 = {t2[p1[2]], t2[p1[0]], t2[p1[1]]};
    CHECK(triangles_intersect(u1.data(), u2.data()) == expected);
    CHECK(triangles_intersect(u2.data(), u1.data()) == expected);
  } while (std::next_permutation(p1.begin(), p1.end()));
}

}  // namespace

TEST_CASE("predicates: triangle pairs crossing, touching, coplanar and separated") {
  const Tri base = {Vector3d(0, 0, 0), Vector3d(4, 0, 0), Vector3d(0, 4, 0)};
  const double u = 0x1p-52;
  // Crossing: a vertical triangle pierces the base.
  check_triangles(base, {Vector3d(1, 1, -1), Vector3d(1, 1, 1), Vector3d(3, -1, 1)}, true);
  // Planes cross, triangles do not (the cut of the second lies beyond the base's hypotenuse).
  check_triangles(base, {Vector3d(3, 3, -1), Vector3d(3, 3, 1), Vector3d(5, 2, 0)}, false);
  // Touching at a shared vertex only.
  check_triangles(base, {Vector3d(4, 0, 0), Vector3d(5, 1, 1), Vector3d(5, -1, 1)}, true);
  // A vertex of the second on the interior of the base, the rest above it.
  check_triangles(base, {Vector3d(1, 1, 0), Vector3d(1, 1, 2), Vector3d(2, 1, 2)}, true);
  // The same vertex lifted by one ulp: separated.
  check_triangles(base, {Vector3d(1, 1, u), Vector3d(1, 1, 2), Vector3d(2, 1, 2)}, false);
  // Edge on edge: the second triangle stands on part of the base's edge x = 0.
  check_triangles(base, {Vector3d(0, 1, 0), Vector3d(0, 3, 0), Vector3d(-1, 2, 3)}, true);
  // Coplanar overlapping, coplanar contained, coplanar touching along an edge, coplanar disjoint.
  check_triangles(base, {Vector3d(1, 1, 0), Vector3d(5, 1, 0), Vector3d(1, 5, 0)}, true);
  check_triangles(base, {Vector3d(0.5, 0.5, 0), Vector3d(1, 0.5, 0), Vector3d(0.5, 1, 0)}, true);
  check_triangles(base, {Vector3d(4, 0, 0), Vector3d(0, 4, 0), Vector3d(4, 4, 0)}, true);
  const double w = 0x1p-51;  // one ulp of 2
  check_triangles(base, {Vector3d(2 + w, 2 + w, 0), Vector3d(4, 4, 0), Vector3d(3, 5, 0)}, false);
  check_triangles(base, {Vector3d(5, 5, 0), Vector3d(6, 5, 0), Vector3d(5, 6, 0)}, false);
  // Coplanar in a tilted plane with decimal-looking coordinates (all multiples of p and q).
  const Vector3d p(0.1, 0.7, 0.3), q(-1.3, 0.2, 2.9);
  const Tri tilted = {Vector3d::Zero(), 4 * p, 4 * q};
  check_triangles(tilted, {2 * p, 0.5 * q, 8 * p}, true);
  check_triangles(tilted, {-p, -2 * p, -2 * q}, false);
  // Separated by parallel planes.
  check_triangles(base, {Vector3d(0, 0, 1), Vector3d(4, 0, 1), Vector3d(0, 4, 1)}, false);
  // Identical triangles.
  check_triangles(base, base, true);
  // Degenerate triangles are their segment or point.
  check_triangles(base, {Vector3d(1, 1, -1), Vector3d(1, 1, 1), Vector3d(1, 1, 3)}, true);
  check_triangles(base, {Vector3d(1, 1, 1), Vector3d(1, 1, 2), Vector3d(1, 1, 3)}, false);
  check_triangles(base, {Vector3d(1, 1, 0), Vector3d(1, 1, 0), Vector3d(1, 1, 0)}, true);
  check_triangles({Vector3d(0, 0, 0), Vector3d(2, 2, 2), Vector3d(1, 1, 1)},
                  {Vector3d(0, 2, 0), Vector3d(2, 0, 2), Vector3d(2, 0, 2)}, true);
  check_triangles({Vector3d(0, 0, 0), Vector3d(2, 2, 2), Vector3d(1, 1, 1)},
                  {Vector3d(0, 2, 1), Vector3d(2, 0, 2), Vector3d(2, 0, 2)}, false);
}

namespace {

using IVec = std::array<std::int64_t, 3>;

IVec sub(const IVec& a, const IVec& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
IVec cross(const IVec& a, const IVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::int64_t dot(const IVec& a, const IVec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Brute-force reference for closed triangles (possibly degenerate) with small integer vertices.
// Two convex polytopes are disjoint iff some axis strictly separates their projections, and a
// separating axis can be taken normal to a facet of the Minkowski difference A - B (within its
// affine hull, or normal to that hull). Those normals are, up to scale, a difference d of two of
// the six points, a cross product d1 x d2, or (d1 x d2) x d3: try them all.
bool sat_intersect(const std::array<IVec, 3>& t1, const std::array<IVec, 3>& t2) {
  std::vector<IVec> pts(t1.begin(), t1.end());
  pts.insert(pts.end(), t2.begin(), t2.end());
  std::vector<IVec> diffs;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j) diffs.push_back(sub(pts[j], pts[i]));
  std::vector<IVec> axes = diffs;
  for (std::size_t i = 0; i < diffs.size(); ++i)
    for (std::size_t j = i + 1; j < diffs.size(); ++j) {
      const IVec n = cross(diffs[i], diffs[j]);
      axes.push_back(n);
      for (const IVec& d : diffs) axes.push_back(cross(n, d));
    }
  for (const IVec& axis : axes) {
    std::int64_t lo1 = dot(axis, t1[0]), hi1 = lo1, lo2 = dot(axis, t2[0]), hi2 = lo2;
    for (int k = 1; k < 3; ++k) {
      lo1 = std::min(lo1, dot(axis, t1[k]));
      hi1 = std::max(hi1, dot(axis, t1[k]));
      lo2 = std::min(lo2, dot(axis, t2[k]));
      hi2 = std::max(hi2, dot(axis, t2[k]));
    }
    if (hi1 < lo2 || hi2 < lo1) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("predicates: triangles_intersect agrees with a separating-axis reference on random integer triangles") {
  std::mt19937_64 rng(5);
  int hits = 0, total = 0;
  for (int range : {2, 3, 5}) {
    std::uniform_int_distribution<int> coord(0, range);
    for (int trial = 0; trial < 1500; ++trial) {
      std::array<IVec, 3> i1, i2;
      for (auto& v : i1)
        for (auto& x : v) x = coord(rng);
      for (auto& v : i2)
        for (auto& x : v) x = coord(rng);
      const bool expected = sat_intersect(i1, i2);
      hits += expected;
      ++total;
      // The same configuration scaled by a power of two and moved by an exact offset.
      for (const auto& [scale, offset] : {std::pair{0, 0.0}, std::pair{-40, 1.0}, std::pair{500, -3e160}}) {
        Tri t1, t2;
        for (int v = 0; v < 3; ++v)
          for (int k = 0; k < 3; ++k) {
            t1[v][k] = std::ldexp(static_cast<double>(i1[v][k]), scale) + offset;
            t2[v][k] = std::ldexp(static_cast<double>(i2[v][k]), scale) + offset;
          }
        CHECK(triangles_intersect(t1.data(), t2.data()) == expected);
        CHECK(triangles_intersect(t2.data(), t1.data()) == expected);
      }
    }
  }
  // Both answers occur often enough for the comparison to mean something.
  CHECK(hits > total / 10);
  CHECK(hits < total * 9 / 10);
}

TEST_CASE("predicates: coincident points give exactly 0, and a triangle with two vertices in one point is a segment") {
  // The shortcut of orient2d/orient3d for coincident points (no exact sum) and of the projection
  // for such triangles (collision checks of collapsed columns' front triangles) answer as the
  // exact arithmetic does.
  const Vector3d p(0.1, 0.7, 1e-3), q(0.30000000000000004, -2.5, 7), r(1e-300, 3, -4);
  CHECK(orient3d(p, p, q, r) == 0);
  CHECK(orient3d(p, q, r, q) == 0);
  CHECK(orient2d(Vector2d(0.1, 0.3), Vector2d(0.7, 0.9), Vector2d(0.1, 0.3)) == 0);
  CHECK(std::isnan(orient3d(p, p, q, Vector3d(std::nan(""), 0, 0))));
  const Tri base = {Vector3d(0, 0, 0), Vector3d(4, 0, 0), Vector3d(0, 4, 0)};
  // A degenerate triangle (a segment from (1, 1, -1) to (1, 1, 1)) pierces the base; beside it, not.
  check_triangles(base, {Vector3d(1, 1, -1), Vector3d(1, 1, -1), Vector3d(1, 1, 1)}, true);
  check_triangles(base, {Vector3d(5, 5, -1), Vector3d(5, 5, -1), Vector3d(5, 5, 1)}, false);
  // A point (three vertices in one) on the base, and off it by one ulp.
  check_triangles(base, {Vector3d(1, 1, 0), Vector3d(1, 1, 0), Vector3d(1, 1, 0)}, true);
  check_triangles(base, {Vector3d(1, 1, 0x1p-52), Vector3d(1, 1, 0x1p-52), Vector3d(1, 1, 0x1p-52)}, false);
}

TEST_CASE("predicates: positive_tet is hybrid_mesh.h's positive volume, exactly") {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  CHECK(positive_tet(a, b, c, d));                       // det [b - a, c - a, d - a] = 1
  CHECK_FALSE(positive_tet(a, c, b, d));                 // mirrored
  CHECK_FALSE(positive_tet(a, b, c, Vector3d(3, -2, 0)));  // flat
}
