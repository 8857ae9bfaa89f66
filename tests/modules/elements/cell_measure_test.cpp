// SPDX-License-Identifier: MIT
#include "modules/elements/cell_measure.h"

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "modules/base/error.h"

using namespace plaf;

namespace {

constexpr CellType cell_types[] = {CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron, CellType::Prism};

// Measure of the reference cell (lagrange.h): triangle 1/2, square 1, tetrahedron 1/6, prism 1/2.
double reference_measure(CellType t) {
  switch (t) {
    case CellType::Triangle:
    case CellType::Prism:
      return 0.5;
    case CellType::Tetrahedron:
      return 1.0 / 6;
    default:
      return 1.0;
  }
}

using Map = Eigen::Vector3d (*)(const Eigen::Vector3d&);

// The nodes of (t, q) at x(r) for the reference node r, ref_dim(t) coordinates each.
template <class F>
std::vector<double> cell_at(CellType t, int q, F&& x) {
  const LagrangeElement& e = lagrange_element(t, q);
  std::vector<double> c;
  for (int i = 0; i < e.size(); ++i) {
    const auto r = e.ref_node(i);
    const Eigen::Vector3d p = x(Eigen::Vector3d(r[0], r[1], r[2]));
    for (int d = 0; d < e.dim(); ++d) c.push_back(p[d]);
  }
  return c;
}

// The cell's own map at reference point xi: sum_k phi_k(xi) x_k.
Eigen::Vector3d evaluate(CellType t, int q, const std::vector<double>& c, const Eigen::Vector3d& xi) {
  const LagrangeElement& e = lagrange_element(t, q);
  std::vector<double> phi(static_cast<std::size_t>(e.size()));
  e.eval(xi.data(), phi.data());
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int k = 0; k < e.size(); ++k)
    for (int d = 0; d < e.dim(); ++d)
      x[d] += phi[static_cast<std::size_t>(k)] * c[static_cast<std::size_t>(k * e.dim() + d)];
  return x;
}

// Positively oriented affine children xi = origin + m eta that tile the reference cell: 4
// triangles or squares, 8 tetrahedra (corners and the octahedron cut around one diagonal), 8
// prisms (4 triangles times 2 halves).
struct Child {
  Eigen::Vector3d origin;
  Eigen::Matrix3d m;
};
std::vector<Child> children(CellType t) {
  const auto simplex = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d) {
    Eigen::Matrix3d m;
    m << b - a, c - a, d - a;
    if (m.determinant() < 0) m.col(0).swap(m.col(1));  // keep the third column (a prism's axis)
    return Child{a, m};
  };
  const Eigen::Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  std::vector<Child> out;
  if (t == CellType::Quadrilateral) {
    for (double v : {0.0, 0.5})
      for (double u : {0.0, 0.5}) out.push_back({Eigen::Vector3d(u, v, 0), Eigen::Vector3d(0.5, 0.5, 1).asDiagonal()});
  } else if (t == CellType::Tetrahedron) {
    const Eigen::Vector3d m01 = x / 2, m02 = y / 2, m03 = z / 2, m12 = (x + y) / 2, m13 = (x + z) / 2,
                          m23 = (y + z) / 2;
    for (const auto& c : {simplex(o, m01, m02, m03), simplex(m01, x, m12, m13), simplex(m02, m12, y, m23),
                          simplex(m03, m13, m23, z), simplex(m01, m23, m02, m12), simplex(m01, m23, m12, m13),
                          simplex(m01, m23, m13, m03), simplex(m01, m23, m03, m02)})
      out.push_back(c);
  } else {
    const Eigen::Vector3d m01 = x / 2, m02 = y / 2, m12 = (x + y) / 2;
    const bool prism = t == CellType::Prism;
    const auto tri = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
      return simplex(a, b, c, a + z);  // the third column along the prism's axis
    };
    for (double w : prism ? std::vector<double>{0.0, 0.5} : std::vector<double>{0.0})
      for (auto c : {tri(o, m01, m02), tri(m01, x, m12), tri(m02, m12, y), tri(m12, m02, m01)}) {
        c.origin.z() = w;
        c.m(2, 2) = prism ? 0.5 : 1.0;
        out.push_back(c);
      }
  }
  return out;
}

}  // namespace

