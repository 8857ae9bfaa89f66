// SPDX-License-Identifier: MIT
#include "modules/elements/validity.h"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "modules/base/error.h"

using namespace plaf;

namespace {

constexpr CellType cell_types[] = {CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron, CellType::Prism};

using Coords = std::vector<double>;
using Point = std::array<double, 3>;

// A fixed non-degenerate linear map per dimension (top-left block used in 2D).
// det of the 2D block [[2, 0.5], [0.3, 1.5]] = 3 - 0.15 = 2.85;
// det of the 3D matrix = 2 (1.8 + 0.08) - 0.5 (0.36 - 0.02) + 0.1 (-0.12 - 0.15) = 3.563.
Eigen::Matrix3d skew_map(int dim) {
  Eigen::Matrix3d a;
  if (dim == 2)
    a << 2, 0.5, 0, 0.3, 1.5, 0, 0, 0, 1;
  else
    a << 2, 0.5, 0.1, 0.3, 1.5, 0.2, 0.1, -0.4, 1.2;
  return a;
}
constexpr double skew_det_2d = 2.85, skew_det_3d = 3.563;

// The reference cell's nodes mapped by x -> a x + b (a straight cell: det J = det a everywhere).
Coords affine_cell(CellType t, int q, const Eigen::Matrix3d& a, const Eigen::Vector3d& b) {
  const LagrangeElement& e = lagrange_element(t, q);
  Coords c;
  for (int i = 0; i < e.size(); ++i) {
    const Point r = e.ref_node(i);
    const Eigen::Vector3d x = a * Eigen::Vector3d(r[0], r[1], r[2]) + b;
    for (int d = 0; d < e.dim(); ++d) c.push_back(x[d]);
  }
  return c;
}

Coords reference_cell(CellType t, int q) {
  return affine_cell(t, q, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
}

// The lattice {0..n}^d / n restricted to the reference cell (boundary included).
std::vector<Point> dense_points(CellType t, int n) {
  const int dim = ref_dim(t);
  std::vector<Point> out;
  for (int k = 0; k <= (dim == 3 ? n : 0); ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        if ((t == CellType::Triangle || t == CellType::Prism) && i + j > n) continue;
        if (t == CellType::Tetrahedron && i + j + k > n) continue;
        out.push_back({static_cast<double>(i) / n, static_cast<double>(j) / n, static_cast<double>(k) / n});
      }
  return out;
}

std::vector<Point> dense_points(CellType t) {
  // 861 (triangle), 1681 (quadrilateral), 1140 (tetrahedron) and 1800 (prism) points.
  switch (t) {
    case CellType::Triangle:
    case CellType::Quadrilateral:
      return dense_points(t, 40);
    case CellType::Tetrahedron:
      return dense_points(t, 17);
    default:
      return dense_points(t, 14);
  }
}

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
};

Range det_range(CellType t, int q, const Coords& c, const std::vector<Point>& points) {
  Range r;
  for (const Point& x : points) {
    const double v = jacobian_determinant(t, q, c.data(), x.data());
    r.lo = std::min(r.lo, v);
    r.hi = std::max(r.hi, v);
  }
  return r;
}

double min_det_at_nodes(CellType t, int q, const Coords& c) {
  const LagrangeElement& e = lagrange_element(t, q);
  std::vector<Point> nodes;
  for (int i = 0; i < e.size(); ++i) nodes.push_back(e.ref_node(i));
  return det_range(t, q, c, nodes).lo;
}

// A skewed straight cell (about 2 units across) with every node moved by up to 0.06 / Q: about
// 3% of the cell, scaled with the node spacing so that higher orders stay valid (fixed seed).
Coords perturbed_cell(CellType t, int q, unsigned seed) {
  const int dim = ref_dim(t);
  Coords c = affine_cell(t, q, skew_map(dim), Eigen::Vector3d(1, -2, 0.5));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.06 / q, 0.06 / q);
  for (double& x : c) x += jitter(rng);
  return c;
}

// Cells that are valid at every Lagrange node but inverted inside (found by a random search
// over node displacements of the reference cell, checking nodes and a fine grid; the test
// re-checks both properties). One moved node of a Q = 2 simplex cannot do it: there
// det J = 1 + delta . grad(phi) is linear and takes its minimum at a vertex, so two nodes move.
struct Move {
  int node;
  Point delta;
};
struct InvertedInside {
  CellType type;
  int order;
  std::vector<Move> moves;
};
const std::vector<InvertedInside>& inverted_inside_cells() {
  static const std::vector<InvertedInside> cells = {
      // Mid-node of edge 0-1, (0.5, 0) -> (0.3, 0.3); see the analytic minimum below.
      {CellType::Quadrilateral, 2, {{4, {-0.2, 0.3, 0}}}},
      // Node (2/3, 1) of edge 2-3 moved out and along the edge.
      {CellType::Quadrilateral, 3, {{8, {-0.25, 0.6, 0}}}},
      // Mid-nodes of edges 0-1 and 1-2.
      {CellType::Triangle, 2, {{3, {-0.15, 0.55, 0}}, {4, {0.6, 0.2, 0}}}},
      // Node (2/3, 1/3) of edge 1-2, moved mostly along the edge.
      {CellType::Triangle, 3, {{5, {-0.3, 0.2, 0}}}},
      // Mid-nodes of edges 0-1 and 3-0.
      {CellType::Tetrahedron, 2, {{4, {0.1, -0.5, 0.55}}, {7, {-0.6, -0.05, -0.1}}}},
      // Mid-node (0.5, 0, 1) of top edge 3-4.
      {CellType::Prism, 2, {{12, {-0.2, -0.55, -0.6}}}},
  };
  return cells;
}

