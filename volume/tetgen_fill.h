// SPDX-License-Identifier: MIT
// 3D volume fill with TetGen (H. Si, "TetGen, a Delaunay-based quality tetrahedral mesh
// generator", ACM TOMS 41, 2015): linear tetrahedra inside a closed triangulated boundary,
// with the boundary preserved exactly (no Steiner points on it, switch Y).
#pragma once

#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf::volume {

struct TetFillParams {
  double max_radius_edge = 1.5;  // quality bound (switch q); 0 disables refinement
  double max_volume = 0;         // volume bound (switch a); 0: none
};

// boundary: linear triangles (one boundary block of order 1 per tag) over mesh.nodes; returns a
// mesh with the same nodes first, new interior nodes after, and order-1 tetrahedra of positive
// volume. Throws MesherError (with TetGen's switches and code) if TetGen fails, InputError if
// the boundary is not made of linear triangles.
HybridMesh<3> tetgen_fill(const HybridMesh<3>& boundary, const TetFillParams& params);

}  // namespace plaf::volume
