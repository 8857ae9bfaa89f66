// SPDX-License-Identifier: MIT
#include "volume/tetgen_fill.h"

#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/mesh/quality.h"

using namespace plaf;

namespace {

// The surface of the box [0,a]^3, n x n squares per face split into outward triangles,
// tagged "wall" (fine enough that TetGen can place interior points without touching it).
HybridMesh<3> box_surface(double a, int n = 6) {
  HybridMesh<3> m;
  auto id = [n](int i, int j, int k) { return static_cast<NodeId>((k * (n + 1) + j) * (n + 1) + i); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.nodes.emplace_back(a * i / n, a * j / n, a * k / n);
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  CellBlock& b = m.boundary_block(CellType::Triangle, 1, wall);
  auto quad = [&](NodeId p, NodeId q, NodeId r, NodeId s) {
    b.connectivity.insert(b.connectivity.end(), {p, q, r, p, r, s});
  };
  for (int u = 0; u < n; ++u)
    for (int v = 0; v < n; ++v) {
      quad(id(u, v, 0), id(u, v + 1, 0), id(u + 1, v + 1, 0), id(u + 1, v, 0));  // z = 0, normal -z
      quad(id(u, v, n), id(u + 1, v, n), id(u + 1, v + 1, n), id(u, v + 1, n));  // z = a, normal +z
      quad(id(u, 0, v), id(u + 1, 0, v), id(u + 1, 0, v + 1), id(u, 0, v + 1));  // y = 0, normal -y
      quad(id(u, n, v), id(u, n, v + 1), id(u + 1, n, v + 1), id(u + 1, n, v));  // y = a, normal +y
      quad(id(0, u, v), id(0, u, v + 1), id(0, u + 1, v + 1), id(0, u + 1, v));  // x = 0, normal -x
      quad(id(n, u, v), id(n, u + 1, v), id(n, u + 1, v + 1), id(n, u, v + 1));  // x = a, normal +x
    }
  // The interior lattice points go to TetGen as free points and become vertices too.
  return m;
}

}  // namespace

TEST_CASE("volume: TetGen fills a box with positive tets whose volumes sum to the box's") {
  for (double a : {1e-6, 1.0, 1e6}) {
    volume::TetFillParams p;
    p.max_volume = a * a * a / 2000;
    const HybridMesh<3> m = volume::tetgen_fill(box_surface(a), p);
    const CellBlock& tets = m.cells.at(0);
    CHECK(tets.size() >= 100);
    double vol = 0;
    for (std::size_t i = 0; i < tets.size(); ++i) {
      const NodeId* c = tets.cell(i);
      const double v =
          (m.nodes[c[1]] - m.nodes[c[0]]).cross(m.nodes[c[2]] - m.nodes[c[0]]).dot(m.nodes[c[3]] - m.nodes[c[0]]) / 6;
      CHECK(v > 0);
      vol += v;
    }
    CHECK(vol == doctest::Approx(a * a * a).epsilon(1e-10));
    const QualityReport q = assess_quality<3>(m, nullptr, QualityOptions{});
    CHECK(q.cells_invalid == 0);
    CHECK(q.conformity.ok);
    CHECK(q.conformity.boundary_facets == 6 * 6 * 6 * 2);  // no Steiner points on the boundary (switch Y)
  }
}

TEST_CASE("volume: a boundary that is not linear triangles is an InputError") {
  CHECK_THROWS_AS(volume::tetgen_fill(HybridMesh<3>{}, {}), InputError);
  HybridMesh<3> curved = box_surface(1.0);
  curved.boundary[0].order = 2;
  CHECK_THROWS_AS(volume::tetgen_fill(curved, {}), InputError);
}