Coords build(const InvertedInside& cell) {
  Coords c = reference_cell(cell.type, cell.order);
  const int dim = ref_dim(cell.type);
  for (const Move& m : cell.moves)
    for (int d = 0; d < dim; ++d) c[m.node * dim + d] += m.delta[d];
  return c;
}

void check_same(const JacobianBounds& a, const JacobianBounds& b) {
  CHECK(a.valid == b.valid);
  CHECK(a.proven == b.proven);
  CHECK(a.min_lower == b.min_lower);
  CHECK(a.min_upper == b.min_upper);
  CHECK(a.max_lower == b.max_lower);
  CHECK(a.max_upper == b.max_upper);
  CHECK(a.subdivisions == b.subdivisions);
}

}  // namespace

TEST_CASE("validity: straight cells have constant det J = det A and scaled Jacobian 1, mirrored ones are invalid") {
  constexpr double coef_rel = 1e-7;
  JacobianCertifier certifier;
  for (CellType t : cell_types)
    for (int q = 1; q <= max_order; ++q) {
      INFO(std::string(cell_name(t)), " Q=", q);
      const int dim = ref_dim(t);
      // An affine map x = A xi + b has J = A, so det J = det A at every point.
      const double det_a = dim == 2 ? skew_det_2d : skew_det_3d;
      const Coords c = affine_cell(t, q, skew_map(dim), Eigen::Vector3d(1, -2, 0.5));
      for (const Point& x : dense_points(t, 4))
        CHECK(jacobian_determinant(t, q, c.data(), x.data()) == doctest::Approx(det_a).epsilon(1e-12));
      const JacobianBounds r = certifier.certify(t, q, c.data());
      CHECK(r.valid);
      CHECK(r.proven);
      CHECK(r.subdivisions == 0);  // all Bernstein coefficients equal det A: nothing to refine
      // Samples are det J to rounding; the coefficients carry rounding of the samples amplified
      // by the inverse Bernstein matrix (norm up to ~7e7 for the order-4 prism).
      CHECK(r.min_upper == doctest::Approx(det_a).epsilon(1e-12));
      CHECK(r.max_lower == doctest::Approx(det_a).epsilon(1e-12));
      CHECK(r.min_lower == doctest::Approx(det_a).epsilon(coef_rel));
      CHECK(r.max_upper == doctest::Approx(det_a).epsilon(coef_rel));
      CHECK(r.scaled_lower() == doctest::Approx(1.0).epsilon(coef_rel));
      CHECK(r.scaled_upper() == doctest::Approx(1.0).epsilon(coef_rel));

      // Mirroring x -> -x flips the sign of det J everywhere.
      Eigen::Matrix3d mirror = skew_map(dim);
      mirror.row(0) *= -1;
      const Coords m = affine_cell(t, q, mirror, Eigen::Vector3d::Zero());
      const JacobianBounds rm = certifier.certify(t, q, m.data());
      CHECK_FALSE(rm.valid);
      CHECK(rm.proven);
      CHECK(rm.min_upper == doctest::Approx(-det_a).epsilon(1e-12));
      CHECK(rm.max_upper == doctest::Approx(-det_a).epsilon(coef_rel));
      // No positive det J anywhere: the scaled Jacobian ranks the cell below every other.
      CHECK(rm.scaled_lower() == -std::numeric_limits<double>::infinity());
      CHECK(rm.scaled_upper() == -std::numeric_limits<double>::infinity());
    }
}

