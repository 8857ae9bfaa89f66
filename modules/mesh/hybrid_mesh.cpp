// SPDX-License-Identifier: MIT
// HybridMesh blocks, tags and the facet-hash conformity check (see hybrid_mesh.h).
#include "modules/mesh/hybrid_mesh.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace plaf {
inline namespace mesh {

const char* boundary_kind_name(BoundaryKind kind) {
  switch (kind) {
    case BoundaryKind::Wall:
      return "wall";
    case BoundaryKind::Farfield:
      return "farfield";
    case BoundaryKind::Symmetry:
      return "symmetry";
    case BoundaryKind::Named:
      return "named";
  }
  return "?";
}

BoundaryKind boundary_kind_from_name(const std::string& name) {
  auto starts = [&](std::string_view prefix) {
    if (name.size() < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(name[i])) != prefix[i]) return false;
    return true;
  };
  if (starts("wall")) return BoundaryKind::Wall;
  if (starts("farfield")) return BoundaryKind::Farfield;
  if (starts("symmetry")) return BoundaryKind::Symmetry;
  return BoundaryKind::Named;
}

template <int Dim>
CellBlock& HybridMesh<Dim>::block(CellType type, int order) {
  for (CellBlock& b : cells)
    if (b.type == type && b.order == order) return b;
  cells.push_back(CellBlock{type, order, -1, {}});
  return cells.back();
}

template <int Dim>
CellBlock& HybridMesh<Dim>::boundary_block(CellType type, int order, int tag) {
  for (CellBlock& b : boundary)
    if (b.type == type && b.order == order && b.tag == tag) return b;
  boundary.push_back(CellBlock{type, order, tag, {}});
  return boundary.back();
}

template <int Dim>
CellBlock& HybridMesh<Dim>::curve_block(int order, int tag) {
  for (CellBlock& b : curves)
    if (b.order == order && b.tag == tag) return b;
  curves.push_back(CellBlock{CellType::Line, order, tag, {}});
  return curves.back();
}

template <int Dim>
int HybridMesh<Dim>::add_tag(const std::string& name, BoundaryKind kind) {
  for (std::size_t i = 0; i < tags.size(); ++i)
    if (tags[i].name == name) return static_cast<int>(i);
  tags.push_back(BoundaryTag{name, kind});
  return static_cast<int>(tags.size()) - 1;
}

