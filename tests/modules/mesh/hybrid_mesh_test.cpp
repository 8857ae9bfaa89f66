// SPDX-License-Identifier: MIT
#include "modules/mesh/hybrid_mesh.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "tests/modules/mesh/structured_mesh.h"

using namespace plaf;
using plaf::test::StructuredMesh;

namespace {

struct Counts {
  std::size_t interior = 0, boundary = 0, open = 0, overshared = 0, mismatches = 0, stray = 0;
};

void check_counts(const ConformityReport& r, const Counts& want) {
  CHECK(r.interior_facets == want.interior);
  CHECK(r.boundary_facets == want.boundary);
  CHECK(r.open_facets == want.open);
  CHECK(r.overshared_facets == want.overshared);
  CHECK(r.node_mismatches == want.mismatches);
  CHECK(r.stray_boundary == want.stray);
  const bool clean = want.open + want.overshared + want.mismatches + want.stray + r.orientation_mismatches == 0;
  CHECK(r.ok == clean);
  CHECK(r.first_problem.empty() == clean);
}

// Facet counts of the structured meshes (structured_mesh.h), counted per direction.
// nx x ny quads: the ny - 1 inner horizontal lines carry nx edges each, the nx - 1 inner
// vertical lines ny each; the box outline has 2 (nx + ny) edges.
Counts quad_counts(std::size_t nx, std::size_t ny) {
  return {nx * (ny - 1) + ny * (nx - 1), 2 * (nx + ny)};
}
// Each square's diagonal adds one interior edge.
Counts triangle_counts(std::size_t nx, std::size_t ny) {
  Counts c = quad_counts(nx, ny);
  c.interior += nx * ny;
  return c;
}
// Prisms: 2 nx ny triangles per horizontal plane (nz - 1 inner planes; bottom and top on the
// boundary), and each of the nz layers has one quadrilateral per edge of the triangle grid.
Counts prism_counts(std::size_t nx, std::size_t ny, std::size_t nz) {
  const Counts t = triangle_counts(nx, ny);
  return {2 * nx * ny * (nz - 1) + nz * t.interior, 4 * nx * ny + nz * t.boundary};
}
// Kuhn tets: T = 6 nx ny nz tets of 4 faces, so 4 T = 2 I + B; each boundary square is cut into
// 2 triangles, B = 4 (nx ny + ny nz + nz nx).
Counts tet_counts(std::size_t nx, std::size_t ny, std::size_t nz) {
  const std::size_t b = 4 * (nx * ny + ny * nz + nz * nx);
  return {(4 * 6 * nx * ny * nz - b) / 2, b};
}

// "facet with vertices a b ...", sorted, as check_conformity names facets.
std::string facet_text(std::vector<NodeId> v) {
  std::sort(v.begin(), v.end());
  std::string s = "facet with vertices";
  for (NodeId x : v) s += ' ' + std::to_string(x);
  return s;
}

bool ends_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(s.size() - p.size(), p.size(), p) == 0;
}

int facet_vertex_count(CellType t, int f) {
  return ref_dim(t) == 2 ? 2 : static_cast<int>(topology(t).faces[f].size());
}

std::vector<NodeId> facet_vertices(const CellBlock& b, std::size_t i, int f) {
  const LagrangeElement& e = lagrange_element(b.type, b.order);
  std::vector<NodeId> v;
  for (int k = 0; k < facet_vertex_count(b.type, f); ++k) v.push_back(b.cell(i)[e.facet_nodes(f)[k]]);
  return v;
}

std::vector<NodeId> facet_all_nodes(const CellBlock& b, std::size_t i, int f) {
  std::vector<NodeId> v;
  for (int l : lagrange_element(b.type, b.order).facet_nodes(f)) v.push_back(b.cell(i)[l]);
  return v;
}