TEST_CASE("validity: cells with det J > 0 at every node but inverted inside are proven invalid") {
  JacobianCertifier certifier;
  for (const InvertedInside& cell : inverted_inside_cells()) {
    INFO(std::string(cell_name(cell.type)), " Q=", cell.order);
    const Coords c = build(cell);
    // Node sampling would pass the cell, a fine grid shows it is inverted.
    REQUIRE(min_det_at_nodes(cell.type, cell.order, c) > 0.05);
    const Range dense = det_range(cell.type, cell.order, c, dense_points(cell.type));
    REQUIRE(dense.lo < -0.05);
    const JacobianBounds r = certifier.certify(cell.type, cell.order, c.data());
    CHECK_FALSE(r.valid);
    CHECK(r.proven);
    CHECK(r.min_upper <= 0);
    CHECK(r.min_lower <= dense.lo);
    CHECK(r.scaled_lower() < 0);
  }
  SUBCASE("the Q = 2 quadrilateral's minimum matches its closed form") {
    // With the mid-node of edge 0-1 moved by (a, b), x = u + a phi, y = v + b phi for
    // phi = 4u(1-u) (1-v)(1-2v), so det J = 1 + a phi_u + b phi_v. On v = 0 (where it is
    // smallest) det J = 1 + 4a(1-2u) - 12b u(1-u), a parabola with minimum
    // 1 - 3b - 4a^2/(3b) at u = 1/2 + a/(3b); a = -0.2, b = 0.3 give -7/90 at u = 5/18.
    constexpr double exact_min = -7.0 / 90.0;
    const InvertedInside& cell = inverted_inside_cells().front();
    const Coords c = build(cell);
    const Point at_min{5.0 / 18.0, 0, 0};
    CHECK(jacobian_determinant(cell.type, cell.order, c.data(), at_min.data()) ==
          doctest::Approx(exact_min).epsilon(1e-12));
    const JacobianBounds r = certifier.certify(cell.type, cell.order, c.data());
    CHECK(r.min_lower <= exact_min);
    CHECK(r.min_upper >= exact_min - 1e-14);
    CHECK(r.min_upper - r.min_lower <= ValidityOptions{}.rel_tol * r.max_upper);
  }
}

TEST_CASE("validity: a valid cell with negative coefficients is proven by subdivision, not without it") {
  // The Q = 2 quadrilateral of the previous case with (a, b) = (-0.2, 0.25): by the same closed
  // form its minimum is 1 - 3b - 4a^2/(3b) = 0.25 - 0.16/0.75 = 11/300 > 0, but small enough that
  // the coefficients of the whole cell go negative.
  constexpr double exact_min = 11.0 / 300.0;
  const InvertedInside cell{CellType::Quadrilateral, 2, {{4, {-0.2, 0.25, 0}}}};
  const Coords c = build(cell);

  JacobianCertifier deep;
  const JacobianBounds r = deep.certify(cell.type, cell.order, c.data());
  CHECK(r.valid);
  CHECK(r.proven);
  CHECK(r.subdivisions > 0);
  CHECK(r.min_lower <= exact_min);
  CHECK(r.min_upper >= exact_min);

  for (int depth : {0, 1}) {
    INFO("max_depth ", depth);
    ValidityOptions shallow_options;
    shallow_options.max_depth = depth;
    JacobianCertifier shallow(shallow_options);
    const JacobianBounds s = shallow.certify(cell.type, cell.order, c.data());
    CHECK_FALSE(s.valid);
    CHECK_FALSE(s.proven);
    CHECK(s.min_lower <= 0);
    CHECK(s.min_upper > 0);
    CHECK(s.min_lower <= exact_min);
    CHECK(s.min_upper >= exact_min);
  }
}