namespace {

// A facet is identified by its sorted vertex ids (up to 4).
using FacetKey = std::array<NodeId, 4>;

struct FacetKeyHash {
  std::size_t operator()(const FacetKey& k) const {
    std::size_t h = 1469598103934665603ull;
    for (NodeId v : k) h = (h ^ static_cast<std::size_t>(static_cast<std::uint32_t>(v))) * 1099511628211ull;
    return h;
  }
};

struct FacetUse {
  int count = 0;
  bool boundary = false;
  std::array<NodeId, 2> around{-1, -1};  // successor and predecessor of the smallest vertex, first use
  std::vector<NodeId> nodes;             // the first use's nodes in canonical order (canonical_nodes)
};

// The successor and predecessor of the smallest vertex in the facet's cyclic vertex order: two
// cells on opposite sides of a facet traverse it in opposite directions (outward-oriented
// facets of positively oriented cells), so the second use swaps them. For an edge (2 vertices)
// the "successor" is the second vertex.
std::array<NodeId, 2> around_min(const NodeId* cell, const std::vector<int>& local, int nv) {
  int m = 0;
  for (int v = 1; v < nv; ++v)
    if (cell[local[v]] < cell[local[m]]) m = v;
  if (nv == 1) return {local[0] == 0 ? 0 : 1, local[0] == 0 ? 1 : 0};  // a line's start or end
  if (nv == 2) return {cell[local[1]], cell[local[0]]};
  return {cell[local[(m + 1) % nv]], cell[local[(m + nv - 1) % nv]]};
}

FacetKey make_key(const NodeId* cell, const std::vector<int>& local, int nv) {
  FacetKey k{-1, -1, -1, -1};
  for (int v = 0; v < nv; ++v) {  // insertion sort of at most 4 ids
    NodeId x = cell[local[v]];
    int j = v;
    for (; j > 0 && k[j - 1] > x; --j) k[j] = k[j - 1];
    k[j] = x;
  }
  return k;
}

// The weights of a facet node on the facet's vertices, in the facet's own vertex order: the
// integer barycentric coordinates (times Q) on a line or triangle, the bilinear ones (times Q^2)
// on a quadrilateral. They name the node's place on the facet independently of where the listing
// starts or which way it runs, and differ between any two nodes of one facet.
using Weights = std::array<int, 4>;

// facet_weights of every node of the facet with nv vertices (1: the end point of a line, 2: a
// line, 3: a triangle, 4: a quadrilateral) and order q, in the facet type's Gmsh node order.
// Throws ConfigError for an order outside 1..max_order (a malformed boundary block).
const std::vector<Weights>& facet_weight_table(int nv, int q) {
  check_order(q);
  static const auto table = [] {
    std::array<std::array<std::vector<Weights>, max_order + 1>, 5> t;
    for (int order = 1; order <= max_order; ++order) {
      t[1][order] = {{1, 0, 0, 0}};
      for (const Lattice& l : gmsh_lattice(CellType::Line, order)) t[2][order].push_back({order - l[0], l[0], 0, 0});
      for (const Lattice& l : gmsh_lattice(CellType::Triangle, order))
        t[3][order].push_back({order - l[0] - l[1], l[0], l[1], 0});
      for (const Lattice& l : gmsh_lattice(CellType::Quadrilateral, order))
        t[4][order].push_back(
            {(order - l[0]) * (order - l[1]), l[0] * (order - l[1]), l[0] * l[1], (order - l[0]) * l[1]});
    }
    return t;
  }();
  return table[static_cast<std::size_t>(nv)][static_cast<std::size_t>(q)];
}

// The facet's nodes (cell[local[k]], in the facet type's Gmsh order) in a canonical order: by
// their weights on the facet's vertices taken in increasing vertex id (the facet key). Two
// listings of one facet give the same sequence exactly when every node sits at the same place
// on the facet, whichever vertex they start at and whichever way they run; a permutation of
// the high-order nodes (an edge's interior nodes reversed, a face's interior rotated) is a
// different curved facet even though its node set is the same.
void canonical_nodes(const NodeId* cell, const std::vector<int>& local, int q, int nv, const FacetKey& key,
                     std::vector<std::pair<Weights, NodeId>>& scratch, std::vector<NodeId>& out) {
  const std::vector<Weights>& w = facet_weight_table(nv, q);
  std::array<int, 4> slot{0, 1, 2, 3};  // slot[p]: the facet vertex with the p-th smallest id
  for (int p = 0; p < nv; ++p)
    for (int v = 0; v < nv; ++v)
      if (cell[local[v]] == key[p]) slot[p] = v;
  scratch.clear();
  for (std::size_t k = 0; k < local.size(); ++k) {
    Weights sorted{0, 0, 0, 0};
    for (int p = 0; p < nv; ++p) sorted[p] = w[k][slot[p]];
    scratch.emplace_back(sorted, cell[local[k]]);
  }
  std::sort(scratch.begin(), scratch.end());
  out.clear();
  for (const auto& [weights, node] : scratch) out.push_back(node);
}

// Is the 2D edge with vertices key[0], key[1] and the nodes `nodes` (any order) straight sided:
// its interior nodes on the chord at the equispaced parameters k / q? Then a lower-order cell
// may share it (a linear triangle on the straight top edge of a curved layer cell).
template <int Dim>
bool straight_edge(const HybridMesh<Dim>& mesh, const FacetKey& key, const std::vector<NodeId>& nodes) {
  if constexpr (Dim != 2) {
    return false;
  } else {
    if (key[2] >= 0 || key[1] < 0) return false;
    const auto a = mesh.nodes[key[0]], b = mesh.nodes[key[1]];
    const double l2 = (b - a).squaredNorm();
    const int q = static_cast<int>(nodes.size()) - 1;
    std::vector<double> t;
    for (NodeId v : nodes) {
      if (v == key[0] || v == key[1]) continue;
      const auto x = mesh.nodes[v];
      const double s = (x - a).dot(b - a) / l2;
      if ((a + s * (b - a) - x).norm() > 1e-9 * std::sqrt(l2)) return false;
      t.push_back(s);
    }
    std::sort(t.begin(), t.end());
    for (int k = 1; k < q; ++k)
      if (std::abs(t[k - 1] - static_cast<double>(k) / q) > 1e-9) return false;
    return q >= 1;
  }
}

int facet_vertices(CellType cell, int facet) {
  if (ref_dim(cell) == 1) return 1;
  if (ref_dim(cell) == 2) return 2;
  return static_cast<int>(topology(cell).faces[facet].size());
}

using FacetMap = std::unordered_map<FacetKey, FacetUse, FacetKeyHash>;

// The report's first problem is the first one found; every problem makes it not ok.
void note_problem(ConformityReport& r, const std::string& what) {
  r.ok = false;
  if (r.first_problem.empty()) r.first_problem = what;
}

std::string describe(const FacetKey& k) {
  std::ostringstream s;
  s << "facet with vertices";
  for (NodeId v : k)
    if (v >= 0) s << ' ' << v;
  return s.str();
}

enum class FacetNodes { Same, OrderTransition, Mismatch };

// Two uses of one facet with the canonical node sequences a and b: the same nodes at the same
// places, a straight 2D edge at two orders, or a mismatch.
template <int Dim>
FacetNodes compare_facet_nodes(const HybridMesh<Dim>& mesh, const FacetKey& key, const std::vector<NodeId>& a,
                               const std::vector<NodeId>& b) {
  if (a == b) return FacetNodes::Same;
  if (a.size() != b.size() && straight_edge(mesh, key, a.size() > b.size() ? a : b)) return FacetNodes::OrderTransition;
  return FacetNodes::Mismatch;
}

// Every facet of every cell, with its number of uses; the nodes and orientation of a second use
// are checked against the first.
template <int Dim>
FacetMap cell_facets(const HybridMesh<Dim>& mesh, ConformityReport& r) {
  FacetMap facets;
  facets.reserve(mesh.num_cells() * 3);
  std::vector<NodeId> canonical;
  std::vector<std::pair<Weights, NodeId>> scratch;
  for (const CellBlock& b : mesh.cells) {
    const LagrangeElement& e = lagrange_element(b.type, b.order);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (int f = 0; f < e.num_facets(); ++f) {
        const auto& local = e.facet_nodes(f);
        const int nv = facet_vertices(b.type, f);
        const FacetKey key = make_key(c, local, nv);
        canonical_nodes(c, local, b.order, nv, key, scratch, canonical);
        FacetUse& use = facets[key];
        const auto around = around_min(c, local, nv);
        if (use.count == 0) {
          use.nodes = canonical;
          use.around = around;
        } else {
          const FacetNodes nodes = compare_facet_nodes(mesh, key, use.nodes, canonical);
          if (nodes == FacetNodes::OrderTransition) {
            ++r.order_transitions;
          } else if (nodes == FacetNodes::Mismatch) {
            ++r.node_mismatches;
            note_problem(r, "cells sharing the " + describe(key) + " have different high-order nodes on it");
          }
          if (use.count == 1 && !(around[0] == use.around[1] && around[1] == use.around[0])) {
            ++r.orientation_mismatches;
            note_problem(r, "the two cells sharing the " + describe(key) +
                                " lie on the same side of it (a duplicated, folded or mis-oriented cell)");
          }
        }
        ++use.count;
      }
    }
  }
  return facets;
}