// Whether facet f of cell i (block 0) lies on a side of the box, decided from lattice points.
template <int Dim>
bool on_box_side(const StructuredMesh<Dim>& s, std::size_t i, int f) {
  const CellBlock& b = s.mesh.cells[0];
  for (int d = 0; d < Dim; ++d)
    for (int side = 0; side < 2; ++side) {
      bool all = true;
      for (NodeId v : facet_vertices(b, i, f)) all = all && s.fine_of(v)[d] == side * s.cubes(d) * s.order();
      if (all) return true;
    }
  return false;
}

template <int Dim>
int first_inner_facet(const StructuredMesh<Dim>& s, std::size_t i) {
  for (int f = 0; f < lagrange_element(s.mesh.cells[0].type, s.order()).num_facets(); ++f)
    if (!on_box_side(s, i, f)) return f;
  return -1;
}

// One mesh of each kind at order q with its derived counts. Every mesh has a single block.
template <class F>
void for_each_mesh(int q, F&& f) {
  f("quads 3x2", plaf::test::quad_grid(3, 2, q), quad_counts(3, 2));
  f("triangles 2x3", plaf::test::triangle_grid(2, 3, q), triangle_counts(2, 3));
  f("prisms 2x1x2", plaf::test::prism_block(2, 1, 2, q), prism_counts(2, 1, 2));
  f("tets 2x1x1", plaf::test::kuhn_tets(2, 1, 1, q), tet_counts(2, 1, 1));
}

}  // namespace

TEST_CASE("mesh: structured grids of order 1..4 conform, with facet counts derived from their size") {
  for (int q = 1; q <= max_order; ++q)
    for (const std::array<int, 3>& n : {std::array<int, 3>{1, 1, 1}, {3, 2, 2}, {4, 5, 1}}) {
      INFO("Q=", q, " n=", n[0], "x", n[1], "x", n[2]);
      const auto nx = static_cast<std::size_t>(n[0]), ny = static_cast<std::size_t>(n[1]),
                 nz = static_cast<std::size_t>(n[2]);
      const auto quads = plaf::test::quad_grid(n[0], n[1], q);
      CHECK(quads.mesh.num_cells() == nx * ny);
      check_counts(check_conformity(quads.mesh), quad_counts(nx, ny));
      const auto triangles = plaf::test::triangle_grid(n[0], n[1], q);
      CHECK(triangles.mesh.num_cells() == 2 * nx * ny);
      check_counts(check_conformity(triangles.mesh), triangle_counts(nx, ny));
      const auto prisms = plaf::test::prism_block(n[0], n[1], n[2], q);
      CHECK(prisms.mesh.num_cells() == 2 * nx * ny * nz);
      check_counts(check_conformity(prisms.mesh), prism_counts(nx, ny, nz));
      const auto tets = plaf::test::kuhn_tets(n[0], n[1], n[2], q);
      CHECK(tets.mesh.num_cells() == 6 * nx * ny * nz);
      check_counts(check_conformity(tets.mesh), tet_counts(nx, ny, nz));
    }
  // Hand checks of the formulas: the 2 x 1 quad grid has one shared edge and six outline edges;
  // the six Kuhn tets of one cube meet pairwise in the six faces through its main diagonal.
  CHECK(quad_counts(2, 1).interior == 1);
  CHECK(quad_counts(2, 1).boundary == 6);
  CHECK(tet_counts(1, 1, 1).interior == 6);
  check_counts(check_conformity(HybridMesh<2>{}), {});
  check_counts(check_conformity(HybridMesh<3>{}), {});
}

TEST_CASE("mesh: a missing boundary facet is an open facet, named by its vertices") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      CellBlock& b = s.mesh.boundary.back();
      const auto npc = static_cast<std::ptrdiff_t>(b.nodes_per_cell());
      const std::vector<NodeId> removed(b.connectivity.end() - npc, b.connectivity.end() - npc + num_vertices(b.type));
      b.connectivity.resize(b.connectivity.size() - static_cast<std::size_t>(npc));
      const ConformityReport r = check_conformity(s.mesh);
      check_counts(r, {counts.interior, counts.boundary - 1, 1, 0, 0, 0});
      CHECK(r.first_problem == facet_text(removed) + " belongs to one cell and to no boundary (a hole in the mesh)");
    });
}