TEST_CASE("validity: minima inside the cell, of exact polynomial maps, are bracketed tightly") {
  // Shears x = (u + t g, v[, w]) with g of degree <= Q are interpolated exactly and have
  // det J = 1 + t dg/du. Each minimum below lies where only the inner sub-cells reach it (the
  // middle triangle, the octahedron of the tetrahedron), so it also checks the subdivisions.
  struct Shear {
    CellType type;
    int order;
    double t;
    double (*g)(const Point&);
    double exact_min;
  };
  const Shear shears[] = {
      // dg/du = -u v (1-u-v), largest (1/27) at the centroid: min det J = 1 - 13.5/27 = 0.5.
      {CellType::Triangle, 4, 13.5,
       [](const Point& x) { return -x[1] * (x[0] * x[0] / 2 * (1 - x[1]) - x[0] * x[0] * x[0] / 3); }, 0.5},
      // The same in the triangle of a prism, for every w.
      {CellType::Prism, 4, 13.5,
       [](const Point& x) { return -x[1] * (x[0] * x[0] / 2 * (1 - x[1]) - x[0] * x[0] * x[0] / 3); }, 0.5},
      // dg/du = -v w (1-u-v-w), largest (1/27) at (0, 1/3, 1/3), in the octahedron's face on u = 0.
      {CellType::Tetrahedron, 4, 13.5,
       [](const Point& x) { return -x[1] * x[2] * (x[0] * (1 - x[1] - x[2]) - x[0] * x[0] / 2); }, 0.5},
      // dg/du = -16 u(1-u) v(1-v), largest (1) at the centre: min det J = 1 - 0.5.
      {CellType::Quadrilateral, 3, 0.5,
       [](const Point& x) { return -16 * x[1] * (1 - x[1]) * (x[0] * x[0] / 2 - x[0] * x[0] * x[0] / 3); }, 0.5},
  };
  ValidityOptions options;
  options.rel_tol = 1e-3;  // tight enough that every case is refined around its minimum
  JacobianCertifier certifier(options);
  for (const Shear& s : shears) {
    INFO(std::string(cell_name(s.type)), " Q=", s.order);
    const LagrangeElement& e = lagrange_element(s.type, s.order);
    Coords c;
    for (int i = 0; i < e.size(); ++i) {
      Point x = e.ref_node(i);
      x[0] += s.t * s.g(x);
      for (int d = 0; d < e.dim(); ++d) c.push_back(x[d]);
    }
    const JacobianBounds r = certifier.certify(s.type, s.order, c.data());
    CHECK(r.valid);
    CHECK(r.proven);
    CHECK(r.min_lower <= s.exact_min);
    CHECK(r.min_upper >= s.exact_min - 1e-12);
    CHECK(r.min_upper - r.min_lower <= options.rel_tol * r.max_upper);
    CHECK(r.subdivisions > 0);
    // det J = 1 where dg/du = 0 (at the vertices) and never more.
    CHECK(r.max_lower == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(r.max_upper >= 1.0 - 1e-12);
  }
}

TEST_CASE("validity: Bernstein bounds enclose det J sampled densely inside perturbed curved cells") {
  const ValidityOptions options;
  JacobianCertifier certifier(options);
  for (CellType t : cell_types)
    for (int q = 1; q <= max_order; ++q) {
      INFO(std::string(cell_name(t)), " Q=", q);
      const Coords c = perturbed_cell(t, q, 42u + static_cast<unsigned>(q));
      const JacobianBounds r = certifier.certify(t, q, c.data());
      REQUIRE(r.valid);
      CHECK(r.proven);
      CHECK(r.min_lower <= r.min_upper);
      CHECK(r.min_upper <= r.max_lower);
      CHECK(r.max_lower <= r.max_upper);
      // Refinement reached the requested tolerance on both bounds.
      const double tol_abs = options.rel_tol * r.max_upper;
      CHECK(r.min_upper - r.min_lower <= tol_abs);
      CHECK(r.max_upper - r.max_lower <= tol_abs);

      const double round_abs = 1e-12 * r.max_upper;
      const std::vector<Point> points = dense_points(t);
      int inside = 0;
      for (const Point& x : points) {
        const double v = jacobian_determinant(t, q, c.data(), x.data());
        inside += r.min_lower - round_abs <= v && v <= r.max_upper + round_abs;
      }
      CHECK(inside == static_cast<int>(points.size()));
      // The dense extremes are values of det J, so they respect the proven bounds; the certifier's
      // own samples may lie between grid points, so they agree with the grid to tol_abs.
      const Range dense = det_range(t, q, c, points);
      CHECK(dense.lo >= r.min_lower - round_abs);
      CHECK(dense.lo <= r.min_upper + tol_abs);
      CHECK(dense.hi <= r.max_upper + round_abs);
      CHECK(dense.hi >= r.max_lower - tol_abs);
      CHECK(r.scaled_lower() <= dense.lo / dense.hi + round_abs);
    }
}

namespace {

// Prisms x = (u, v, Z(u, v, w)) in the prism's space of order q: J is lower triangular, so
// det J = dZ/dw exactly, with known extremes.
struct AxialPrism {
  const char* name;
  int min_order;  // Z lies in the prism space from this order on
  double (*z)(double u, double v, double w);
  double det_min, det_max;            // exact extremes of dZ/dw over the prism
  bool positive_at_nodes[max_order];  // per order 1..4: dZ/dw > 0 at every Lagrange node
};

// e2 = l0 l1 + l1 l2 + l2 l0 of the barycentric coordinates: 0 at the triangle's vertices, 1/4
// at its edge midpoints, 1/3 (its maximum) at the centroid.
double e2(double u, double v) {
  const double l0 = 1 - u - v;
  return l0 * u + u * v + v * l0;
}

const AxialPrism axial_prisms[] = {
    // Q >= 1: dZ/dw = 1 + b u, b = -0.5: 1 on u = 0, 0.5 on u = 1.
    {"tapered", 1, [](double u, double, double w) { return w * (1 - 0.5 * u); }, 0.5, 1.0, {true, true, true, true}},
    // b = -1.5: -0.5 on the vertical edge u = 1, through its nodes.
    {"tapered inverted",
     1,
     [](double u, double, double w) { return w * (1 - 1.5 * u); },
     -0.5,
     1.0,
     {false, false, false, false}},
    // Q >= 2: dZ/dw = 1 + a (0.3 - e2), a = 15: 5.5 at the vertices, 0.5 at the centroid.
    {"dimpled",
     2,
     [](double u, double v, double w) { return w * (1 + 15 * (0.3 - e2(u, v))); },
     0.5,
     5.5,
     {false, true, true, true}},
    // a = 60: 19 at the vertices, 4 at the edge midpoints, 1 + 60 (0.3 - 5/16) = 0.25 at the
    // Q = 4 face nodes (1/4, 1/4, 1/2), but -1 at the centroid (a node only at Q = 3).
    {"dimpled inverted",
     2,
     [](double u, double v, double w) { return w * (1 + 60 * (0.3 - e2(u, v))); },
     -1.0,
     19.0,
     {false, true, false, true}},
    // Q >= 3: dZ/dw = 1 + a ((w - 1/2)^2 - 1/72), a = 144: 3 at w = 1/3, 2/3 (the Q = 3 nodes
    // nearest 1/2), 35 at w = 0, 1, but -1 at w = 1/2 (a node at Q = 4).
    {"waisted inverted",
     3,
     [](double, double, double w) { return w + 144 * (std::pow(w - 0.5, 3) / 3 - w / 72); },
     -1.0,
     35.0,
     {false, false, true, false}},
};

}  // namespace

TEST_CASE("validity: prisms of order 1..4 with exact det J extremes, valid and inverted (inside only where possible)") {
  ValidityOptions options;
  options.rel_tol = 1e-3;
  JacobianCertifier certifier(options);
  for (const AxialPrism& p : axial_prisms)
    for (int q = p.min_order; q <= max_order; ++q) {
      INFO(p.name, " Q=", q);
      const LagrangeElement& e = lagrange_element(CellType::Prism, q);
      Coords c;
      for (int i = 0; i < e.size(); ++i) {
        const Point r = e.ref_node(i);
        c.insert(c.end(), {r[0], r[1], p.z(r[0], r[1], r[2])});
      }
      REQUIRE((min_det_at_nodes(CellType::Prism, q, c) > 0) == p.positive_at_nodes[q - 1]);
      const JacobianBounds b = certifier.certify(CellType::Prism, q, c.data());
      CHECK(b.proven);
      CHECK(b.valid == (p.det_min > 0));
      const double round_abs = 1e-9 * p.det_max;
      CHECK(b.min_lower <= p.det_min + round_abs);
      CHECK(b.max_upper >= p.det_max - round_abs);
      CHECK(b.max_lower == doctest::Approx(p.det_max).epsilon(options.rel_tol));
      if (p.det_min > 0) {
        // Refined to rel_tol: the certified scaled Jacobian brackets det_min / det_max, within
        // about rel_tol (both bounds are within rel_tol det_max of the extremes).
        CHECK(b.min_upper >= p.det_min - round_abs);
        CHECK(b.scaled_lower() <= p.det_min / p.det_max + round_abs);
        CHECK(b.scaled_upper() >= p.det_min / p.det_max - round_abs);
        CHECK(b.scaled_lower() == doctest::Approx(p.det_min / p.det_max).epsilon(2 * options.rel_tol));
      } else {
        CHECK(b.min_upper <= 0);
        CHECK(b.scaled_lower() < 0);
      }
    }
}

TEST_CASE("validity: prisms of a spherical shell (t = 0.3 and 1e-5) are valid at orders 1..4, det J ~ t (1 + t w)^2") {
  // Nodes at (1 + t w) n / |n| for n on the flat triangle a, b, c of unit vectors (a face of an
  // icosahedron). The radius is linear in w and interpolated exactly, so the order-Q map is
  // x = (1 + t w) N(u, v) with N the interpolant of the unit directions, and
  // det J = t (1 + t w)^2 N . (N_u x N_v): min det J / t and max det J / (t (1 + t)^2) do not
  // depend on t, the thin shell is as valid as the thick one. Dense samples lie inside the
  // certified bounds, and the certified scaled Jacobian is within 2 rel_tol of theirs.
  const double g = (1 + std::sqrt(5.0)) / 2;
  const Eigen::Vector3d a = Eigen::Vector3d(0, 1, g).normalized(), b = Eigen::Vector3d(1, g, 0).normalized(),
                        c = Eigen::Vector3d(-1, g, 0).normalized();
  REQUIRE((b - a).cross(c - a).dot(a) > 0);  // counter-clockwise seen from outside: w points out
  const ValidityOptions options;
  JacobianCertifier certifier(options);
  for (int q = 1; q <= max_order; ++q) {
    std::vector<Range> dense;
    for (const double t : {0.3, 1e-5}) {
      INFO("t=", t, " Q=", q);
      const LagrangeElement& e = lagrange_element(CellType::Prism, q);
      Coords x;
      for (int i = 0; i < e.size(); ++i) {
        const Point r = e.ref_node(i);
        const Eigen::Vector3d p = (1 + t * r[2]) * (a + r[0] * (b - a) + r[1] * (c - a)).normalized();
        x.insert(x.end(), {p[0], p[1], p[2]});
      }
      const JacobianBounds r = certifier.certify(CellType::Prism, q, x.data());
      CHECK(r.valid);
      CHECK(r.proven);
      const Range d = det_range(CellType::Prism, q, x, dense_points(CellType::Prism));
      const double round_abs = 1e-9 * r.max_upper;
      CHECK(d.lo >= r.min_lower - round_abs);
      CHECK(d.hi <= r.max_upper + round_abs);
      CHECK(r.scaled_lower() <= d.lo / d.hi + 1e-9);
      CHECK(r.scaled_lower() >= d.lo / d.hi - 2 * options.rel_tol);
      dense.push_back({d.lo / t, d.hi / (t * (1 + t) * (1 + t))});
    }
    INFO("Q=", q);
    CHECK(dense[1].lo == doctest::Approx(dense[0].lo).epsilon(1e-9));
    CHECK(dense[1].hi == doctest::Approx(dense[0].hi).epsilon(1e-9));
  }
}

TEST_CASE("validity: annulus sector quadrilateral has scaled Jacobian r_in / r_out") {
  // x = (r cos(theta), r sin(theta)) with r = r0 + (r1 - r0) u, theta = theta0 + dtheta v has
  // det J = (r1 - r0) dtheta r, so min det J / max det J = r0 / r1 for the exact map; the
  // order-Q interpolant of the map is close to it.
  constexpr double r0 = 1.0, r1 = 2.0, theta0 = 0.3, dtheta = std::numbers::pi / 3;
  constexpr double exact_ratio = r0 / r1;
  ValidityOptions options;
  options.rel_tol = 1e-3;  // so the bracket is well inside the 2% asserted below
  JacobianCertifier certifier(options);
  for (int q = 2; q <= max_order; ++q) {
    INFO("Q=", q);
    const LagrangeElement& e = lagrange_element(CellType::Quadrilateral, q);
    Coords c;
    for (int i = 0; i < e.size(); ++i) {
      const Point uv = e.ref_node(i);
      const double r = r0 + (r1 - r0) * uv[0], theta = theta0 + dtheta * uv[1];
      c.push_back(r * std::cos(theta));
      c.push_back(r * std::sin(theta));
    }
    const JacobianBounds r = certifier.certify(CellType::Quadrilateral, q, c.data());
    CHECK(r.valid);
    CHECK(r.proven);
    CHECK(r.scaled_lower() <= r.scaled_upper());
    if (q >= 3) {
      CHECK(r.scaled_lower() == doctest::Approx(exact_ratio).epsilon(0.02));
      CHECK(r.scaled_upper() == doctest::Approx(exact_ratio).epsilon(0.02));
      // The extremes themselves: (r1 - r0) dtheta r at r = r0 and r = r1.
      CHECK(r.min_upper == doctest::Approx((r1 - r0) * dtheta * r0).epsilon(0.02));
      CHECK(r.max_lower == doctest::Approx((r1 - r0) * dtheta * r1).epsilon(0.02));
    }
  }
}

TEST_CASE("validity: decisions and scaled bounds do not depend on the length scale (1e-8 .. 1e8)") {
  std::vector<std::pair<CellType, int>> kinds;
  std::vector<Coords> cells;
  for (CellType t : cell_types)
    for (int q = 2; q <= max_order; ++q) {
      kinds.emplace_back(t, q);
      cells.push_back(perturbed_cell(t, q, 7u * static_cast<unsigned>(q)));
    }
  for (const InvertedInside& cell : inverted_inside_cells()) {
    kinds.emplace_back(cell.type, cell.order);
    cells.push_back(build(cell));
  }
  JacobianCertifier certifier;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto [t, q] = kinds[k];
    INFO(std::string(cell_name(t)), " Q=", q);
    const JacobianBounds unit = certifier.certify(t, q, cells[k].data());
    for (double scale : {1e-8, 1e8}) {
      INFO("scale ", scale);
      Coords scaled = cells[k];
      for (double& x : scaled) x *= scale;
      const JacobianBounds r = certifier.certify(t, q, scaled.data());
      CHECK(r.valid == unit.valid);
      CHECK(r.proven == unit.proven);
      const double det_scale = std::pow(scale, ref_dim(t));  // det J scales as length^dim
      CHECK(r.min_lower == doctest::Approx(unit.min_lower * det_scale).epsilon(1e-9));
      CHECK(r.max_upper == doctest::Approx(unit.max_upper * det_scale).epsilon(1e-9));
      CHECK(r.scaled_lower() == doctest::Approx(unit.scaled_lower()).epsilon(1e-9));
      CHECK(r.scaled_upper() == doctest::Approx(unit.scaled_upper()).epsilon(1e-9));
    }
  }
}

