// SPDX-License-Identifier: MIT
// Structured test meshes of order Q on a box of n[d] unit cubes (squares) per axis.
//
// Every node is a point of the fine lattice {0 .. n[d] Q} per axis, stored once, at position
// spacing[d] * p[d] / Q. A cell is given by the integer corners of its reference axes (vertex 0
// and the vertex at the end of each reference axis, see axis_vertices), and its node with
// reference lattice coordinates l sits at Q v0 + sum_d l_d (a_d - v0) in fine-lattice units: an
// affine map, so two cells that share corners share every node on the common facet by
// construction, and no test helper decides adjacency the way check_conformity does.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/elements/lagrange.h"

namespace plaf::test {

using Corner = std::array<int, 3>;

// The vertices at the ends of the reference axes from vertex 0 (lagrange.h reference cells).
inline std::vector<int> axis_vertices(CellType t) {
  switch (t) {
    case CellType::Quadrilateral:
      return {1, 3};
    case CellType::Triangle:
      return {1, 2};
    default:
      return {1, 2, 3};  // tetrahedron and prism (w runs from vertex 0 to vertex 3)
  }
}

template <int Dim>
class StructuredMesh {
 public:
  static constexpr int dim = Dim;

  StructuredMesh(std::array<int, 3> cubes, int order, std::array<double, 3> spacing = {1, 1, 1})
      : n_(cubes), q_(order) {
    for (int d = Dim; d < 3; ++d) n_[d] = 0;
    const int nx = n_[0] * q_ + 1, ny = n_[1] * q_ + 1, nz = n_[2] * q_ + 1;
    mesh.nodes.resize(static_cast<std::size_t>(nx) * ny * nz);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const std::array<int, 3> p{i, j, k};
          typename HybridMesh<Dim>::Point x;
          for (int d = 0; d < Dim; ++d) x[d] = spacing[d] * p[d] / q_;
          mesh.nodes[static_cast<std::size_t>(id(p))] = x;
        }
  }

  int order() const { return q_; }
  int cubes(int d) const { return n_[d]; }

  NodeId id(const std::array<int, 3>& fine) const {
    const int nx = n_[0] * q_ + 1, ny = n_[1] * q_ + 1;
    return static_cast<NodeId>((fine[2] * ny + fine[1]) * nx + fine[0]);
  }
  std::array<int, 3> fine_of(NodeId v) const {
    const int nx = n_[0] * q_ + 1, ny = n_[1] * q_ + 1;
    return {v % nx, (v / nx) % ny, v / (nx * ny)};
  }

  // Appends a cell with vertex 0 at corner v0 and reference axes ending at corners axes[d].
  void add_cell(CellType t, const Corner& v0, const std::vector<Corner>& axes) {
    CellBlock& b = mesh.block(t, q_);
    for (const Lattice& l : lagrange_element(t, q_).lattice()) {
      std::array<int, 3> p{};
      for (int d = 0; d < 3; ++d) {
        p[d] = q_ * v0[d];
        for (std::size_t a = 0; a < axes.size(); ++a) p[d] += l[a] * (axes[a][d] - v0[d]);
      }
      b.connectivity.push_back(id(p));
    }
  }

  // Tags every cell facet whose vertices all lie on one side of the box ("x-", "y+", ...) with
  // the facet's nodes in the cell's own facet order (Gmsh order of the facet type).
  void tag_box_boundary() {
    const char* names[3][2] = {{"x-", "x+"}, {"y-", "y+"}, {"z-", "z+"}};
    for (const CellBlock& b : mesh.cells) {  // boundary_block() grows mesh.boundary only
      const LagrangeElement& e = lagrange_element(b.type, b.order);
      const CellTopology& topo = topology(b.type);
      for (std::size_t i = 0; i < b.size(); ++i) {
        const NodeId* c = b.cell(i);
        for (int f = 0; f < e.num_facets(); ++f) {
          const int nv = Dim == 2 ? 2 : static_cast<int>(topo.faces[f].size());
          for (int d = 0; d < Dim; ++d)
            for (int side = 0; side < 2; ++side) {
              bool on = true;
              for (int v = 0; v < nv; ++v) on = on && fine_of(c[e.facet_nodes(f)[v]])[d] == side * n_[d] * q_;
              if (!on) continue;
              const CellType ft = Dim == 2 ? CellType::Line : nv == 3 ? CellType::Triangle : CellType::Quadrilateral;
              CellBlock& bb = mesh.boundary_block(ft, q_, mesh.add_tag(names[d][side], BoundaryKind::Named));
              for (int l : e.facet_nodes(f)) bb.connectivity.push_back(c[l]);
            }
        }
      }
    }
  }