TEST_CASE("mesh: a boundary facet that is no cell's facet is stray") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      // Box corners two cubes apart along x: no cell has them all (every cell spans one cube).
      std::vector<NodeId> v{s.id({0, 0, 0}), s.id({2 * q, 0, 0})};
      if (s.dim == 3) v.push_back(s.id({0, 0, q}));
      const CellType facet = s.dim == 2 ? CellType::Line : CellType::Triangle;
      CellBlock& b = s.mesh.boundary_block(facet, q, 0);
      for (int k = 0; k < num_nodes(facet, q); ++k) b.connectivity.push_back(v[static_cast<std::size_t>(k) % v.size()]);
      const ConformityReport r = check_conformity(s.mesh);
      check_counts(r, {counts.interior, counts.boundary, 0, 0, 0, 1});
      CHECK(r.first_problem == "boundary " + facet_text(v) + " is not a facet of any cell");
    });
}

TEST_CASE("mesh: a duplicated cell oversharing its inner facets") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      CellBlock& b = s.mesh.cells[0];
      const std::size_t i = 1;
      // Its inner facets are now used three times; its boundary facets twice, and being tagged
      // they count as an embedded interface (interior), not as boundary.
      std::size_t inner = 0, outer = 0;
      for (int f = 0; f < lagrange_element(b.type, q).num_facets(); ++f) (on_box_side(s, i, f) ? outer : inner)++;
      REQUIRE(inner > 0);
      const std::vector<NodeId> copy(b.cell(i), b.cell(i) + b.nodes_per_cell());
      b.connectivity.insert(b.connectivity.end(), copy.begin(), copy.end());
      const ConformityReport r = check_conformity(s.mesh);
      check_counts(r, {counts.interior - inner + outer, counts.boundary - outer, 0, inner, 0, 0});
      // Its tagged outer facets are now used twice from the same side: a duplicate, not an
      // embedded interface.
      CHECK(r.orientation_mismatches == outer);
      CHECK(!r.first_problem.empty());
    });
}

TEST_CASE("mesh: two cells sharing a facet's vertices but not its high-order nodes are a node mismatch") {
  for (int q = 2; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      CellBlock& b = s.mesh.cells[0];
      if (b.type == CellType::Tetrahedron && q < 3) return;  // no node inside a triangle face
      INFO(std::string(name), " Q=", q);
      const std::size_t i = 1;
      const int f = first_inner_facet(s, i);
      REQUIRE(f >= 0);
      // Cell i gets its own copy, at the same position, of the last node of facet f: a node
      // inside that edge or face. Where it also lies on other facets of cell i (an edge node of
      // a prism's triangle at Q = 2), each of those mismatches too: with the neighbour across an
      // inner facet, or with the boundary facet's own nodes.
      const LagrangeElement& el = lagrange_element(b.type, q);
      const int local = el.facet_nodes(f).back();
      std::size_t containing = 0;
      for (int g = 0; g < el.num_facets(); ++g)
        for (int n : el.facet_nodes(g)) containing += n == local;
      const std::size_t at = i * static_cast<std::size_t>(b.nodes_per_cell()) + static_cast<std::size_t>(local);
      s.mesh.nodes.push_back(s.mesh.nodes[static_cast<std::size_t>(b.connectivity[at])]);
      b.connectivity[at] = static_cast<NodeId>(s.mesh.nodes.size() - 1);
      const ConformityReport r = check_conformity(s.mesh);
      check_counts(r, {counts.interior, counts.boundary, 0, 0, containing, 0});
      if (containing == 1)
        CHECK(r.first_problem ==
              "cells sharing the " + facet_text(facet_vertices(b, i, f)) + " have different high-order nodes on it");
    });
}