TEST_CASE("validity: a warmed-up certifier gives identical results on repeated, interleaved calls") {
  std::vector<std::pair<CellType, int>> kinds;
  std::vector<Coords> cells;
  for (CellType t : cell_types)
    for (int q = 1; q <= max_order; ++q) {
      kinds.emplace_back(t, q);
      cells.push_back(perturbed_cell(t, q, 99u));
    }
  const InvertedInside& bad = inverted_inside_cells()[1];
  kinds.emplace_back(bad.type, bad.order);
  cells.push_back(build(bad));

  JacobianCertifier warm;
  std::vector<JacobianBounds> first;
  for (std::size_t k = 0; k < cells.size(); ++k)
    first.push_back(warm.certify(kinds[k].first, kinds[k].second, cells[k].data()));
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t k = cells.size(); k-- > 0;) {  // reverse order: scratch of other kinds in between
      INFO(std::string(cell_name(kinds[k].first)), " Q=", kinds[k].second, " pass ", pass);
      check_same(warm.certify(kinds[k].first, kinds[k].second, cells[k].data()), first[k]);
    }
  JacobianCertifier fresh;
  for (std::size_t k = 0; k < cells.size(); ++k)
    check_same(fresh.certify(kinds[k].first, kinds[k].second, cells[k].data()), first[k]);
}

