// SPDX-License-Identifier: MIT
#include "modules/mesh/extrude_front.h"

#include <array>
#include <map>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace mesh {

CurvedFront<3> extrude_front(const CurvedFront<2>& section, double z0, double z1, int n_z) {
  if (!(z1 > z0) || n_z < 1) throw MesherError("extrude_front: needs z1 > z0 and at least one row");
  const int q = section.order;
  CurvedFront<3> f;
  f.order = q;
  const int z0_tag = 0, z1_tag = 1;
  f.tags = {{"z0", BoundaryKind::Symmetry}, {"z1", BoundaryKind::Symmetry}};
  const int steps = n_z * q;  // z levels of the lattice
  // Node (section node id, z level) -> 3D id: every lattice node is a section node at a z level.
  std::map<std::pair<NodeId, int>, NodeId> ids;
  auto node = [&](NodeId s, int level) {
    const auto [it, added] = ids.emplace(std::make_pair(s, level), static_cast<NodeId>(f.nodes.size()));
    if (added) {
      const Eigen::Vector2d& x = section.nodes[static_cast<std::size_t>(s)];
      const double z = level == steps ? z1 : z0 + (z1 - z0) * static_cast<double>(level) / steps;
      f.nodes.emplace_back(x.x(), x.y(), z);
      const Eigen::Vector2d& n = section.normals[static_cast<std::size_t>(s)];
      f.normals.emplace_back(n.x(), n.y(), 0.0);
    }
    return it->second;
  };
  const std::vector<Lattice>& lattice = lagrange_element(CellType::Triangle, q).lattice();
  bool any = false;
  for (const FrontLoop& loop : section.loops) {
    if (loop.kind != BoundaryKind::Wall) continue;
    any = true;
    const int tag = static_cast<int>(f.tags.size());
    f.tags.push_back({loop.tag, loop.kind});
    const std::size_t ne = loop.size();
    for (std::size_t e = 0; e < ne; ++e) {
      const NodeId* el = loop.elements.data() + e * static_cast<std::size_t>(q + 1);
      // The section node at lattice position k = 0..q along the element (Gmsh line order: ends
      // first, then the interior from start to end).
      auto along = [&](int k) { return k == 0 ? el[0] : k == q ? el[1] : el[1 + k]; };
      for (int row = 0; row < n_z; ++row) {
        // Corners as (k, level): A (0, r), B (q, r), C (q, r + q), D (0, r + q).
        const int r = row * q;
        const std::array<std::array<int, 2>, 3> t0 = {{{0, r}, {q, r + q}, {q, r}}};   // A, C, B
        const std::array<std::array<int, 2>, 3> t1 = {{{0, r}, {0, r + q}, {q, r + q}}};  // A, D, C
        for (const auto& t : {t0, t1}) {
          for (const Lattice& l : lattice) {
            const int w1 = l[0], w2 = l[1], w0 = q - w1 - w2;  // weights x q
            const int k = (w0 * t[0][0] + w1 * t[1][0] + w2 * t[2][0]) / q;
            const int level = (w0 * t[0][1] + w1 * t[1][1] + w2 * t[2][1]) / q;
            f.triangles.push_back(node(along(k), level));
          }
          f.triangle_tag.push_back(tag);
        }
      }
      // The rims, running as in their triangles: B -> A at z0 (triangle A, C, B of the first
      // row), D -> C at z1 (triangle A, D, C of the last row).
      f.rim_edges.push_back(node(along(q), 0));
      f.rim_edges.push_back(node(along(0), 0));
      for (int k = q - 1; k >= 1; --k) f.rim_edges.push_back(node(along(k), 0));
      f.rim_tag.push_back(z0_tag);
      f.rim_edges.push_back(node(along(0), steps));
      f.rim_edges.push_back(node(along(q), steps));
      for (int k = 1; k < q; ++k) f.rim_edges.push_back(node(along(k), steps));
      f.rim_tag.push_back(z1_tag);
    }
  }
  if (!any) throw MesherError("extrude_front: the section has no wall loop");
  return f;
}

}  // namespace mesh
}  // namespace plaf