namespace {

// The weights of the nodes of a facet type on its vertices (line and triangle: barycentric
// lattice coordinates; quadrilateral: bilinear products), in Gmsh order: independent of
// hybrid_mesh.cpp, from the lattice of lagrange.h.
std::vector<std::array<int, 4>> node_weights(CellType t, int q) {
  std::vector<std::array<int, 4>> out;
  for (const Lattice& l : gmsh_lattice(t, q)) {
    if (t == CellType::Line) out.push_back({q - l[0], l[0], 0, 0});
    if (t == CellType::Triangle) out.push_back({q - l[0] - l[1], l[0], l[1], 0});
    if (t == CellType::Quadrilateral)
      out.push_back({(q - l[0]) * (q - l[1]), l[0] * (q - l[1]), l[0] * l[1], (q - l[0]) * l[1]});
  }
  return out;
}

// The same facet listed from its vertex perm[0], then perm[1], ...: the node at each place of
// the new listing is the node of the old listing at the same point of the facet.
std::vector<NodeId> relist(const std::vector<NodeId>& nodes, CellType t, int q, const std::vector<int>& perm) {
  const auto w = node_weights(t, q);
  std::vector<NodeId> out;
  for (const auto& want : w)
    for (std::size_t k = 0; k < w.size(); ++k) {
      bool same = true;
      for (std::size_t j = 0; j < perm.size(); ++j) same = same && w[k][static_cast<std::size_t>(perm[j])] == want[j];
      if (same) out.push_back(nodes[k]);
    }
  REQUIRE(out.size() == nodes.size());
  return out;
}

}  // namespace

TEST_CASE("mesh: a boundary facet may start at any vertex and run either way, its nodes in the same places") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      // Every boundary facet listed from its second vertex, backwards (a reflection and a turn).
      for (CellBlock& b : s.mesh.boundary) {
        const int nv = num_vertices(b.type);
        std::vector<int> perm;
        for (int j = 0; j < nv; ++j) perm.push_back(((1 - j) % nv + nv) % nv);
        const auto npc = static_cast<std::size_t>(b.nodes_per_cell());
        for (std::size_t i = 0; i < b.size(); ++i) {
          const std::vector<NodeId> old(b.cell(i), b.cell(i) + npc);
          const std::vector<NodeId> moved = relist(old, b.type, q, perm);
          std::copy(moved.begin(), moved.end(), b.connectivity.begin() + static_cast<std::ptrdiff_t>(i * npc));
        }
      }
      check_counts(check_conformity(s.mesh), counts);
    });
}

TEST_CASE("mesh: the same facet nodes in other places (a reversed edge, a turned face) are a node mismatch") {
  // Swapping two nodes of a facet inside one cell keeps every facet's node set (a sorted-set
  // comparison passes it) but moves them: a different curved cell, which must not conform.
  for (int q = 2; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      CellBlock& b = s.mesh.cells[0];
      const std::size_t i = 1;
      const int f = first_inner_facet(s, i);
      REQUIRE(f >= 0);
      const LagrangeElement& el = lagrange_element(b.type, q);
      const std::vector<int>& local = el.facet_nodes(f);
      // The first node inside edge 0 of the facet and the facet's last node (inside its last
      // edge, or inside the face): two places of the facet.
      const int nv = facet_vertex_count(b.type, f);
      const int a = local[static_cast<std::size_t>(nv)], z = local.back();
      if (s.dim == 2 && q == 2) return;  // an edge with one interior node: one place only
      REQUIRE(a != z);
      const auto at = [&](int l) {
        return i * static_cast<std::size_t>(b.nodes_per_cell()) + static_cast<std::size_t>(l);
      };
      std::swap(b.connectivity[at(a)], b.connectivity[at(z)]);
      const ConformityReport r = check_conformity(s.mesh);
      CHECK(r.node_mismatches >= 1);
      CHECK(r.interior_facets == counts.interior);
      CHECK(r.boundary_facets == counts.boundary);
      CHECK_FALSE(r.ok);
      CHECK(r.first_problem.find("high-order nodes") != std::string::npos);
    });
}