TEST_CASE("validity: bad orders, line cells and non-finite coordinates are rejected") {
  JacobianCertifier certifier;
  const Coords tri = reference_cell(CellType::Triangle, 1);
  CHECK_THROWS_AS(certifier.certify(CellType::Triangle, 5, tri.data()), ConfigError);
  const Coords line{0.0, 1.0};
  CHECK_THROWS_AS(certifier.certify(CellType::Line, 1, line.data()), InputError);
  Coords nan_tri = tri;
  nan_tri[3] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(certifier.certify(CellType::Triangle, 1, nan_tri.data()),
                       "validity: node 1 of an order-1 triangle has a non-finite coordinate", InputError);
}

namespace {

// The order-q surface triangle x(u, v) = a + u e0 + v e1 + bump(u, v), nodes in Gmsh order.
template <class Bump>
std::vector<Eigen::Vector3d> surface_triangle(int q, const Eigen::Vector3d& a, const Eigen::Vector3d& e0,
                                              const Eigen::Vector3d& e1, Bump bump) {
  const LagrangeElement& e = lagrange_element(CellType::Triangle, q);
  std::vector<Eigen::Vector3d> nodes;
  for (int i = 0; i < e.size(); ++i) {
    const auto r = e.ref_node(i);
    nodes.push_back(a + r[0] * e0 + r[1] * e1 + bump(r[0], r[1]));
  }
  return nodes;
}

}  // namespace

