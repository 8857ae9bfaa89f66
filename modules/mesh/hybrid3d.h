// SPDX-License-Identifier: MIT
// Assembly of the 3D hybrid mesh (PLAF Sec. II.E): the layer mesh (curved prisms, tetrahedra of a
// first layer with fans, the wall triangles, the symmetry quadrilaterals and triangles) and,
// without a fill, its outer front as the boundary
// tagged `layers_outer`; with a fill (the TetGen tetrahedra, issue 15), the fill's tetrahedra at
// the layers' order instead, straight-sided, on the outer front's own nodes there (its high-order
// nodes are the prisms' top nodes), and the fill's boundary facets (the farfield) at that order.
#pragma once

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"

namespace plaf {
inline namespace mesh {

// The 3D mesh of a layer stage's result: its mesh (cells and boundary; moved in, it holds every
// node of the run) plus the outer front's triangles (order Q) in a boundary block tagged
// `layers_outer` (kind Named). Where a wall triangle's columns all stopped before their first
// layer (local stops, layer_core.h) the wall triangle is an outer triangle too, with no cell
// between: both are left out and counted in *bare_wall_facets (a fill would meet the wall there),
// and then the nodes no element uses are dropped (compact_nodes: the others renumbered in order).
HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> layer_mesh, const CurvedFront<3>& outer,
                                 std::size_t* bare_wall_facets = nullptr);

// The layer mesh and a fill of its outer front (FillResult's contract, linear_front.h: the layer
// mesh's nodes first). Every node of an order-Q tetrahedron or boundary triangle is identified by
// its weights on the linear vertices, so edges and faces are shared with each other and with the
// outer front's triangles (whose nodes are taken as they are). Throws MesherError when the fill
// breaks the node contract or the outer front holds quadrilaterals (a linear fill meets triangles).
HybridMesh<3> assemble_hybrid_3d(HybridMesh<3> layer_mesh, const CurvedFront<3>& outer, const FillResult<3>& fill);

}  // namespace mesh
}  // namespace plaf