TEST_CASE(
    "mesh: a prism layer under a tetrahedron layer conforms: quadrilaterals, prism-prism and prism-tet triangles") {
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    const int nx = 3, ny = 2;
    // Layer z in [0, 1]: two prisms per square (split along the diagonal (i, j)-(i+1, j+1));
    // layer z in [1, 2]: six Kuhn tetrahedra per cube, whose bottom triangles are cut along the
    // same diagonal (kuhn_tets in structured_mesh.h).
    StructuredMesh<3> s({nx, ny, 2}, q);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        s.add_cell(CellType::Prism, {i, j, 0}, {{i + 1, j, 0}, {i + 1, j + 1, 0}, {i, j, 1}});
        s.add_cell(CellType::Prism, {i, j, 0}, {{i + 1, j + 1, 0}, {i, j + 1, 0}, {i, j, 1}});
      }
    const StructuredMesh<3> tets = plaf::test::kuhn_tets(nx, ny, 1, q);
    const CellBlock& tb = tets.mesh.cells[0];
    CellBlock& out = s.mesh.block(CellType::Tetrahedron, q);
    for (NodeId v : tb.connectivity) {  // the tet layer lifted by one cube onto s's lattice
      std::array<int, 3> p = tets.fine_of(v);
      p[2] += q;
      out.connectivity.push_back(s.id(p));
    }
    s.tag_box_boundary();
    std::size_t quads = 0, triangles = 0;
    for (const CellBlock& b : s.mesh.boundary) (b.type == CellType::Quadrilateral ? quads : triangles) += b.size();
    const auto x = static_cast<std::size_t>(nx), y = static_cast<std::size_t>(ny);
    // Interior: the prism layer's inner quadrilaterals (one per inner edge of its triangle
    // grid), the 2 x y triangles between the layers, the tet layer's own inner faces. Boundary:
    // the prisms' bottom triangles and side quadrilaterals, the tets' faces but their bottom.
    const Counts t = triangle_counts(x, y), k = tet_counts(x, y, 1);
    const Counts want{t.interior + 2 * x * y + k.interior, 2 * x * y + t.boundary + k.boundary - 2 * x * y};
    check_counts(check_conformity(s.mesh), want);
    CHECK(quads == t.boundary);
    CHECK(triangles == 2 * x * y + k.boundary - 2 * x * y);
  }
}

