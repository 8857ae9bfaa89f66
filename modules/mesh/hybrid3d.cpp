// SPDX-License-Identifier: MIT
// Assembly of the 3D hybrid mesh (hybrid3d.h).
#include "modules/mesh/hybrid3d.h"

namespace plaf {
inline namespace mesh {

HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> mesh, const CurvedFront<3>& outer) {
  if (outer.num_triangles() + outer.num_quads() > 0) {
    const int tag = mesh.add_tag("layers_outer", BoundaryKind::Named);
    if (outer.num_triangles() > 0) {
      CellBlock& b = mesh.boundary_block(CellType::Triangle, outer.order, tag);
      b.connectivity.insert(b.connectivity.end(), outer.triangles.begin(), outer.triangles.end());
    }
    if (outer.num_quads() > 0) {
      CellBlock& b = mesh.boundary_block(CellType::Quadrilateral, outer.order, tag);
      b.connectivity.insert(b.connectivity.end(), outer.quads.begin(), outer.quads.end());
    }
  }
  return mesh;
}

}  // namespace mesh
}  // namespace plaf
