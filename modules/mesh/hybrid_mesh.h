// SPDX-License-Identifier: MIT
// HybridMesh<Dim>: the product of a plaf run. Nodes in one contiguous array, cells in blocks of
// one (type, order) each with flat connectivity, boundary facets in tagged blocks.
//
// Conventions: cell connectivity is in Gmsh's node order (lagrange.h); 2D cells are
// counter-clockwise (det J > 0), 3D cells have positive volume. Boundary facets are cells of
// dimension Dim-1 (lines in 2D; triangles/quadrilaterals in 3D) carrying the index of their tag.
// The 3D layers' wall and outer-front triangles keep the surface's orientation (right-hand normal
// away from the body), their symmetry quadrilaterals face into the prisms; check_conformity does
// not depend on a facet's orientation. In 3D, curves are tagged line blocks (dimension 1): feature or symmetry curves of a surface,
// e.g. the symmetry loop where a half-body's surface ends on its symmetry plane.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace mesh {

using NodeId = std::int32_t;

enum class BoundaryKind : std::uint8_t { Wall, Farfield, Symmetry, Named };
const char* boundary_kind_name(BoundaryKind kind);
// The kind a boundary's name implies (case-insensitive prefix): "wall*" -> Wall, "farfield*" ->
// Farfield, "symmetry*" -> Symmetry, else Named (the readers' rule for files without kinds).
BoundaryKind boundary_kind_from_name(const std::string& name);

struct BoundaryTag {
  std::string name;
  BoundaryKind kind = BoundaryKind::Named;
};

// Cells of one type and order; connectivity is flat, nodes_per_cell() ids per cell.
struct CellBlock {
  CellType type = CellType::Triangle;
  int order = 1;
  int tag = -1;  // boundary blocks: index into HybridMesh::tags; -1 for volume blocks
  std::vector<NodeId> connectivity;

  int nodes_per_cell() const { return num_nodes(type, order); }
  std::size_t size() const { return connectivity.size() / static_cast<std::size_t>(nodes_per_cell()); }
  const NodeId* cell(std::size_t i) const { return connectivity.data() + i * nodes_per_cell(); }
};

template <int Dim>
struct HybridMesh {
  using Point = Eigen::Matrix<double, Dim, 1>;
  std::vector<Point> nodes;
  std::vector<CellBlock> cells;     // cells of dimension Dim
  std::vector<CellBlock> boundary;  // facets of dimension Dim - 1, each block with a tag
  std::vector<CellBlock> curves;    // 3D only: tagged line blocks (feature / symmetry curves)
  std::vector<BoundaryTag> tags;

  std::size_t num_cells() const {
    std::size_t n = 0;
    for (const CellBlock& b : cells) n += b.size();
    return n;
  }
  // The block of (type, order), created on first use.
  CellBlock& block(CellType type, int order);
  // The boundary block of (type, order, tag), created on first use.
  CellBlock& boundary_block(CellType type, int order, int tag);
  // The curves line block of (order, tag), created on first use.
  CellBlock& curve_block(int order, int tag);
  int add_tag(const std::string& name, BoundaryKind kind);
};

// Drops the nodes no cell, boundary facet or curve uses and renumbers the rest (order kept).
template <int Dim>
void compact_nodes(HybridMesh<Dim>& mesh);

struct ConformityReport {
  bool ok = true;
  std::size_t interior_facets = 0;         // shared by exactly two cells with the same high-order nodes
  std::size_t boundary_facets = 0;         // used by one cell and listed in a boundary block
  std::size_t open_facets = 0;             // used by one cell but in no boundary block (a hole or crack)
  std::size_t overshared_facets = 0;       // used by three or more cells
  std::size_t node_mismatches = 0;         // high-order facet nodes differ between the cells (or boundary) sharing it
  std::size_t order_transitions = 0;       // a 2D edge shared at two orders, straight sided (not a problem)
  std::size_t orientation_mismatches = 0;  // two cells on the same side of a facet (duplicate, fold)
  std::size_t stray_boundary = 0;          // boundary facets that are not a facet of any cell
  std::string first_problem;               // a one-line description of the first problem found
};

// Every interior facet shared by exactly two cells with identical high-order facet nodes, and
// every facet used once listed in a boundary block; the two cells of a facet on opposite sides
// of it. In 3D the facets are triangles and quadrilaterals: a prism has two triangles and three
// quadrilaterals, and shares a triangle with a prism or a tetrahedron, a quadrilateral with a
// prism. Identical means the same node at the same place of the facet (its weights on the
// facet's vertices): a listing may start at any vertex and run either way (a boundary
// quadrilateral need not start where its prism's face does), but the same nodes in other places
// (an edge's interior nodes reversed, a face's interior nodes rotated) are a node mismatch, as
// they make another curved facet. In 2D an edge may be shared by cells (or a boundary line) of
// different orders when it is straight sided at the higher order (counted in order_transitions).
// A mesh of boundary facets alone (a surface mesh) is checked as a mesh of those facets: closed,
// consistently oriented loops (2D) or surfaces (3D); in 3D an open surface edge is a boundary
// facet when a curves block lists it (with the same high-order nodes), e.g. the rim of a
// half-body on its symmetry plane. Curves are not checked in a mesh with cells. Hash-based:
// O(number of facets).
template <int Dim>
ConformityReport check_conformity(const HybridMesh<Dim>& mesh);

// How far a high-order node may lie off its linear position and still count as there: rel_tol of
// its cell's size, plus the rounding of stored coordinates of that magnitude (a few ulps, more
// than rel_tol * size for a small cell far from the origin: a 1e-5 first-layer cell at x = 1).
// is_curved's rule; the layers judge their straight elements by it too.
inline double straight_tolerance(double size, double magnitude, double rel_tol = 1e-12) {
  return rel_tol * size + 16 * std::numeric_limits<double>::epsilon() * magnitude;
}

// True when a high-order node of cell i of block b lies off the cell's linear interpolation of its
// vertices by more than straight_tolerance (rel_tol times its size, and the rounding of its
// coordinates).
template <int Dim>
bool is_curved(const HybridMesh<Dim>& mesh, const CellBlock& block, std::size_t cell, double rel_tol = 1e-12);

// The diagonal of the bounding box of the nodes of the facets tagged as walls (of every node when
// there are none; 0 for no node): the body's size, without a farfield's.
template <int Dim>
double wall_diagonal(const HybridMesh<Dim>& mesh) {
  using Point = typename HybridMesh<Dim>::Point;
  Point lo = Point::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const CellBlock& b : mesh.boundary)
    if (b.tag >= 0 && mesh.tags[static_cast<std::size_t>(b.tag)].kind == BoundaryKind::Wall)
      for (const NodeId n : b.connectivity) {
        lo = lo.cwiseMin(mesh.nodes[static_cast<std::size_t>(n)]);
        hi = hi.cwiseMax(mesh.nodes[static_cast<std::size_t>(n)]);
      }
  if (!(lo[0] <= hi[0]))
    for (const Point& x : mesh.nodes) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  return lo[0] <= hi[0] ? (hi - lo).norm() : 0.0;
}

// Coordinates of cell i of block b, row-major (Dim per node), in Gmsh order, into out.
template <int Dim>
void gather_coords(const HybridMesh<Dim>& mesh, const CellBlock& b, std::size_t i, double* out) {
  const NodeId* c = b.cell(i);
  const int n = b.nodes_per_cell();
  for (int k = 0; k < n; ++k)
    for (int d = 0; d < Dim; ++d) out[k * Dim + d] = mesh.nodes[c[k]][d];
}

}  // namespace mesh
}  // namespace plaf