TEST_CASE("mesh: a crack (cells on both sides of a plane with their own nodes) opens its facets") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      CellBlock& b = s.mesh.cells[0];
      const auto npc = static_cast<std::size_t>(b.nodes_per_cell());
      // Facets in the plane x = 1: one square face per (y, z) cube, cut into 2 triangles for the
      // tets; ny (2D) or ny nz (3D) squares.
      const std::size_t squares = static_cast<std::size_t>(s.cubes(1)) * (s.dim == 3 ? s.cubes(2) : 1);
      const std::size_t cracked = squares * (b.type == CellType::Tetrahedron ? 2 : 1);
      // Cells with every vertex at x >= 1 get their own copies of the nodes on x = 1.
      std::map<NodeId, NodeId> copy;
      for (std::size_t i = 0; i < b.size(); ++i) {
        bool right = true;
        for (int v = 0; v < num_vertices(b.type); ++v) right = right && s.fine_of(b.cell(i)[v])[0] >= q;
        if (!right) continue;
        for (std::size_t k = i * npc; k < (i + 1) * npc; ++k) {
          const NodeId v = b.connectivity[k];
          if (s.fine_of(v)[0] != q) continue;
          if (!copy.count(v)) {
            s.mesh.nodes.push_back(s.mesh.nodes[static_cast<std::size_t>(v)]);
            copy[v] = static_cast<NodeId>(s.mesh.nodes.size() - 1);
          }
          b.connectivity[k] = copy[v];
        }
      }
      // Box-side facets of those cells follow them (all their vertices at x >= 1).
      for (CellBlock& bb : s.mesh.boundary) {
        const auto fn = static_cast<std::size_t>(bb.nodes_per_cell());
        for (std::size_t i = 0; i < bb.size(); ++i) {
          bool right = true;
          for (int v = 0; v < num_vertices(bb.type); ++v) right = right && s.fine_of(bb.cell(i)[v])[0] >= q;
          if (!right) continue;
          for (std::size_t k = i * fn; k < (i + 1) * fn; ++k)
            if (copy.count(bb.connectivity[k])) bb.connectivity[k] = copy[bb.connectivity[k]];
        }
      }
      ConformityReport r = check_conformity(s.mesh);
      check_counts(r, {counts.interior - cracked, counts.boundary, 2 * cracked, 0, 0, 0});
      CHECK(ends_with(r.first_problem, " belongs to one cell and to no boundary (a hole in the mesh)"));

      // Tagging both faces of the crack makes it a (two-sided) boundary again.
      const int tag = s.mesh.add_tag("crack", BoundaryKind::Wall);
      const LagrangeElement& e = lagrange_element(b.type, q);
      for (std::size_t i = 0; i < b.size(); ++i)
        for (int f = 0; f < e.num_facets(); ++f) {
          bool in_plane = true;
          for (NodeId v : facet_vertices(b, i, f))
            in_plane = in_plane && s.mesh.nodes[static_cast<std::size_t>(v)][0] == 1.0;
          if (!in_plane) continue;
          const CellType ft = s.dim == 2                           ? CellType::Line
                              : facet_vertex_count(b.type, f) == 3 ? CellType::Triangle
                                                                   : CellType::Quadrilateral;
          const std::vector<NodeId> nodes = facet_all_nodes(b, i, f);
          CellBlock& bb = s.mesh.boundary_block(ft, q, tag);
          bb.connectivity.insert(bb.connectivity.end(), nodes.begin(), nodes.end());
        }
      r = check_conformity(s.mesh);
      check_counts(r, {counts.interior - cracked, counts.boundary + 2 * cracked, 0, 0, 0, 0});
    });
}

TEST_CASE("mesh: a tagged inner facet is an embedded interface and still conforms") {
  for (int q = 1; q <= max_order; ++q)
    for_each_mesh(q, [&](const char* name, auto s, const Counts& counts) {
      INFO(std::string(name), " Q=", q);
      const CellBlock& b = s.mesh.cells[0];
      const int f = first_inner_facet(s, 0);
      REQUIRE(f >= 0);
      const CellType ft = s.dim == 2                           ? CellType::Line
                          : facet_vertex_count(b.type, f) == 3 ? CellType::Triangle
                                                               : CellType::Quadrilateral;
      const std::vector<NodeId> nodes = facet_all_nodes(b, 0, f);
      CellBlock& bb = s.mesh.boundary_block(ft, q, s.mesh.add_tag("interface", BoundaryKind::Named));
      bb.connectivity.insert(bb.connectivity.end(), nodes.begin(), nodes.end());
      check_counts(check_conformity(s.mesh), counts);
    });
}