TEST_CASE("validity: surface triangles are certified in their flat triangle's plane") {
  JacobianCertifier certifier;
  const Eigen::Vector3d a(0.3, -1, 2), e0(1, 0.2, 0.1), e1(0.1, 0.9, -0.4);
  const Eigen::Vector3d normal = e0.cross(e1).normalized();
  for (int q = 1; q <= max_order; ++q) {
    INFO("order ", q);
    // Flat, in any orientation and position: det J constant, scaled Jacobian 1.
    const auto flat = surface_triangle(q, a, e0, e1, [](double, double) { return Eigen::Vector3d::Zero(); });
    JacobianBounds b = certify_surface_triangle(certifier, q, flat.data());
    CHECK(b.valid);
    CHECK(b.scaled_lower() == doctest::Approx(1).epsilon(1e-9));
    // The plane frame keeps lengths: det J = twice the flat triangle's area.
    CHECK(b.min_lower == doctest::Approx(e0.cross(e1).norm()).epsilon(1e-9));
    std::vector<double> plane(flat.size() * 2);
    REQUIRE(surface_triangle_plane_coords(q, flat.data(), plane.data()));
    CHECK(plane[0] == 0);
    CHECK(plane[1] == 0);
    CHECK(plane[2] == doctest::Approx(e0.norm()));
    CHECK(plane[3] == doctest::Approx(0).epsilon(1e-12));
    CHECK(plane[5] > 0);  // vertex 2 on the positive side: counter-clockwise
    // The mirrored triangle (vertices 1 and 2 swapped) is still counter-clockwise in its own frame.
    if (q == 1) {
      const std::vector<Eigen::Vector3d> swapped = {flat[0], flat[2], flat[1]};
      CHECK(certify_surface_triangle(certifier, 1, swapped.data()).valid);
    }
  }
  for (int q = 2; q <= max_order; ++q) {
    INFO("order ", q);
    // A bump along the normal does not change the map in the plane: still scaled Jacobian 1.
    auto bump = [&](double u, double v) { return Eigen::Vector3d(3 * u * v * normal); };
    const auto bumped = surface_triangle(q, a, e0, e1, bump);
    JacobianBounds b = certify_surface_triangle(certifier, q, bumped.data());
    CHECK(b.valid);
    CHECK(b.scaled_lower() == doctest::Approx(1).epsilon(1e-9));
    // A tangential shear that folds the triangle over edge 0-1 near vertex 1 (the map's
    // u-derivative along e0 is 1 - 2.4 u, negative for u > 5/12): proven invalid.
    auto fold = [&](double u, double) { return Eigen::Vector3d(-1.2 * u * u * e0); };
    const auto folded = surface_triangle(q, a, e0, e1, fold);
    b = certify_surface_triangle(certifier, q, folded.data());
    CHECK_FALSE(b.valid);
    CHECK(b.proven);
    CHECK(b.min_upper < 0);
  }
  // A degenerate flat triangle is proven invalid; a non-finite node is an input error.
  std::vector<Eigen::Vector3d> line = {a, a + e0, a + 2 * e0};
  JacobianBounds d = certify_surface_triangle(certifier, 1, line.data());
  CHECK_FALSE(d.valid);
  CHECK(d.proven);
  std::vector<double> plane(6);
  CHECK_FALSE(surface_triangle_plane_coords(1, line.data(), plane.data()));
  line[2] = Eigen::Vector3d(0, std::numeric_limits<double>::quiet_NaN(), 0);
  CHECK_THROWS_AS(certify_surface_triangle(certifier, 1, line.data()), InputError);
}

