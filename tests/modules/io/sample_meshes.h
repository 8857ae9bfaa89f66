// SPDX-License-Identifier: MIT
// Sample meshes for the I/O tests (MSH, CGNS): an annulus sector of every cell type and order on
// a shared integer lattice, with tagged boundaries; and comparisons of two meshes, exact (a
// round trip) or up to node numbering (a file another tool rewrote).
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "modules/elements/lagrange.h"
#include "modules/mesh/hybrid_mesh.h"

namespace plaf::test {

// Builds meshes from cells placed on a global integer lattice: a cell of order q with frame
// (O, A, B, C) has its local lattice point l at O + (l0 (A-O) + l1 (B-O) + l2 (C-O)) / q. Nodes at
// the same global lattice point are shared. A lattice step of `unit` per cell (divisible by 1..4)
// lets cells of every order share their vertices.
template <int Dim>
struct LatticeMesh {
  static constexpr int unit = 12;
  using Point = typename HybridMesh<Dim>::Point;
  HybridMesh<Dim> mesh;
  std::map<Lattice, NodeId> ids;
  std::vector<Lattice> where;  // global lattice point of each node
  std::function<Point(const Lattice&)> place;

  NodeId node(const Lattice& g) {
    auto [it, inserted] = ids.emplace(g, static_cast<NodeId>(mesh.nodes.size()));
    if (inserted) {
      mesh.nodes.push_back(place(g));
      where.push_back(g);
    }
    return it->second;
  }

  void add_cell(CellType t, int q, const std::array<Lattice, 4>& frame) {
    CellBlock& b = mesh.block(t, q);
    for (const Lattice& l : gmsh_lattice(t, q)) {
      Lattice g = frame[0];
      for (int d = 0; d < 3; ++d)
        for (int e = 0; e < 3; ++e) g[d] += l[e] * (frame[e + 1][d] - frame[0][d]) / q;
      b.connectivity.push_back(node(g));
    }
  }