TEST_CASE("mesh: block(), boundary_block() and add_tag() return the existing entry for the same key") {
  HybridMesh<2> m;
  m.block(CellType::Quadrilateral, 2).connectivity.assign(9, 0);
  m.block(CellType::Quadrilateral, 3);
  m.block(CellType::Triangle, 2);
  CHECK(m.cells.size() == 3);
  CellBlock& q2 = m.block(CellType::Quadrilateral, 2);
  CHECK(&q2 == &m.cells[0]);
  CHECK(q2.connectivity.size() == 9);
  CHECK(q2.tag == -1);
  CHECK(m.cells.size() == 3);
  CHECK(m.num_cells() == 1);

  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  const int far = m.add_tag("far", BoundaryKind::Farfield);
  CHECK(wall == 0);
  CHECK(far == 1);
  // The same name is the same tag; its first kind is kept.
  CHECK(m.add_tag("wall", BoundaryKind::Symmetry) == wall);
  CHECK(m.tags.size() == 2);
  CHECK(m.tags[0].kind == BoundaryKind::Wall);
  CHECK(std::string(boundary_kind_name(m.tags[1].kind)) == "farfield");

  m.boundary_block(CellType::Line, 2, wall);
  m.boundary_block(CellType::Line, 2, far);
  m.boundary_block(CellType::Line, 3, wall);
  CHECK(m.boundary.size() == 3);
  CHECK(&m.boundary_block(CellType::Line, 2, far) == &m.boundary[1]);
  CHECK(m.boundary.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) CHECK(m.boundary[k].tag == (k == 1 ? far : wall));
  CHECK(m.cells.size() == 3);  // boundary blocks never land among the cells

  // nodes_per_cell() is the size of the Lagrange lattice: (Q+1)(Q+2)/2 triangle nodes, (Q+1)^2
  // quadrilateral, (Q+1)(Q+2)(Q+3)/6 tetrahedron, (Q+1)^2 (Q+2)/2 prism, Q+1 line.
  for (int q = 1; q <= max_order; ++q) {
    const auto n = [&](CellType t) { return CellBlock{t, q, -1, {}}.nodes_per_cell(); };
    CHECK(n(CellType::Line) == q + 1);
    CHECK(n(CellType::Triangle) == (q + 1) * (q + 2) / 2);
    CHECK(n(CellType::Quadrilateral) == (q + 1) * (q + 1));
    CHECK(n(CellType::Tetrahedron) == (q + 1) * (q + 2) * (q + 3) / 6);
    CHECK(n(CellType::Prism) == (q + 1) * (q + 1) * (q + 2) / 2);
  }
}

TEST_CASE("mesh: gather_coords returns the cell's nodes in connectivity order") {
  const auto s = plaf::test::prism_block(1, 1, 1, 3);
  const CellBlock& b = s.mesh.cells[0];
  std::vector<double> x(static_cast<std::size_t>(b.nodes_per_cell()) * 3);
  gather_coords(s.mesh, b, 1, x.data());
  for (int k = 0; k < b.nodes_per_cell(); ++k)
    for (int d = 0; d < 3; ++d)
      CHECK(x[static_cast<std::size_t>(3 * k + d)] == s.mesh.nodes[static_cast<std::size_t>(b.cell(1)[k])][d]);
}

TEST_CASE("mesh: a surface mesh alone is checked as closed, consistently oriented loops") {
  // Two order-2 line elements around a "loop" 0 -> 1 -> 0 with mid nodes 2 and 3.
  HybridMesh<2> m;
  m.nodes.resize(6);
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  CellBlock& b = m.boundary_block(CellType::Line, 2, wall);
  b.connectivity = {0, 1, 2, 1, 4, 3, 4, 0, 5};  // 0 -> 1 -> 4 -> 0, Gmsh order: ends, middle
  ConformityReport r = check_conformity(m);
  CHECK(r.ok);
  CHECK(r.interior_facets == 3);
  // Reversing one element breaks the orientation at both its ends.
  b.connectivity = {0, 1, 2, 4, 1, 3, 4, 0, 5};
  r = check_conformity(m);
  CHECK_FALSE(r.ok);
  CHECK(r.orientation_mismatches == 2);
  // An open loop leaves two ends used once.
  b.connectivity = {0, 1, 2, 1, 4, 3};
  r = check_conformity(m);
  CHECK(r.open_facets == 2);
}

