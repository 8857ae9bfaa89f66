// SPDX-License-Identifier: MIT
// The 3D front of a surface mesh (curved_front.h).
#include <string>

#include "modules/base/error.h"
#include "modules/mesh/curved_front.h"

namespace plaf {
inline namespace mesh {

CurvedFront<3> surface_front(const HybridMesh<3>& surface, const ReferenceGeometry<3>& reference) {
  CurvedFront<3> f;
  f.order = 0;
  f.tags = surface.tags;
  for (const CellBlock& b : surface.boundary) {
    if (b.type != CellType::Triangle)
      throw MesherError("surface front: the surface has " + std::string(cell_name(b.type)) + " facets, not triangles");
    if (f.order != 0 && b.order != f.order)
      throw MesherError("surface front: triangles of orders " + std::to_string(f.order) + " and " +
                        std::to_string(b.order) + " in one surface");
    f.order = b.order;
    f.triangles.insert(f.triangles.end(), b.connectivity.begin(), b.connectivity.end());
    f.triangle_tag.insert(f.triangle_tag.end(), b.size(), b.tag);
  }
  if (f.order == 0) throw MesherError("surface front: the surface has no triangles");
  for (const CellBlock& b : surface.curves) {
    if (b.tag < 0 || surface.tags[static_cast<std::size_t>(b.tag)].kind != BoundaryKind::Symmetry) continue;
    if (b.order != f.order)
      throw MesherError("surface front: symmetry curves of order " + std::to_string(b.order) + " on triangles of order " +
                        std::to_string(f.order));
    f.rim_edges.insert(f.rim_edges.end(), b.connectivity.begin(), b.connectivity.end());
    f.rim_tag.insert(f.rim_tag.end(), b.size(), b.tag);
  }
  f.nodes = surface.nodes;
  f.normals.resize(f.nodes.size());
  for (std::size_t i = 0; i < f.nodes.size(); ++i) f.normals[i] = reference.normal(f.nodes[i]).normalized();
  return f;
}

}  // namespace mesh
}  // namespace plaf