TEST_CASE("cell measure: affine cells measure |det A| times the reference cell, at every order") {
  Eigen::Matrix3d a;
  a << 2, 0.5, 0.1, 0.3, 1.5, 0.2, 0.1, -0.4, 1.2;  // det 3.563; its 2D block [[2, .5], [.3, 1.5]] 2.85
  for (CellType t : cell_types)
    for (int q = 1; q <= max_order; ++q) {
      INFO(std::string(cell_name(t)), " Q=", q);
      const double det_a = ref_dim(t) == 2 ? 2.85 : 3.563;
      const auto c =
          cell_at(t, q, [&](const Eigen::Vector3d& r) { return Eigen::Vector3d(a * r + Eigen::Vector3d(5, -3, 7)); });
      CHECK(cell_measure(t, q, c.data()) == doctest::Approx(det_a * reference_measure(t)).epsilon(1e-13));
      // Mirrored: the measure is signed.
      const auto m =
          cell_at(t, q, [&](const Eigen::Vector3d& r) { return Eigen::Vector3d(-(a * r)[0], (a * r)[1], (a * r)[2]); });
      CHECK(cell_measure(t, q, m.data()) == doctest::Approx(-det_a * reference_measure(t)).epsilon(1e-13));
    }
  CHECK_THROWS_AS(cell_measure(CellType::Line, 2, std::vector<double>(3).data()), InputError);
}

TEST_CASE("cell measure: a prism of height 1 + b u^Q has volume 1/2 + b / ((Q+1)(Q+2))") {
  // x = (u, v, w (1 + b u^Q)) lies in the prism's space and has det J = 1 + b u^Q; over the
  // reference triangle, the integral of u^Q is Q! 1! / (Q + 2)! = 1 / ((Q+1)(Q+2)).
  for (int q = 1; q <= max_order; ++q) {
    const double b = 0.7;
    const auto c = cell_at(CellType::Prism, q, [&](const Eigen::Vector3d& r) {
      return Eigen::Vector3d(r[0], r[1], r[2] * (1 + b * std::pow(r[0], q)));
    });
    CHECK(cell_measure(CellType::Prism, q, c.data()) == doctest::Approx(0.5 + b / ((q + 1) * (q + 2))).epsilon(1e-14));
  }
}

TEST_CASE("cell measure: exact for det J of full degree, so additive over the cell's re-interpolated children") {
  // A degree-Q map restricted to an affine child of the reference cell is a degree-Q map of the
  // child's own reference coordinates: the child's nodes, taken from the parent's map, represent
  // it exactly. Exact integration of det J then gives parent = sum of children to rounding; a
  // rule too short for det J's degree would miss by its quadrature error, which for these
  // strongly curved cells is far above rounding.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.12, 0.12);
  for (CellType t : cell_types)
    for (int q = 1; q <= max_order; ++q) {
      INFO(std::string(cell_name(t)), " Q=", q);
      const int dim = ref_dim(t);
      std::vector<double> c = cell_at(t, q, [](const Eigen::Vector3d& r) {
        return Eigen::Vector3d(r[0] + 0.3 * r[1] * r[1], r[1] + 0.2 * r[0] * r[2], r[2] + 0.25 * r[0] * r[1]);
      });
      for (std::size_t k = static_cast<std::size_t>(num_vertices(t) * dim); k < c.size(); ++k) c[k] += jitter(rng) / q;
      const double whole = cell_measure(t, q, c.data());
      REQUIRE(whole > 0);
      double parts = 0;
      for (const Child& ch : children(t)) {
        const auto sub = cell_at(t, q, [&](const Eigen::Vector3d& eta) {
          Eigen::Vector3d xi = ch.origin + ch.m * eta;
          for (int d = dim; d < 3; ++d) xi[d] = 0;
          return evaluate(t, q, c, xi);
        });
        parts += cell_measure(t, q, sub.data());
      }
      CHECK(parts == doctest::Approx(whole).epsilon(1e-13));
    }
}