TEST_CASE("validity: surface quadrilaterals are certified in the plane of their vector area") {
  JacobianCertifier certifier;
  // The unit square in z = 0, counter-clockwise seen from +z: the frame keeps it as it is.
  const std::vector<Eigen::Vector3d> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  std::vector<double> plane(8);
  REQUIRE(surface_quad_plane_coords(1, square.data(), plane.data()));
  CHECK(plane == std::vector<double>{0, 0, 1, 0, 1, 1, 0, 1});
  JacobianBounds b = certify_surface_quad(certifier, 1, square.data());
  CHECK(b.valid);
  CHECK(b.scaled_lower() == doctest::Approx(1).epsilon(1e-12));
  // Listed clockwise it is the same square seen from -z: still valid in its own frame.
  const std::vector<Eigen::Vector3d> clockwise = {square[0], square[3], square[2], square[1]};
  CHECK(certify_surface_quad(certifier, 1, clockwise.data()).valid);
  // A bow tie (vertices 2 and 3 swapped) has a vanishing vector area: degenerate, invalid.
  const std::vector<Eigen::Vector3d> bow_tie = {square[0], square[1], square[3], square[2]};
  b = certify_surface_quad(certifier, 1, bow_tie.data());
  CHECK_FALSE(b.valid);
  CHECK(b.proven);
  // A warped quadrilateral (vertex 2 lifted) is valid in its best-fitting plane.
  const std::vector<Eigen::Vector3d> warped = {square[0], square[1], {1, 1, 0.3}, square[3]};
  CHECK(certify_surface_quad(certifier, 1, warped.data()).valid);
  std::vector<Eigen::Vector3d> bad = square;
  bad[1].y() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(certify_surface_quad(certifier, 1, bad.data()), InputError);
}

TEST_CASE("validity: cell_valid refuses a curved tetrahedron certified positive whose corners are inverted") {
  // Corners: the apex (0.25, 0.25, -0.05) lies below the base triangle's plane, so the corner
  // tetrahedron is inverted; the base's edges 0-1 and 2-0 bow down by 0.15 under it (and edge 1-2
  // bulges out by 0.05), which turns the curved cell right side up: det J > 0 everywhere, proven.
  // (Found by a search over midnode offsets; the layer stage met such cells on a published
  // capsule at h0 1e-5 L, accepted them, and the quality stage then failed the run.)
  const Coords x = {0,     0,     0,     1,     0,     0,      0,     1,     0,      0.25, 0.25, -0.05,
                    0.5,   0,     -0.15, 0.55,  0.5,   0,      0,     0.5,   -0.15,  0.125, 0.125, -0.075,
                    0.125, 0.625, -0.025, 0.625, 0.125, -0.025};
  JacobianCertifier certifier;
  const JacobianBounds jb = certifier.certify(CellType::Tetrahedron, 2, x.data());
  CHECK(jb.valid);
  CHECK(jb.proven);
  CHECK_FALSE(simplex_corners_positive<3>(CellType::Tetrahedron, x.data()));
  CHECK_FALSE(cell_valid<3>(certifier, CellType::Tetrahedron, 2, x.data()));
  // The apex above the plane (and the midnodes on the straight edges): both verdicts agree.
  Coords up = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.25, 0.25, 0.5};
  const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
  for (const auto& e : edges)
    for (int d = 0; d < 3; ++d) up.push_back(0.5 * (up[3 * e[0] + d] + up[3 * e[1] + d]));
  CHECK(cell_valid<3>(certifier, CellType::Tetrahedron, 2, up.data()));
  // Prisms have no corner simplex: the certificate alone decides.
  CHECK(simplex_corners_positive<3>(CellType::Prism, x.data()));
}
