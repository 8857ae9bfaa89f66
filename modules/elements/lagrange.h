// SPDX-License-Identifier: MIT
// Lagrange geometry elements of order Q = 1..4 on equispaced nodes, in Gmsh's node order.
//
// Reference cells (plaf's own convention; the writers map to Gmsh/VTK):
//   Line          u in [0,1]
//   Triangle      (0,0), (1,0), (0,1)
//   Quadrilateral [0,1]^2, vertices (0,0), (1,0), (1,1), (0,1)
//   Tetrahedron   (0,0,0), (1,0,0), (0,1,0), (0,0,1)
//   Prism         triangle (u,v) x line w in [0,1]; vertices 0-2 at w = 0, 3-5 at w = 1
// Every node sits on the lattice {0..Q}^d / Q and is stored as integer lattice coordinates.
// Node order is Gmsh's: vertices, then edge interiors (each from its first to its second
// vertex), then face interiors, then the cell interior, recursively as a lower-order element.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace plaf {
inline namespace elements {

enum class CellType : std::uint8_t { Line, Triangle, Quadrilateral, Tetrahedron, Prism };

constexpr int max_order = 4;

int ref_dim(CellType type);
int num_vertices(CellType type);
int num_nodes(CellType type, int order);
const char* cell_name(CellType type);  // "line", "triangle", "quadrilateral", ...
// Throws ConfigError unless 1 <= order <= max_order.
void check_order(int order);

using Lattice = std::array<int, 3>;

// The local vertex lists of the linear edges and facets of a cell, in Gmsh's order.
struct CellTopology {
  std::vector<std::array<int, 2>> edges;
  std::vector<std::vector<int>> faces;  // 3 or 4 vertices, for 3D cells; facets of 2D cells are edges
};
const CellTopology& topology(CellType type);

// One Lagrange element (type, order): its nodes and basis. Built once per (type, order) and
// shared; evaluation writes into caller buffers and never allocates.
class LagrangeElement {
 public:
  LagrangeElement(CellType type, int order);

  CellType type() const { return type_; }
  int order() const { return order_; }
  int dim() const { return dim_; }
  int size() const { return static_cast<int>(lattice_.size()); }
  const std::vector<Lattice>& lattice() const { return lattice_; }
  // Reference coordinates of node i (dim entries, the rest zero).
  std::array<double, 3> ref_node(int i) const;

  // phi[i] = value of basis function i at reference point xi (dim entries).
  void eval(const double* xi, double* phi) const;
  // dphi[i*dim + d] = d phi_i / d xi_d at xi.
  void eval_grad(const double* xi, double* dphi) const;

  // Local node indices on linear edge e (order Q+1 nodes, from its first to its second vertex).
  const std::vector<int>& edge_nodes(int e) const { return edge_nodes_[e]; }
  // Local node indices on facet f of a 2D cell (= its edges) or a 3D cell (its faces, in the
  // face's own Gmsh order starting at the face's first vertex).
  const std::vector<int>& facet_nodes(int f) const { return facet_nodes_[f]; }
  int num_facets() const { return static_cast<int>(facet_nodes_.size()); }
  // Index of the node with these lattice coordinates, or -1.
  int find(const Lattice& l) const;

 private:
  CellType type_;
  int order_;
  int dim_;
  std::vector<Lattice> lattice_;
  std::vector<int> index_;  // node of lattice point (a, b, c) at (a (Q + 1) + b) (Q + 1) + c, or -1
  std::vector<std::vector<int>> edge_nodes_;
  std::vector<std::vector<int>> facet_nodes_;
};

// The shared element for (type, order); throws ConfigError for an order outside 1..max_order.
const LagrangeElement& lagrange_element(CellType type, int order);

// Lattice coordinates of the nodes of (type, order) in Gmsh's order (used by the element and
// by the writers, which permute to other orders).
std::vector<Lattice> gmsh_lattice(CellType type, int order);
// The same nodes in VTK's Lagrange-cell order (VTK 9, types 68-73).
std::vector<Lattice> vtk_lattice(CellType type, int order);
// The same nodes in CGNS's order (SIDS "Unstructured Grid Element Numbering Conventions": BAR_2..5,
// TRI_3/6/10/15, QUAD_4/9/16/25, TETRA_4/10/20/35, PENTA_6/18/40/75).
std::vector<Lattice> cgns_lattice(CellType type, int order);
// perm[k] = the index in `from` of the point to[k]: the node order `to` read from a cell stored in
// the order `from` (both the same set of lattice points; throws Error otherwise).
std::vector<int> lattice_permutation(const std::vector<Lattice>& from, const std::vector<Lattice>& to);

}  // namespace elements
}  // namespace plaf