  // Facets used by one cell become boundary facets, tagged by classify(vertex lattice points).
  void add_boundary(const std::function<std::pair<std::string, BoundaryKind>(const std::vector<Lattice>&)>& classify) {
    std::map<std::vector<NodeId>, std::pair<int, std::vector<NodeId>>> facets;  // sorted vertices -> uses, nodes
    std::map<std::vector<NodeId>, std::pair<CellType, int>> kinds;
    for (const CellBlock& b : mesh.cells) {
      const LagrangeElement& e = lagrange_element(b.type, b.order);
      for (std::size_t i = 0; i < b.size(); ++i)
        for (int f = 0; f < e.num_facets(); ++f) {
          const int nv = Dim == 2 ? 2 : static_cast<int>(topology(b.type).faces[f].size());
          std::vector<NodeId> nodes, key;
          for (int k : e.facet_nodes(f)) nodes.push_back(b.cell(i)[k]);
          key.assign(nodes.begin(), nodes.begin() + nv);
          std::sort(key.begin(), key.end());
          auto& use = facets[key];
          ++use.first;
          use.second = nodes;
          kinds[key] = {Dim == 2 ? CellType::Line : (nv == 3 ? CellType::Triangle : CellType::Quadrilateral), b.order};
        }
    }
    for (const auto& [key, use] : facets) {
      if (use.first != 1) continue;
      std::vector<Lattice> vertices;
      for (NodeId v : key) vertices.push_back(where[v]);
      const auto [name, kind] = classify(vertices);
      const auto [type, order] = kinds[key];
      CellBlock& b = mesh.boundary_block(type, order, mesh.add_tag(name, kind));
      b.connectivity.insert(b.connectivity.end(), use.second.begin(), use.second.end());
    }
  }
};

// Six times the signed volume of a tetrahedron of lattice points.
inline long lattice_volume(const std::array<Lattice, 4>& v) {
  long e[3][3];
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d) e[a][d] = v[a + 1][d] - v[0][d];
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

// An annulus sector r in [1, 2], theta in [0.1, 1.3] (and z in [0, 0.5] in 3D), nx x ny (x nz)
// lattice cells scaled by `scale`; order(i, j, k) gives each cell's order. In 2D the lower half
// of the theta range holds quadrilaterals, the upper half pairs of triangles; in 3D the lower half
// of z holds prisms and the upper half six (Kuhn) tetrahedra per cell.
template <int Dim>
HybridMesh<Dim> annulus_sector(int nx, int ny, int nz, double scale, const std::function<int(int, int, int)>& order) {
  constexpr int u = LatticeMesh<Dim>::unit;
  LatticeMesh<Dim> m;
  m.place = [&](const Lattice& g) {
    const double r = 1.0 + static_cast<double>(g[0]) / (u * nx);
    const double t = 0.1 + 1.2 * static_cast<double>(g[1]) / (u * ny);
    typename HybridMesh<Dim>::Point p;
    p[0] = scale * r * std::cos(t);
    p[1] = scale * r * std::sin(t);
    if constexpr (Dim == 3) p[2] = scale * 0.5 * static_cast<double>(g[2]) / (u * nz);
    return p;
  };
  for (int k = 0; k < (Dim == 3 ? nz : 1); ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int q = order(i, j, k);
        auto at = [&](int a, int b, int c) { return Lattice{u * (i + a), u * (j + b), u * (k + c)}; };
        if constexpr (Dim == 2) {
          if (2 * j < ny) {
            m.add_cell(CellType::Quadrilateral, q, {at(0, 0, 0), at(1, 0, 0), at(0, 1, 0), at(0, 0, 0)});
          } else {
            m.add_cell(CellType::Triangle, q, {at(0, 0, 0), at(1, 0, 0), at(1, 1, 0), at(0, 0, 0)});
            m.add_cell(CellType::Triangle, q, {at(0, 0, 0), at(1, 1, 0), at(0, 1, 0), at(0, 0, 0)});
          }
        } else if (2 * k < nz) {
          m.add_cell(CellType::Prism, q, {at(0, 0, 0), at(1, 0, 0), at(1, 1, 0), at(0, 0, 1)});
          m.add_cell(CellType::Prism, q, {at(0, 0, 0), at(1, 1, 0), at(0, 1, 0), at(0, 0, 1)});
        } else {
          // Kuhn: one tetrahedron per axis permutation, along the diagonal (0,0,0)-(1,1,1).
          const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
          for (const auto& p : perms) {
            std::array<int, 3> s{0, 0, 0};
            std::array<Lattice, 4> v;
            v[0] = at(0, 0, 0);
            for (int a = 0; a < 3; ++a) {
              s[p[a]] = 1;
              v[a + 1] = at(s[0], s[1], s[2]);
            }
            if (lattice_volume(v) < 0) std::swap(v[2], v[3]);
            m.add_cell(CellType::Tetrahedron, q, v);
          }
        }
      }
  m.add_boundary([&](const std::vector<Lattice>& vs) -> std::pair<std::string, BoundaryKind> {
    auto all = [&](int d, int value) {
      for (const Lattice& v : vs)
        if (v[d] != value) return false;
      return true;
    };
    if (all(0, 0)) return {"wall_inner", BoundaryKind::Wall};
    if (all(0, u * nx)) return {"Farfield", BoundaryKind::Farfield};
    if (all(1, 0)) return {"symmetry plane", BoundaryKind::Symmetry};
    return {"outlet", BoundaryKind::Named};
  });
  return m.mesh;
}

template <int Dim>
void check_same(const HybridMesh<Dim>& a, const HybridMesh<Dim>& b) {
  REQUIRE(a.nodes.size() == b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i)
    for (int d = 0; d < Dim; ++d) {
      INFO("node ", i, " coordinate ", d);
      CHECK(std::bit_cast<std::uint64_t>(a.nodes[i][d]) == std::bit_cast<std::uint64_t>(b.nodes[i][d]));
    }
  auto same_blocks = [](const std::vector<CellBlock>& x, const std::vector<CellBlock>& y) {
    REQUIRE(x.size() == y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      CHECK(x[i].type == y[i].type);
      CHECK(x[i].order == y[i].order);
      CHECK(x[i].tag == y[i].tag);
      CHECK(x[i].connectivity == y[i].connectivity);
    }
  };
  same_blocks(a.cells, b.cells);
  same_blocks(a.boundary, b.boundary);
  same_blocks(a.curves, b.curves);
  REQUIRE(a.tags.size() == b.tags.size());
  for (std::size_t i = 0; i < a.tags.size(); ++i) {
    CHECK(a.tags[i].name == b.tags[i].name);
    CHECK(a.tags[i].kind == b.tags[i].kind);
  }
}

// Each cell of the blocks as its type, order and the coordinates of its nodes in order (of a mesh
// of unit size, rounded to 1e-12), sorted:
// the same multiset in two files of one mesh (Gmsh may renumber nodes and cells, never move a node
// or reorder a cell's nodes).
inline std::vector<std::vector<double>> cell_keys(const std::vector<CellBlock>& blocks, const HybridMesh<3>& h) {
  std::vector<std::vector<double>> all;
  for (const CellBlock& blk : blocks)
    for (std::size_t c = 0; c < blk.size(); ++c) {
      std::vector<double> key = {static_cast<double>(blk.type), static_cast<double>(blk.order)};
      for (int k = 0; k < blk.nodes_per_cell(); ++k)
        for (int d = 0; d < 3; ++d)  // to 1e-12: Gmsh writes ASCII coordinates with 16 digits
          key.push_back(std::round(h.nodes[static_cast<std::size_t>(blk.cell(c)[k])][d] * 1e12) * 1e-12);
      all.push_back(key);
    }
  std::sort(all.begin(), all.end());
  return all;
}

}  // namespace plaf::test
