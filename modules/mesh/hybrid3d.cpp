// SPDX-License-Identifier: MIT
// Assembly of the 3D hybrid mesh (hybrid3d.h).
#include "modules/mesh/hybrid3d.h"

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <vector>
#include <utility>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace mesh {

HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> mesh, const CurvedFront<3>& outer, std::size_t* bare_wall_facets) {
  // A wall triangle whose three columns stopped before growing is also an outer triangle, with
  // the same nodes: no cell lies between the two. Both are left out (bare_wall_facets).
  std::set<std::array<NodeId, 3>> outer_keys;
  for (std::size_t t = 0; t < outer.num_triangles(); ++t) {
    std::array<NodeId, 3> k = {outer.triangle(t)[0], outer.triangle(t)[1], outer.triangle(t)[2]};
    std::sort(k.begin(), k.end());
    outer_keys.insert(k);
  }
  std::set<std::array<NodeId, 3>> bare;
  for (CellBlock& b : mesh.boundary) {
    if (b.type != CellType::Triangle || b.tag < 0 || mesh.tags[static_cast<std::size_t>(b.tag)].kind != BoundaryKind::Wall)
      continue;
    const std::size_t np = static_cast<std::size_t>(b.nodes_per_cell());
    std::vector<NodeId> kept;
    for (std::size_t i = 0; i < b.size(); ++i) {
      std::array<NodeId, 3> k = {b.cell(i)[0], b.cell(i)[1], b.cell(i)[2]};
      std::sort(k.begin(), k.end());
      if (outer_keys.count(k)) {
        bare.insert(k);
        continue;
      }
      kept.insert(kept.end(), b.cell(i), b.cell(i) + np);
    }
    b.connectivity = std::move(kept);
  }
  if (bare_wall_facets) *bare_wall_facets = bare.size();
  if (outer.num_triangles() + outer.num_quads() > 0) {
    const int tag = mesh.add_tag("layers_outer", BoundaryKind::Named);
    if (outer.num_triangles() > 0) {
      CellBlock& b = mesh.boundary_block(CellType::Triangle, outer.order, tag);
      const std::size_t np = static_cast<std::size_t>(num_nodes(CellType::Triangle, outer.order));
      for (std::size_t t = 0; t < outer.num_triangles(); ++t) {
        std::array<NodeId, 3> k = {outer.triangle(t)[0], outer.triangle(t)[1], outer.triangle(t)[2]};
        std::sort(k.begin(), k.end());
        if (!bare.count(k)) b.connectivity.insert(b.connectivity.end(), outer.triangle(t), outer.triangle(t) + np);
      }
    }
    if (outer.num_quads() > 0) {
      CellBlock& b = mesh.boundary_block(CellType::Quadrilateral, outer.order, tag);
      b.connectivity.insert(b.connectivity.end(), outer.quads.begin(), outer.quads.end());
    }
  }
  // The nodes of left-out triangles that no other element uses go too (Gmsh's check counts them
  // as nodes connected to no 3D element: the published 717 wing, h0 1e-5 L, 86 of them).
  if (!bare.empty()) compact_nodes(mesh);
  return mesh;
}

namespace {

// A lattice node of an order-Q simplex by its integer weights on the simplex's linear vertices:
// the (vertex, weight) pairs of positive weight, sorted (so every cell sharing the node agrees).
using NodeKey = std::array<std::pair<NodeId, int>, 4>;

template <std::size_t N>
NodeKey node_key(const std::array<NodeId, N>& v, const std::array<int, N>& w) {
  NodeKey k;
  k.fill({-1, 0});
  for (std::size_t i = 0; i < N; ++i)
    if (w[i] > 0) k[i] = {v[i], w[i]};
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace

HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> mesh, const CurvedFront<3>& outer, const FillResult<3>& fill) {
  if (outer.num_quads() > 0)
    throw MesherError("assembly: the layers' outer front has quadrilaterals; a linear fill meets triangles only");
  const std::size_t n_layer = mesh.nodes.size();
  if (fill.nodes.size() < n_layer)
    throw MesherError("assembly: the fill returned fewer nodes than the layer mesh has (linear_front.h's contract)");
  for (std::size_t i = 0; i < n_layer; i += std::max<std::size_t>(1, n_layer / 64))
    if (fill.nodes[i] != mesh.nodes[i]) throw MesherError("assembly: the fill moved a layer node (linear_front.h's contract)");
  mesh.nodes.insert(mesh.nodes.end(), fill.nodes.begin() + static_cast<std::ptrdiff_t>(n_layer), fill.nodes.end());
  const int q = outer.order;
  const LagrangeElement& te = lagrange_element(CellType::Triangle, q);
  const LagrangeElement& tet = lagrange_element(CellType::Tetrahedron, q);
  std::map<NodeKey, NodeId> ids;
  // The outer front's nodes as they are (the prisms' top faces).
  for (std::size_t t = 0; t < outer.num_triangles(); ++t) {
    const NodeId* n = outer.triangle(t);
    const std::array<NodeId, 3> v = {n[0], n[1], n[2]};
    for (int k = 0; k < te.size(); ++k) {
      const Lattice& l = te.lattice()[static_cast<std::size_t>(k)];
      ids.emplace(node_key<3>(v, {q - l[0] - l[1], l[0], l[1]}), n[k]);
    }
  }
  auto node = [&](const NodeKey& key) {
    if (key[3].second == q) return key[3].first;  // a linear vertex is itself (sorted: it comes last)
    const auto [it, added] = ids.emplace(key, static_cast<NodeId>(mesh.nodes.size()));
    if (added) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (const auto& [v, w] : key)
        if (w > 0) x += (static_cast<double>(w) / q) * mesh.nodes[static_cast<std::size_t>(v)];
      mesh.nodes.push_back(x);
    }
    return it->second;
  };
  CellBlock& tets = mesh.block(CellType::Tetrahedron, q);
  for (const auto& s : fill.simplices)
    for (const Lattice& l : tet.lattice())
      tets.connectivity.push_back(node(node_key<4>(s, {q - l[0] - l[1] - l[2], l[0], l[1], l[2]})));
  std::vector<int> tag_of(fill.tags.size());
  for (std::size_t k = 0; k < fill.tags.size(); ++k) tag_of[k] = mesh.add_tag(fill.tags[k].name, fill.tags[k].kind);
  for (std::size_t f = 0; f < fill.boundary.size(); ++f) {
    CellBlock& b = mesh.boundary_block(CellType::Triangle, q, tag_of[static_cast<std::size_t>(fill.boundary_tag[f])]);
    for (const Lattice& l : te.lattice())
      b.connectivity.push_back(node(node_key<3>(fill.boundary[f], {q - l[0] - l[1], l[0], l[1]})));
  }
  // A node no cell or facet uses goes (Gmsh's check counts it as connected to no 3D element: one on
  // the published 717 wing, h0 1e-4 L, three on the spot, h0 1e-5 L).
  compact_nodes(mesh);
  return mesh;
}

}  // namespace mesh
}  // namespace plaf
