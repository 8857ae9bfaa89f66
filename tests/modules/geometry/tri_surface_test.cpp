// SPDX-License-Identifier: MIT
#include "modules/geometry/tri_surface.h"

#include <doctest/doctest.h>

#include "modules/base/error.h"

namespace plaf {
namespace {

// A unit tetrahedron, outward.
TriangleSoup tetrahedron() {
  TriangleSoup s;
  s.source = "tet";
  s.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  return s;
}

TEST_CASE("tri_surface: soup round trip, Euler characteristic, straight high-order nodes") {
  TriSurface s = surface_from_soup(tetrahedron());
  CHECK(s.mesh.n_faces() == 4);
  CHECK(s.euler_characteristic() == 2);
  CHECK(s.tags.size() == 1);
  for (const auto e : s.mesh.edges()) CHECK(s.mesh.property(s.edge_curve, e) == -1);
  const TriangleSoup back = soup_from_surface(s);
  CHECK(back.triangles.size() == 4);
  // Straight order-3 nodes: edge nodes at thirds, the face node at the centroid.
  s.order = 3;
  const auto f = *s.mesh.faces().begin();
  const std::vector<Eigen::Vector3d> n = s.triangle_nodes(f);
  REQUIRE(n.size() == 10);
  CHECK((n[3] - (2 * n[0] + n[1]) / 3).norm() < 1e-15);
  CHECK((n[9] - (n[0] + n[1] + n[2]) / 3).norm() < 1e-15);
  // Curved edge nodes are read in the face's direction.
  const auto h = s.mesh.halfedge_handle(f);
  const auto e = s.mesh.edge_handle(h);
  const Eigen::Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(s.mesh.halfedge_handle(e, 0)));
  const Eigen::Vector3d b = s.mesh.point(s.mesh.to_vertex_handle(s.mesh.halfedge_handle(e, 0)));
  s.mesh.property(s.edge_nodes, e) = {a + (b - a) / 3 + Eigen::Vector3d(0, 0, 0.1), a + 2 * (b - a) / 3};
  for (const auto g : s.mesh.faces()) {
    const auto nodes = s.triangle_nodes(g);
    CHECK(nodes.size() == 10);
  }
  const std::vector<Eigen::Vector3d> m = s.triangle_nodes(f);
  const bool forward = s.mesh.halfedge_handle(e, 0) == h;
  CHECK((m[forward ? 3 : 4] - (a + (b - a) / 3 + Eigen::Vector3d(0, 0, 0.1))).norm() < 1e-15);
}

TEST_CASE("tri_surface: a non-manifold soup is refused with the triangle named") {
  TriangleSoup s = tetrahedron();
  s.points.push_back({1, 1, 1});
  s.triangles.push_back({0, 1, 4});  // a third face on edge (0, 1)
  CHECK_THROWS_WITH_AS(surface_from_soup(s), doctest::Contains("triangle 4"), MesherError);
}

}  // namespace
}  // namespace plaf
