// SPDX-License-Identifier: MIT
// Assembly of the 3D hybrid mesh (PLAF Sec. II.E): the layer mesh (curved prisms, the wall
// triangles, the symmetry quadrilaterals) and, without a fill, its outer front as the boundary
// tagged `layers_outer`. The TetGen fill joins here next (issue 15).
#pragma once

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"

namespace plaf {
inline namespace mesh {

// The 3D mesh of a layer stage's result: its mesh (cells and boundary; moved in, it holds every
// node of the run) plus the outer front's triangles (order Q) in a boundary block tagged
// `layers_outer` (kind Named).
HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> layer_mesh, const CurvedFront<3>& outer);

}  // namespace mesh
}  // namespace plaf
