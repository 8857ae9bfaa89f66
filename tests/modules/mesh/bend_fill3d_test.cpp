// SPDX-License-Identifier: MIT
#include "modules/mesh/bend_fill3d.h"
#include "modules/mesh/untangle3d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"

using namespace plaf;

namespace {

// The unit square's column [0, 1]^2 x [0, 1] in n x n x levels hexahedra, each cut into Kuhn's 6
// tetrahedra (conforming: every square is cut along its diagonal from (0, 0) to (1, 1)), at order
// 2, its levels thin at the bottom (0, 0.02, 0.04, 0.08, ...). The bottom is a curved front: its
// vertices stay at z = 0, the midpoint of each of its edges rises by bulge * 16 x (1 - x) y (1 - y)
// (zero on the square's sides, so the side facets stay flat; bulge / edge 0.12 at the centre for
// n = 4, bulge 0.03, about the spot's 0.1), more than the lowest level is thick.
struct Column {
  HybridMesh<3> mesh;
  std::vector<std::uint8_t> boundary;  // the node is on a boundary facet
  std::vector<std::uint8_t> front;     // ... on the bottom
  Column(int n, double bulge) {
    const std::vector<double> z = {0, 0.02, 0.04, 0.08, 0.16, 0.32, 0.64, 1.0};
    const int levels = static_cast<int>(z.size()) - 1;
    auto vid = [&](int i, int j, int k) { return static_cast<NodeId>((k * (n + 1) + j) * (n + 1) + i); };
    for (int k = 0; k <= levels; ++k)
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
          mesh.nodes.emplace_back(static_cast<double>(i) / n, static_cast<double>(j) / n,
                                  z[static_cast<std::size_t>(k)]);
    const LagrangeElement& el = lagrange_element(CellType::Tetrahedron, 2);
    std::map<std::pair<NodeId, NodeId>, NodeId> mid;
    auto midpoint = [&](NodeId a, NodeId b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = mid.emplace(key, static_cast<NodeId>(mesh.nodes.size()));
      if (added)
        mesh.nodes.push_back(0.5 * (mesh.nodes[static_cast<std::size_t>(a)] + mesh.nodes[static_cast<std::size_t>(b)]));
      return it->second;
    };
    CellBlock& tets = mesh.block(CellType::Tetrahedron, 2);
    std::map<std::array<NodeId, 3>, std::pair<int, std::array<NodeId, 6>>> faces;  // sorted vertices -> count, nodes
    const std::array<std::array<int, 3>, 6> perms = {
        {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
    for (int k = 0; k < levels; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (const auto& p : perms) {
            std::array<int, 3> c = {0, 0, 0};
            std::array<NodeId, 4> v{};
            v[0] = vid(i, j, k);
            for (int s = 0; s < 3; ++s) {
              c[static_cast<std::size_t>(p[static_cast<std::size_t>(s)])] = 1;
              v[static_cast<std::size_t>(s + 1)] = vid(i + c[0], j + c[1], k + c[2]);
            }
            auto X = [&](int a) { return mesh.nodes[static_cast<std::size_t>(v[static_cast<std::size_t>(a)])]; };
            if ((X(1) - X(0)).cross(X(2) - X(0)).dot(X(3) - X(0)) < 0) std::swap(v[1], v[2]);
            std::array<NodeId, 10> cell{};
            for (int m = 0; m < el.size(); ++m) {
              const Lattice& l = el.lattice()[static_cast<std::size_t>(m)];
              const std::array<int, 4> w = {2 - l[0] - l[1] - l[2], l[0], l[1], l[2]};
              std::vector<NodeId> on;
              for (int a = 0; a < 4; ++a)
                for (int r = 0; r < w[static_cast<std::size_t>(a)]; ++r) on.push_back(v[static_cast<std::size_t>(a)]);
              cell[static_cast<std::size_t>(m)] = on[0] == on[1] ? on[0] : midpoint(on[0], on[1]);
            }
            tets.connectivity.insert(tets.connectivity.end(), cell.begin(), cell.end());
            for (int f = 0; f < 4; ++f) {
              const std::vector<int>& fn = el.facet_nodes(f);
              std::array<NodeId, 6> nodes{};
              for (std::size_t m = 0; m < 6; ++m) nodes[m] = cell[static_cast<std::size_t>(fn[m])];
              std::array<NodeId, 3> key = {nodes[0], nodes[1], nodes[2]};
              std::sort(key.begin(), key.end());
              auto& e = faces[key];
              ++e.first;
              e.second = nodes;
            }
          }
    const int wall = mesh.add_tag("front", BoundaryKind::Wall);
    const int far = mesh.add_tag("box", BoundaryKind::Farfield);
    boundary.assign(mesh.nodes.size(), 0);
    front.assign(mesh.nodes.size(), 0);
    for (const auto& [key, e] : faces) {
      if (e.first != 1) continue;
      bool bottom = true;
      for (NodeId id : key) bottom = bottom && mesh.nodes[static_cast<std::size_t>(id)].z() == 0;
      CellBlock& f = mesh.boundary_block(CellType::Triangle, 2, bottom ? wall : far);
      f.connectivity.insert(f.connectivity.end(), e.second.begin(), e.second.end());
      for (NodeId id : e.second) {
        boundary[static_cast<std::size_t>(id)] = 1;
        if (bottom) front[static_cast<std::size_t>(id)] = 1;
      }
    }
    for (const auto& [key, m] : mid) {
      Eigen::Vector3d& x = mesh.nodes[static_cast<std::size_t>(m)];
      if (front[static_cast<std::size_t>(m)]) x.z() += bulge * 16 * x.x() * (1 - x.x()) * x.y() * (1 - x.y());
    }
  }
  std::size_t invalid() const {
    JacobianCertifier certifier;
    std::size_t bad = 0;
    const CellBlock& b = mesh.cells[0];
    std::vector<double> xs;
    for (std::size_t c = 0; c < b.size(); ++c) {
      xs.clear();
      for (int k = 0; k < 10; ++k)
        for (int d = 0; d < 3; ++d) xs.push_back(mesh.nodes[static_cast<std::size_t>(b.cell(c)[k])][d]);
      bad += certifier.certify(CellType::Tetrahedron, 2, xs.data()).valid ? 0 : 1;
    }
    return bad;
  }
};

}  // namespace

TEST_CASE("bend fill 3D: a fill thinner than its curved front's bulge bends with it and is valid") {
  Column col(4, 0.03);
  REQUIRE(col.invalid() > 0);  // the straight fill's lowest cells are inverted by the bulge
  const std::vector<Eigen::Vector3d> before = col.mesh.nodes;
  const FillBending bent = bend_fill_3d(col.mesh, 0, 0);
  CHECK(bent.curved_faces == 32);  // every bottom triangle has an edge inside the square
  CHECK(bent.nodes_moved > 0);
  // Here every fill node lies over a vertex or an edge midpoint of a front triangle, where the
  // triangle's displacement is a node's: none moves further than the largest bulge.
  CHECK(bent.max_shift <= 0.03 + 1e-12);
  CHECK(col.invalid() == 0);
  // The guard's counts: the cells the map moved were inverted before, none after, nothing put back.
  CHECK(bent.invalid_before > 0);
  CHECK(bent.invalid_after == 0);
  CHECK(bent.nodes_returned == 0);
  // The boundary stays; a node beyond the reach of every front triangle (its longest edge, the
  // diagonal 0.354) does not move. Above the centre (0.375, 0.375) of a square, the midpoint of its
  // diagonal from (0.25, 0.25) to (0.5, 0.5), which rose by bulge_there, the fill's nodes (the
  // midpoints of the hexahedra's main diagonals and of the levels' diagonals) rise less, less
  // further up.
  const double bulge_there = 0.03 * 16 * std::pow(0.375 * 0.625, 2);
  double lowest = -1, higher = -1;
  for (std::size_t i = 0; i < before.size(); ++i) {
    const Eigen::Vector3d d = col.mesh.nodes[i] - before[i];
    if (col.boundary[i]) {
      CHECK(d.norm() == 0);
      continue;
    }
    if (before[i].z() >= 0.36) CHECK(d.norm() == 0);
    if (std::abs(before[i].x() - 0.375) < 1e-12 && std::abs(before[i].y() - 0.375) < 1e-12) {
      if (std::abs(before[i].z() - 0.01) < 1e-12) lowest = d.z();
      if (std::abs(before[i].z() - 0.12) < 1e-12) higher = d.z();
    }
  }
  CHECK(lowest > 0.5 * bulge_there);
  CHECK(lowest <= bulge_there + 1e-12);
  CHECK(higher >= 0);
  CHECK(higher < lowest);
}

TEST_CASE("bend fill 3D: a straight front moves nothing") {
  Column col(4, 0.0);
  const std::vector<Eigen::Vector3d> before = col.mesh.nodes;
  const FillBending bent = bend_fill_3d(col.mesh, 0, 0);
  CHECK(bent.curved_faces == 0);
  CHECK(bent.nodes_moved == 0);
  CHECK(col.mesh.nodes == before);
  CHECK(col.invalid() == 0);
}

TEST_CASE("bend fill 3D: without the bend, the untangler's last resort makes the bulge's cells straight") {
  // The same column, untangled with no node or vertex moves: only the last resort acts. The
  // lowest cells are inverted by the front's bulge; making one straight puts its front edges
  // back on their chords, which straightens the cells around those edges too (fewer cells made
  // straight than were inverted).
  Column col(4, 0.03);
  const std::size_t inverted = col.invalid();
  REQUIRE(inverted > 1);
  const std::vector<Eigen::Vector3d> before = col.mesh.nodes;
  const FillUntangling u = untangle_fill_3d(col.mesh, 0, 0, UntangleMoves{.nodes = false, .vertices = false});
  CHECK(u.invalid_before == inverted);
  CHECK(u.invalid_after == 0);
  CHECK(col.invalid() == 0);
  CHECK(u.cells_straightened > 0);
  CHECK(u.cells_straightened < inverted);
  CHECK(u.straightened > 0);  // front nodes: the bulge given up there, and measured
  CHECK(u.straightened_max > 0.01);
  CHECK(u.straightened_max <= 0.03 + 1e-12);
  // Off the front, only nodes of the lowest level (z <= 0.02) moved: the region stays local.
  for (std::size_t i = 0; i < before.size(); ++i)
    if (!col.front[i] && before[i].z() > 0.02 + 1e-12) CHECK(col.mesh.nodes[i] == before[i]);
}