  HybridMesh<Dim> mesh;

 private:
  std::array<int, 3> n_;
  int q_;
};

// nx x ny squares, one order-Q quadrilateral each.
inline StructuredMesh<2> quad_grid(int nx, int ny, int q, double h = 1.0) {
  StructuredMesh<2> s({nx, ny, 0}, q, {h, h, h});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) s.add_cell(CellType::Quadrilateral, {i, j, 0}, {{i + 1, j, 0}, {i, j + 1, 0}});
  s.tag_box_boundary();
  return s;
}

// The same squares, each split along its diagonal (i, j) - (i+1, j+1) into two triangles.
inline void add_split_square(StructuredMesh<2>& s, int i, int j) {
  s.add_cell(CellType::Triangle, {i, j, 0}, {{i + 1, j, 0}, {i + 1, j + 1, 0}});
  s.add_cell(CellType::Triangle, {i, j, 0}, {{i + 1, j + 1, 0}, {i, j + 1, 0}});
}
inline StructuredMesh<2> triangle_grid(int nx, int ny, int q, double h = 1.0) {
  StructuredMesh<2> s({nx, ny, 0}, q, {h, h, h});
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) add_split_square(s, i, j);
  s.tag_box_boundary();
  return s;
}

// The triangle grid extruded through nz layers: two prisms per cube.
inline StructuredMesh<3> prism_block(int nx, int ny, int nz, int q) {
  StructuredMesh<3> s({nx, ny, nz}, q);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        s.add_cell(CellType::Prism, {i, j, k}, {{i + 1, j, k}, {i + 1, j + 1, k}, {i, j, k + 1}});
        s.add_cell(CellType::Prism, {i, j, k}, {{i + 1, j + 1, k}, {i, j + 1, k}, {i, j, k + 1}});
      }
  s.tag_box_boundary();
  return s;
}

// Kuhn (Freudenthal) subdivision: six tetrahedra per cube around its main diagonal, one per
// permutation of the axes, vertex 1 swapped with 2 where needed for a positive volume. The same
// split in every cube is conforming (each square face is cut along its own main diagonal).
inline StructuredMesh<3> kuhn_tets(int nx, int ny, int nz, int q) {
  StructuredMesh<3> s({nx, ny, nz}, q);
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          const Corner v0{i, j, k};
          Corner v1 = v0, v2, v3{i + 1, j + 1, k + 1};
          v1[p[0]] += 1;
          v2 = v1;
          v2[p[1]] += 1;
          const auto det = [&](const Corner& a, const Corner& b, const Corner& c) {
            const int u[3] = {a[0] - v0[0], a[1] - v0[1], a[2] - v0[2]};
            const int v[3] = {b[0] - v0[0], b[1] - v0[1], b[2] - v0[2]};
            const int w[3] = {c[0] - v0[0], c[1] - v0[1], c[2] - v0[2]};
            return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                   u[2] * (v[0] * w[1] - v[1] * w[0]);
          };
          if (det(v1, v2, v3) > 0)
            s.add_cell(CellType::Tetrahedron, v0, {v1, v2, v3});
          else
            s.add_cell(CellType::Tetrahedron, v0, {v2, v1, v3});
        }
  s.tag_box_boundary();
  return s;
}

}  // namespace plaf::test
