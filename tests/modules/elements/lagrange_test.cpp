// SPDX-License-Identifier: MIT
#include "modules/elements/lagrange.h"

#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/error.h"

using namespace plaf;

namespace {

constexpr CellType all_types[] = {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
                                  CellType::Prism};

// A random point inside the reference cell.
std::array<double, 3> random_point(CellType t, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::array<double, 3> x{u(rng), u(rng), u(rng)};
  if (t == CellType::Triangle || t == CellType::Prism) {
    if (x[0] + x[1] > 1) x = {1 - x[0], 1 - x[1], x[2]};
  } else if (t == CellType::Tetrahedron) {
    while (x[0] + x[1] + x[2] > 1) x = {u(rng), u(rng), u(rng)};
  }
  for (int d = ref_dim(t); d < 3; ++d) x[d] = 0.0;
  return x;
}

}  // namespace

TEST_CASE("lagrange: node orders equal Gmsh's and VTK's (tests/data/node_orders.txt, from their APIs)") {
  std::ifstream in(PLAF_TEST_DATA "/node_orders.txt");
  REQUIRE(in.good());
  std::string line;
  int checked = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string who, name;
    int q = 0, code = 0, n = 0;
    s >> who >> name >> q >> code >> n;
    CellType type{};
    for (CellType t : all_types)
      if (name == cell_name(t)) type = t;
    REQUIRE(std::string(cell_name(type)) == name);
    const int dim = ref_dim(type);
    const auto expected_nodes = who == "gmsh" ? gmsh_lattice(type, q) : vtk_lattice(type, q);
    REQUIRE(n == num_nodes(type, q));
    REQUIRE(static_cast<int>(expected_nodes.size()) == n);
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < dim; ++d) {
        int c = 0;
        s >> c;
        INFO(who, " ", name, " Q=", q, " node ", i);
        CHECK(expected_nodes[i][d] == c);
      }
    ++checked;
  }
  CHECK(checked == 40);  // 5 types x 4 orders x {gmsh, vtk}
}

TEST_CASE("lagrange: Kronecker property, partition of unity and exact polynomials of degree Q") {
  std::mt19937 rng(7);
  for (CellType t : all_types)
    for (int q = 1; q <= max_order; ++q) {
      const LagrangeElement& e = lagrange_element(t, q);
      const int n = e.size();
      std::vector<double> phi(n), grad(n * e.dim());
      for (int i = 0; i < n; ++i) {
        const auto x = e.ref_node(i);
        e.eval(x.data(), phi.data());
        for (int j = 0; j < n; ++j) CHECK(phi[j] == doctest::Approx(i == j ? 1.0 : 0.0));
      }
      // f = (1 + x + 2y - z)^Q lies in every space here (total degree Q).
      auto f = [&](const std::array<double, 3>& x) { return std::pow(1 + x[0] + 2 * x[1] - x[2], q); };
      for (int trial = 0; trial < 20; ++trial) {
        const auto x = random_point(t, rng);
        e.eval(x.data(), phi.data());
        e.eval_grad(x.data(), grad.data());
        double sum = 0, fi = 0;
        std::array<double, 3> gsum{0, 0, 0}, gf{0, 0, 0};
        for (int i = 0; i < n; ++i) {
          sum += phi[i];
          fi += phi[i] * f(e.ref_node(i));
          for (int d = 0; d < e.dim(); ++d) {
            gsum[d] += grad[i * e.dim() + d];
            gf[d] += grad[i * e.dim() + d] * f(e.ref_node(i));
          }
        }
        CHECK(sum == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(fi == doctest::Approx(f(x)).epsilon(1e-11));
        const double base = q * std::pow(1 + x[0] + 2 * x[1] - x[2], q - 1);
        const double exact_grad[3] = {base, 2 * base, -base};
        for (int d = 0; d < e.dim(); ++d) {
          CHECK(gsum[d] == doctest::Approx(0.0).scale(1.0).epsilon(1e-11));
          CHECK(gf[d] == doctest::Approx(exact_grad[d]).epsilon(1e-10));
        }
      }
    }
}

TEST_CASE("lagrange: edge and facet nodes lie on their edge/facet, Q+1 per edge") {
  for (CellType t : all_types)
    for (int q = 1; q <= max_order; ++q) {
      const LagrangeElement& e = lagrange_element(t, q);
      const CellTopology& topo = topology(t);
      for (std::size_t k = 0; k < topo.edges.size(); ++k) {
        const auto& nodes = e.edge_nodes(static_cast<int>(k));
        REQUIRE(static_cast<int>(nodes.size()) == q + 1);
        CHECK(nodes.front() == topo.edges[k][0]);
        CHECK(nodes.back() == topo.edges[k][1]);
        for (int i : nodes) CHECK(i >= 0);
      }
      for (int f = 0; f < e.num_facets(); ++f) {
        const auto& nodes = e.facet_nodes(f);
        for (int i : nodes) REQUIRE(i >= 0);
        if (ref_dim(t) == 3) {
          const CellType ft = topo.faces[f].size() == 3 ? CellType::Triangle : CellType::Quadrilateral;
          CHECK(static_cast<int>(nodes.size()) == num_nodes(ft, q));
          for (std::size_t v = 0; v < topo.faces[f].size(); ++v) CHECK(nodes[v] == topo.faces[f][v]);
        }
      }
    }
}

TEST_CASE("lagrange: an order outside 1..4 is a ConfigError naming the order") {
  CHECK_THROWS_AS(lagrange_element(CellType::Triangle, 0), ConfigError);
  CHECK_THROWS_WITH_AS(lagrange_element(CellType::Quadrilateral, 7), "geometry order 7 is outside 1..4", ConfigError);
}

TEST_CASE("lagrange: find gives every node back from its lattice point, and -1 off the lattice") {
  for (CellType t : {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron, CellType::Prism})
    for (int q = 1; q <= max_order; ++q) {
      CAPTURE(q);
      const LagrangeElement& e = lagrange_element(t, q);
      for (int i = 0; i < e.size(); ++i) CHECK(e.find(e.lattice()[static_cast<std::size_t>(i)]) == i);
      CHECK(e.find({-1, 0, 0}) == -1);
      CHECK(e.find({0, q + 1, 0}) == -1);
      CHECK(e.find({0, 0, 99}) == -1);
      if (t == CellType::Triangle || t == CellType::Tetrahedron) CHECK(e.find({q, q, 0}) == -1);  // outside the simplex
    }
}
