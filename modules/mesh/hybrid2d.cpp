// SPDX-License-Identifier: MIT
// Assembly of the 2D hybrid mesh (hybrid2d.h).
#include "modules/mesh/hybrid2d.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "modules/base/error.h"
#include "modules/elements/validity.h"

namespace plaf {
inline namespace mesh {

namespace {

using Vec = Eigen::Vector2d;

std::uint64_t edge_key(NodeId a, NodeId b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b)), hi = static_cast<std::uint32_t>(std::max(a, b));
  return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

// The nodes of every order-q edge of the mesh, from its smaller to its larger vertex id (q + 1
// ids along the edge, ends included).
class EdgeNodes {
 public:
  EdgeNodes(const HybridMesh<2>& mesh, int q) {
    for (const CellBlock& b : mesh.cells) {
      if (b.order != q) continue;
      const LagrangeElement& e = lagrange_element(b.type, b.order);
      for (std::size_t i = 0; i < b.size(); ++i)
        for (int k = 0; k < static_cast<int>(topology(b.type).edges.size()); ++k) {
          std::vector<NodeId> along;
          for (int l : e.edge_nodes(k)) along.push_back(b.cell(i)[l]);
          add(along);
        }
    }
    for (const CellBlock& b : mesh.boundary) {
      if (b.type != CellType::Line || b.order != q) continue;
      for (std::size_t i = 0; i < b.size(); ++i) {
        const NodeId* c = b.cell(i);  // Gmsh line order: ends, then the interior from the first end
        std::vector<NodeId> along{c[0]};
        along.insert(along.end(), c + 2, c + q + 1);
        along.push_back(c[1]);
        add(along);
      }
    }
  }

  // Nodes along the edge a -> b (q + 1 ids), or nullptr if the edge is new.
  const std::vector<NodeId>* find(NodeId a, NodeId b) const {
    const auto it = map_.find(edge_key(a, b));
    return it == map_.end() ? nullptr : &it->second;
  }
  void add(std::vector<NodeId> along) {
    if (along.front() > along.back()) std::reverse(along.begin(), along.end());
    map_.emplace(edge_key(along.front(), along.back()), std::move(along));
  }

 private:
  std::unordered_map<std::uint64_t, std::vector<NodeId>> map_;
};

// Value at t in [0, 1] of the order-q interpolant through q + 1 equispaced points.
Vec interpolate(const std::vector<Vec>& pts, double t) {
  const int q = static_cast<int>(pts.size()) - 1;
  Vec x = Vec::Zero();
  for (int i = 0; i <= q; ++i) {
    double w = 1;
    for (int j = 0; j <= q; ++j)
      if (j != i) w *= (t * q - j) / static_cast<double>(i - j);
    x += w * pts[i];
  }
  return x;
}

}  // namespace

std::size_t add_triangles_at_order(HybridMesh<2>& mesh, const std::vector<std::array<NodeId, 3>>& triangles,
                                   int order) {
  check_order(order);
  EdgeNodes edges(mesh, order);
  const LagrangeElement& el = lagrange_element(CellType::Triangle, order);
  const int npc = el.size();
  // Append the block last: `mesh.block` may reallocate mesh.cells.
  std::vector<NodeId> conn;
  conn.reserve(triangles.size() * static_cast<std::size_t>(npc));
  std::vector<NodeId> cell(npc);
  std::array<std::vector<Vec>, 3> edge_pts;
  for (const auto& t : triangles) {
    for (int v = 0; v < 3; ++v) cell[v] = t[v];
    const Vec x0 = mesh.nodes[t[0]], x1 = mesh.nodes[t[1]], x2 = mesh.nodes[t[2]];
    bool curved = false;
    // Edge k of the triangle runs from vertex k to vertex (k + 1) % 3 (Gmsh's edge order).
    std::array<std::vector<NodeId>, 3> along;
    for (int k = 0; k < 3; ++k) {
      const NodeId a = t[k], b = t[(k + 1) % 3];
      const std::vector<NodeId>* known = edges.find(a, b);
      if (!known) {
        std::vector<NodeId> ids{std::min(a, b)};
        const Vec pa = mesh.nodes[std::min(a, b)], pb = mesh.nodes[std::max(a, b)];
        for (int s = 1; s < order; ++s) {
          ids.push_back(static_cast<NodeId>(mesh.nodes.size()));
          mesh.nodes.push_back(pa + (pb - pa) * (static_cast<double>(s) / order));
        }
        ids.push_back(std::max(a, b));
        edges.add(ids);
        known = edges.find(a, b);
      }
      along[k] = *known;
      if (along[k].front() != a) std::reverse(along[k].begin(), along[k].end());
      edge_pts[k].clear();
      const Vec pa = mesh.nodes[a], pb = mesh.nodes[b];
      for (int s = 0; s <= order; ++s) {
        const Vec p = mesh.nodes[along[k][s]];
        edge_pts[k].push_back(p);
        if ((p - (pa + (pb - pa) * (static_cast<double>(s) / order))).norm() > 1e-12 * (pb - pa).norm()) curved = true;
      }
    }
    // Edge and interior nodes by their lattice coordinates.
    for (int i = 3; i < npc; ++i) {
      const auto r = el.ref_node(i);
      const double l[3] = {1 - r[0] - r[1], r[0], r[1]};
      const int zero = l[0] < 1e-12 ? 0 : l[1] < 1e-12 ? 1 : l[2] < 1e-12 ? 2 : -1;
      if (zero >= 0) {
        // On edge k = the edge opposite vertex `zero`: k runs from vertex (zero + 1) % 3.
        const int k = (zero + 1) % 3;
        const double s = l[(k + 1) % 3] * order;
        cell[i] = along[k][static_cast<std::size_t>(std::lround(s))];
        continue;
      }
      Vec x = l[0] * x0 + l[1] * x1 + l[2] * x2;
      if (curved)
        for (int k = 0; k < 3; ++k) {
          const double li = l[k], lj = l[(k + 1) % 3], w = li + lj;
          const double tt = lj / w;
          const Vec chord = edge_pts[k].front() + tt * (edge_pts[k].back() - edge_pts[k].front());
          x += w * (interpolate(edge_pts[k], tt) - chord);
        }
      cell[i] = static_cast<NodeId>(mesh.nodes.size());
      mesh.nodes.push_back(x);
    }
    conn.insert(conn.end(), cell.begin(), cell.end());
  }
  CellBlock& block = mesh.block(CellType::Triangle, order);
  block.connectivity.insert(block.connectivity.end(), conn.begin(), conn.end());
  for (std::size_t b = 0; b < mesh.cells.size(); ++b)
    if (&mesh.cells[b] == &block) return b;
  return mesh.cells.size() - 1;
}

std::size_t split_quads(HybridMesh<2>& mesh) {
  std::size_t split = 0;
  JacobianCertifier certifier;
  std::vector<CellBlock> kept;
  std::vector<std::pair<int, std::vector<NodeId>>> made;  // (order, connectivity)
  for (CellBlock& b : mesh.cells) {
    if (b.type != CellType::Quadrilateral) {
      kept.push_back(std::move(b));
      continue;
    }
    const int q = b.order;
    const LagrangeElement& quad = lagrange_element(CellType::Quadrilateral, q);
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q);
    // Local quad node at each lattice point (i, j).
    std::vector<int> at((q + 1) * (q + 1));
    for (int k = 0; k < quad.size(); ++k) at[quad.lattice()[k][1] * (q + 1) + quad.lattice()[k][0]] = k;
    // The two triangles of each diagonal, as reference-square corners (i, j) * q.
    using Corner = std::array<int, 2>;
    const std::array<std::array<std::array<Corner, 3>, 2>, 2> halves = {{
        {{{{{0, 0}, {q, 0}, {q, q}}}, {{{0, 0}, {q, q}, {0, q}}}}},  // diagonal 0-2
        {{{{{q, 0}, {q, q}, {0, q}}}, {{{q, 0}, {0, q}, {0, 0}}}}},  // diagonal 1-3
    }};
    std::vector<NodeId> out;
    std::vector<double> coords(2 * static_cast<std::size_t>(tri.size()));
    std::array<std::vector<NodeId>, 2> cand;
    for (std::size_t c = 0; c < b.size(); ++c) {
      const NodeId* qc = b.cell(c);
      const double d02 = (mesh.nodes[qc[2]] - mesh.nodes[qc[0]]).norm();
      const double d13 = (mesh.nodes[qc[3]] - mesh.nodes[qc[1]]).norm();
      const int first = d02 <= d13 ? 0 : 1;
      // The shorter diagonal, or the other if the shorter one's triangles are not both valid
      // (when neither is, the second stays and the quality stage reports it).
      for (int attempt = 0; attempt < 2; ++attempt) {
        const int d = attempt == 0 ? first : 1 - first;
        bool valid = true;
        for (int h = 0; h < 2; ++h) {
          cand[h].clear();
          const auto& corners = halves[d][h];
          for (int k = 0; k < tri.size(); ++k) {
            const auto& l = tri.lattice()[k];  // triangle lattice: (i, j) with l0 = q - i - j
            const int i = (q - l[0] - l[1]) * corners[0][0] + l[0] * corners[1][0] + l[1] * corners[2][0];
            const int j = (q - l[0] - l[1]) * corners[0][1] + l[0] * corners[1][1] + l[1] * corners[2][1];
            cand[h].push_back(qc[at[(j / q) * (q + 1) + i / q]]);
          }
          for (int k = 0; k < tri.size(); ++k)
            for (int x = 0; x < 2; ++x) coords[2 * k + x] = mesh.nodes[cand[h][k]][x];
          if (!cell_valid<2>(certifier, CellType::Triangle, q, coords.data())) valid = false;
        }
        if (valid) break;
      }
      for (int h = 0; h < 2; ++h) out.insert(out.end(), cand[h].begin(), cand[h].end());
      ++split;
    }
    made.emplace_back(q, std::move(out));
  }
  mesh.cells = std::move(kept);
  for (auto& [q, conn] : made) {
    CellBlock& t = mesh.block(CellType::Triangle, q);
    t.connectivity.insert(t.connectivity.end(), conn.begin(), conn.end());
  }
  return split;
}

