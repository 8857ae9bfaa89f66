// SPDX-License-Identifier: MIT
#include "modules/mesh/untangle3d.h"

#include <doctest/doctest.h>

#include <array>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"

using namespace plaf;

namespace {

// One order-2 fill tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,h) whose edge 0-1 bulges by
// `bulge` along +z. Its face (0,1,2) is a boundary facet (a curved front triangle: its nodes
// stay); the three edges to vertex 3 are the fill's own. At vertex 1 the Jacobian is h - 4 bulge
// (the edge's tangent there turns down by 4 bulge), so a bulge above h / 4 inverts the cell.
struct BulgedTet {
  HybridMesh<3> mesh;
  std::array<NodeId, 10> ids{};
  int node_on(int a, int b) const {  // local index of the order-2 node between vertices a and b
    std::array<int, 4> w = {0, 0, 0, 0};
    w[static_cast<std::size_t>(a)] = w[static_cast<std::size_t>(b)] = 1;
    return lagrange_element(CellType::Tetrahedron, 2).find(Lattice{w[1], w[2], w[3]});
  }
  BulgedTet(double h, double bulge, bool front_on_top = false) {
    const LagrangeElement& el = lagrange_element(CellType::Tetrahedron, 2);
    const std::array<Eigen::Vector3d, 4> v = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                              Eigen::Vector3d(0, 0, h)};
    CellBlock& b = mesh.block(CellType::Tetrahedron, 2);
    for (int k = 0; k < el.size(); ++k) {
      const Lattice& l = el.lattice()[static_cast<std::size_t>(k)];
      const std::array<int, 4> w = {2 - l[0] - l[1] - l[2], l[0], l[1], l[2]};
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int i = 0; i < 4; ++i) p += 0.5 * w[static_cast<std::size_t>(i)] * v[static_cast<std::size_t>(i)];
      ids[static_cast<std::size_t>(k)] = static_cast<NodeId>(mesh.nodes.size());
      mesh.nodes.push_back(p);
      b.connectivity.push_back(ids[static_cast<std::size_t>(k)]);
    }
    mesh.nodes[static_cast<std::size_t>(ids[static_cast<std::size_t>(node_on(0, 1))])].z() += bulge;
    // The front: face (0,1,2); with front_on_top also the faces on vertex 3, so no node is free.
    const int tag = mesh.add_tag("front", BoundaryKind::Named);
    CellBlock& f = mesh.boundary_block(CellType::Triangle, 2, tag);
    auto face = [&](int a, int c, int d) {
      for (int k : {a, c, d}) f.connectivity.push_back(ids[static_cast<std::size_t>(k)]);
      for (auto [p, r] : {std::pair{a, c}, std::pair{c, d}, std::pair{d, a}})
        f.connectivity.push_back(ids[static_cast<std::size_t>(node_on(p, r))]);
    };
    face(0, 2, 1);
    if (front_on_top) {
      face(0, 1, 3);
      face(1, 2, 3);
      face(0, 3, 2);
    }
  }
  const Eigen::Vector3d& x(int k) const { return mesh.nodes[static_cast<std::size_t>(ids[static_cast<std::size_t>(k)])]; }
  // The front triangle's nodes (vertices 0, 1, 2 and their edges) are where they were.
  bool front_unmoved(const std::vector<Eigen::Vector3d>& before) const {
    for (int k : {0, 1, 2, node_on(0, 1), node_on(1, 2), node_on(0, 2)})
      if (x(k) != before[static_cast<std::size_t>(ids[static_cast<std::size_t>(k)])]) return false;
    return true;
  }
  bool valid() {
    JacobianCertifier certifier;
    std::vector<double> xs;
    for (NodeId id : ids)
      for (int d = 0; d < 3; ++d) xs.push_back(mesh.nodes[static_cast<std::size_t>(id)][d]);
    return certifier.certify(CellType::Tetrahedron, 2, xs.data()).valid;
  }
};

}  // namespace

TEST_CASE("untangle 3D: a fill tetrahedron inverted by a curved front edge is untangled by its own edges only") {
  BulgedTet t(0.1, 0.05);  // h - 4 bulge = -0.1 at vertex 1
  REQUIRE_FALSE(t.valid());
  const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
  const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
  CHECK(u.curved == 1);
  CHECK(u.invalid_before == 1);
  CHECK(u.invalid_after == 0);
  CHECK(u.nodes_moved >= 1);
  CHECK(t.valid());
  // The vertices and the front triangle's nodes did not move; only the edges to vertex 3 did.
  CHECK(t.front_unmoved(before));
  CHECK(t.x(3) == before[static_cast<std::size_t>(t.ids[3])]);
}