// Every boundary facet must be a facet of a cell, with the same high-order nodes; marks them.
template <int Dim>
void match_boundary(const HybridMesh<Dim>& mesh, FacetMap& facets, ConformityReport& r) {
  std::vector<NodeId> canonical;
  std::vector<std::pair<Weights, NodeId>> scratch;
  for (const CellBlock& b : mesh.boundary) {
    const int nv = num_vertices(b.type);
    std::vector<int> local(static_cast<std::size_t>(b.nodes_per_cell()));
    for (std::size_t v = 0; v < local.size(); ++v) local[v] = static_cast<int>(v);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const FacetKey key = make_key(b.cell(i), local, nv);
      auto it = facets.find(key);
      if (it == facets.end()) {
        ++r.stray_boundary;
        note_problem(r, "boundary " + describe(key) + " is not a facet of any cell");
      } else {
        it->second.boundary = true;
        canonical_nodes(b.cell(i), local, b.order, nv, key, scratch, canonical);
        const FacetNodes nodes = compare_facet_nodes(mesh, key, canonical, it->second.nodes);
        if (nodes == FacetNodes::OrderTransition) {
          ++r.order_transitions;
        } else if (nodes == FacetNodes::Mismatch) {
          ++r.node_mismatches;
          note_problem(r, "boundary " + describe(key) + " has other high-order nodes than the cell it bounds");
        }
      }
    }
  }
}