namespace {

// Adds a front's loops (order-Q elements) to the mesh's boundary under their tags; at order 1
// (their vertices alone) when `linear`.
void add_boundary_loops(HybridMesh<2>& mesh, const CurvedFront<2>& front, const std::vector<const FrontLoop*>& loops,
                        bool linear) {
  for (const FrontLoop* l : loops) {
    const int tag = mesh.add_tag(l->tag, l->kind);
    CellBlock& b = mesh.boundary_block(CellType::Line, linear ? 1 : front.order, tag);
    for (std::size_t e = 0; e < l->size(); ++e) {
      const NodeId* c = front.element(*l, e);
      if (linear)
        b.connectivity.insert(b.connectivity.end(), c, c + 2);
      else
        b.connectivity.insert(b.connectivity.end(), c, c + front.order + 1);
    }
  }
}

}  // namespace

Assembled2D assemble_hybrid_2d(const CurvedFront<2>& surface, const LayerResult<2>& layers,
                               const FillResult<2>* fill, const AssemblyOptions& o) {
  Assembled2D out;
  HybridMesh<2>& mesh = out.mesh;
  const bool grown = !layers.mesh.cells.empty() || !layers.mesh.boundary.empty();
  if (!grown && !fill) return {front_mesh(surface), 0};
  mesh = layers.mesh;
  if (fill) {
    std::vector<const FrontLoop*> bare;  // loops of the surface mesh that bound the fill directly
    for (const LinearLoop& l : layers.fill_front.loops)
      if (!l.layered) bare.push_back(&surface.loops[static_cast<std::size_t>(l.source_loop)]);
    mesh.nodes = fill->nodes;
    const bool uniform = o.uniform_order || o.order == 1;
    // The bare loops' boundary lines: at order Q they give the triangles their curved edges.
    add_boundary_loops(mesh, surface, bare, !uniform);
    if (uniform) {
      add_triangles_at_order(mesh, fill->simplices, o.order);
    } else {
      CellBlock& t = mesh.block(CellType::Triangle, 1);
      for (const auto& tri : fill->simplices) t.connectivity.insert(t.connectivity.end(), tri.begin(), tri.end());
    }
    if (!grown) return out;
  } else {
    // Layers alone: the outermost front is tagged "layers_outer".
    const int outer = mesh.add_tag("layers_outer", BoundaryKind::Named);
    CellBlock& b = mesh.boundary_block(CellType::Line, o.order, outer);
    for (const FrontLoop& l : layers.outer.loops)
      b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
  }
  if (o.split_quads) out.split_quads = split_quads(mesh);
  compact_nodes(mesh);  // e.g. the farfield's surface nodes are not part of a layers-only mesh
  return out;
}

}  // namespace mesh
}  // namespace plaf