TEST_CASE("untangle 3D: the vertex off the front untangles the cell alone, its edges carried along") {
  BulgedTet t(0.1, 0.05);
  REQUIRE_FALSE(t.valid());
  const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
  const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0, UntangleMoves{.nodes = false, .vertices = true});
  CHECK(u.invalid_before == 1);
  CHECK(u.invalid_after == 0);
  CHECK(u.nodes_moved == 0);
  CHECK(u.vertices_moved == 1);
  CHECK(t.valid());
  CHECK(t.front_unmoved(before));
  CHECK(t.mesh.nodes[static_cast<std::size_t>(t.ids[3])].z() > 0.1);  // vertex 3 rose
  // ... and carried its straight edges along: they are still straight.
  for (int a : {0, 1, 2}) {
    const Eigen::Vector3d mid = 0.5 * (t.mesh.nodes[static_cast<std::size_t>(t.ids[static_cast<std::size_t>(a)])] +
                                       t.mesh.nodes[static_cast<std::size_t>(t.ids[3])]);
    CHECK((t.mesh.nodes[static_cast<std::size_t>(t.ids[static_cast<std::size_t>(t.node_on(a, 3))])] - mid).norm() < 1e-12);
  }
}

TEST_CASE("untangle 3D: a valid curved fill is left as it is, a cell with no free node is made straight or left and counted") {
  SUBCASE("valid") {
    BulgedTet t(0.1, 0.01);  // h - 4 bulge = 0.06
    REQUIRE(t.valid());
    const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
    const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
    CHECK(u.curved == 1);
    CHECK(u.invalid_before == 0);
    CHECK(u.nodes_moved == 0);
    CHECK(t.mesh.nodes == before);
  }
  SUBCASE("every node on the front: the last resort makes it straight, the boundary's bulge given up and measured") {
    BulgedTet t(0.1, 0.05, true);
    const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
    const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
    CHECK(u.invalid_before == 1);
    CHECK(u.invalid_after == 0);
    CHECK(u.nodes_moved == 0);
    CHECK(u.cells_straightened == 1);
    CHECK(u.straightened == 1);  // the one curved node, on the front
    CHECK(u.straightened_max == doctest::Approx(0.05));
    CHECK(t.valid());
    // Straight: the bulged edge's node is back at its midpoint; the vertices did not move.
    CHECK((t.x(t.node_on(0, 1)) - 0.5 * (t.x(0) + t.x(1))).norm() < 1e-15);
    for (int k = 0; k < 4; ++k) CHECK(t.x(k) == before[static_cast<std::size_t>(t.ids[static_cast<std::size_t>(k)])]);
  }
  SUBCASE("a cell inverted even straight is left as it was and counted") {
    BulgedTet t(-0.1, 0.05, true);  // the apex below the front: the linear tetrahedron is inverted
    const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
    const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
    CHECK(u.invalid_before == 1);
    CHECK(u.invalid_after == 1);
    CHECK(u.cells_straightened == 0);
    CHECK(u.straightened == 0);
    CHECK(t.mesh.nodes == before);
    CHECK_FALSE(t.valid());
  }
  SUBCASE("a straight fill is not looked at") {
    BulgedTet t(0.1, 0.0);
    const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
    CHECK(u.curved == 0);
    CHECK(u.certified == 0);
  }
}

TEST_CASE("untangle 3D: a flat straight tetrahedron (a TetGen sliver at the front) is untangled by its free vertex") {
  // Straight, its apex 1e-9 below the front's plane: a signed volume within rounding of 0 that the
  // certificate calls invalid. It is no curved cell, but its vertex off the front lifts it.
  BulgedTet t(-1e-9, 0);
  REQUIRE_FALSE(t.valid());
  const std::vector<Eigen::Vector3d> before = t.mesh.nodes;
  const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
  CHECK(u.curved == 0);
  CHECK(u.flat == 1);
  CHECK(u.invalid_before == 1);
  CHECK(u.invalid_after == 0);
  CHECK(u.vertices_moved == 1);
  CHECK(t.valid());
  CHECK(t.front_unmoved(before));
}

TEST_CASE("untangle 3D: a straight fill of cells not near flat is not certified") {
  BulgedTet t(1e-3, 0);  // a valid sliver 1e-3 tall over a unit triangle: 6V = 1e-3, over 1e-6 of its span cubed
  REQUIRE(t.valid());
  const FillUntangling u = untangle_fill_3d(t.mesh, 0, 0);
  CHECK(u.certified == 0);
  CHECK(u.flat == 0);
  CHECK(u.invalid_before == 0);
}