// Each facet by its uses: interior, boundary, open (a hole) or overshared.
void classify_facets(const FacetMap& facets, ConformityReport& r) {
  for (const auto& [key, use] : facets) {
    if (use.count == 2 && !use.boundary) {
      ++r.interior_facets;
    } else if (use.count == 1 && use.boundary) {
      ++r.boundary_facets;
    } else if (use.count == 1) {
      ++r.open_facets;
      note_problem(r, describe(key) + " belongs to one cell and to no boundary (a hole in the mesh)");
    } else if (use.count >= 3) {
      ++r.overshared_facets;
      note_problem(r, describe(key) + " is shared by " + std::to_string(use.count) + " cells");
    } else {
      ++r.interior_facets;  // count == 2 and tagged: an interior (embedded) boundary
    }
  }
}

}  // namespace

template <int Dim>
ConformityReport check_conformity(const HybridMesh<Dim>& mesh) {
  // A mesh of boundary facets alone (a surface mesh) is checked as a mesh of those facets: closed
  // loops (2D) or closed surfaces (3D) with consistently oriented, shared high-order nodes; the
  // curves of a 3D surface are its boundary (its edges allowed to stay open).
  if (mesh.cells.empty() && !mesh.boundary.empty()) {
    HybridMesh<Dim> surface;
    surface.cells = mesh.boundary;
    for (CellBlock& b : surface.cells) b.tag = -1;
    if constexpr (Dim == 3) surface.boundary = mesh.curves;
    return check_conformity(surface);
  }
  // 1. The cells' facets, 2. the boundary facets against them, 3. every facet by its uses.
  ConformityReport r;
  FacetMap facets = cell_facets(mesh, r);
  match_boundary(mesh, facets, r);
  classify_facets(facets, r);
  return r;
}

template <int Dim>
void compact_nodes(HybridMesh<Dim>& mesh) {
  std::vector<NodeId> map(mesh.nodes.size(), -1);
  for (const auto* blocks : {&mesh.cells, &mesh.boundary, &mesh.curves})
    for (const CellBlock& b : *blocks)
      for (NodeId v : b.connectivity) map[static_cast<std::size_t>(v)] = 0;
  NodeId next = 0;
  for (std::size_t i = 0; i < map.size(); ++i)
    if (map[i] == 0) {
      mesh.nodes[static_cast<std::size_t>(next)] = mesh.nodes[i];
      map[i] = next++;
    }
  mesh.nodes.resize(static_cast<std::size_t>(next));
  for (auto* blocks : {&mesh.cells, &mesh.boundary, &mesh.curves})
    for (CellBlock& b : *blocks)
      for (NodeId& v : b.connectivity) v = map[static_cast<std::size_t>(v)];
}

template void compact_nodes(HybridMesh<2>&);
template void compact_nodes(HybridMesh<3>&);
template struct HybridMesh<2>;
template struct HybridMesh<3>;
template ConformityReport check_conformity(const HybridMesh<2>&);
template ConformityReport check_conformity(const HybridMesh<3>&);

template <int Dim>
bool is_curved(const HybridMesh<Dim>& mesh, const CellBlock& b, std::size_t i, double rel_tol) {
  if (b.order == 1) return false;
  const LagrangeElement& e = lagrange_element(b.type, b.order);
  const LagrangeElement& lin = lagrange_element(b.type, 1);
  const NodeId* c = b.cell(i);
  double size = 0, magnitude = 0;
  for (int k = 1; k < lin.size(); ++k) size = std::max(size, (mesh.nodes[c[k]] - mesh.nodes[c[0]]).norm());
  for (int k = 0; k < e.size(); ++k) magnitude = std::max(magnitude, mesh.nodes[c[k]].cwiseAbs().maxCoeff());
  const double tol = straight_tolerance(size, magnitude, rel_tol);
  double phi[8];
  for (int k = lin.size(); k < e.size(); ++k) {
    const auto xi = e.ref_node(k);
    lin.eval(xi.data(), phi);
    typename HybridMesh<Dim>::Point x = HybridMesh<Dim>::Point::Zero();
    for (int m = 0; m < lin.size(); ++m) x += phi[m] * mesh.nodes[c[m]];
    if ((x - mesh.nodes[c[k]]).norm() > tol) return true;
  }
  return false;
}

template bool is_curved<2>(const HybridMesh<2>&, const CellBlock&, std::size_t, double);
template bool is_curved<3>(const HybridMesh<3>&, const CellBlock&, std::size_t, double);

}  // namespace mesh
}  // namespace plaf