namespace {

// The unit square in z = 0 as two order-2 surface triangles: vertices 0..3, edge midpoints 4
// (0-1), 5 (1-2), 6 (2-3), 7 (3-0), 8 (the diagonal 0-2); an open surface with a 4-edge rim.
HybridMesh<3> square_surface() {
  HybridMesh<3> m;
  m.nodes = {{0, 0, 0},   {1, 0, 0},   {1, 1, 0},   {0, 1, 0},    {0.5, 0, 0},
             {1, 0.5, 0}, {0.5, 1, 0}, {0, 0.5, 0}, {0.5, 0.5, 0}};
  const int wall = m.add_tag("wall", BoundaryKind::Wall);
  m.boundary_block(CellType::Triangle, 2, wall).connectivity = {0, 1, 2, 4, 5, 8, 0, 2, 3, 8, 6, 7};
  return m;
}

}  // namespace

TEST_CASE("mesh: a 3D surface's open edges are boundary when a curves block lists them") {
  HybridMesh<3> m = square_surface();
  ConformityReport r = check_conformity(m);
  CHECK_FALSE(r.ok);
  CHECK(r.open_facets == 4);
  CHECK(r.interior_facets == 1);

  const int symmetry = m.add_tag("symmetry", BoundaryKind::Symmetry);
  CellBlock& rim = m.curve_block(2, symmetry);
  rim.connectivity = {0, 1, 4, 1, 2, 5, 2, 3, 6, 0, 3, 7};  // the last one against the face's direction
  CHECK(&m.curve_block(2, symmetry) == &m.curves[0]);
  CHECK(m.curves.size() == 1);
  CHECK(m.curves[0].type == CellType::Line);
  CHECK(m.curves[0].tag == symmetry);
  CHECK(m.boundary.size() == 1);  // curves never land among the boundary blocks
  r = check_conformity(m);
  check_counts(r, {1, 4, 0, 0, 0, 0});

  // A curve on the inner diagonal is an embedded curve (still interior, no problem).
  HybridMesh<3> diagonal = m;
  CellBlock& inner = diagonal.curve_block(2, symmetry);
  inner.connectivity.insert(inner.connectivity.end(), {0, 2, 8});
  check_counts(check_conformity(diagonal), {1, 4, 0, 0, 0, 0});

  // A curve with another middle node than its triangle's edge is a node mismatch.
  HybridMesh<3> mismatch = m;
  mismatch.curves[0].connectivity[2] = 5;
  r = check_conformity(mismatch);
  CHECK(r.node_mismatches == 1);
  CHECK_FALSE(r.ok);
  CHECK(r.first_problem == "boundary " + facet_text({0, 1}) + " has other high-order nodes than the cell it bounds");

  // A curve that is no edge of the surface is stray.
  HybridMesh<3> stray = m;
  stray.nodes.push_back({0.5, 0.5, 1});
  stray.curves[0].connectivity.insert(stray.curves[0].connectivity.end(), {1, 3, 9});
  r = check_conformity(stray);
  CHECK(r.stray_boundary == 1);
  CHECK_FALSE(r.ok);
}

TEST_CASE("mesh: compact_nodes keeps and renumbers the nodes of curves") {
  HybridMesh<3> m = square_surface();
  m.nodes.push_back({9, 9, 9});  // 9: unused
  m.nodes.push_back({2, 0, 0});  // 10: used by a curve alone
  const int feature = m.add_tag("feature", BoundaryKind::Named);
  m.curve_block(1, feature).connectivity = {1, 10};
  compact_nodes(m);
  REQUIRE(m.nodes.size() == 10);
  CHECK(m.curves[0].connectivity == std::vector<NodeId>{1, 9});
  CHECK(m.nodes[9] == Eigen::Vector3d(2, 0, 0));
  CHECK(m.boundary[0].connectivity == std::vector<NodeId>{0, 1, 2, 4, 5, 8, 0, 2, 3, 8, 6, 7});
}
