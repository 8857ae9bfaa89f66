// SPDX-License-Identifier: MIT
// Assembly of the 2D hybrid mesh (PLAF, Sec. II and Fig. 12): the fill's linear triangles joined
// to the curved layer cells, and the optional split of the layer quadrilaterals into triangles.
#pragma once

#include <array>
#include <vector>

#include "modules/mesh/curved_front.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/linear_front.h"

namespace plaf {
inline namespace mesh {

// Adds the triangles (counter-clockwise vertex ids of mesh.nodes) as cells of `order`. An edge
// that already exists at that order in the mesh (an edge of a cell, or a boundary line) keeps its
// nodes, so the triangles share the layers' outer edges and follow curved boundary lines; other
// edges get new straight-sided nodes, shared by the two triangles of the edge. Interior nodes of
// a triangle with a curved edge follow the edge's displacement from its chord, blended into the
// triangle as (l_i + l_j) g_ij(l_j / (l_i + l_j)) for the edge (i, j) in barycentric l; other
// interior nodes are straight. Returns the index of the triangle block in mesh.cells.
std::size_t add_triangles_at_order(HybridMesh<2>& mesh, const std::vector<std::array<NodeId, 3>>& triangles,
                                   int order);

// Splits every quadrilateral of the mesh into two triangles of the same order in reference
// space: the triangles' nodes are the quadrilateral's own lattice nodes (no node is added, and
// the quad's edges keep theirs). The diagonal is the shorter one unless that gives a triangle
// whose certified Jacobian is not positive while the other does not. Quad blocks are replaced by
// triangle blocks. Returns the number of quadrilaterals split.
std::size_t split_quads(HybridMesh<2>& mesh);

struct AssemblyOptions {
  int order = 1;
  bool uniform_order = true;  // the fill's triangles at order Q (else order 1, and the bare loops too)
  bool split_quads = false;
};

struct Assembled2D {
  HybridMesh<2> mesh;
  std::size_t split_quads = 0;
};

// The 2D hybrid mesh from the stages' products: the layer mesh (or the surface front's nodes,
// when `layers` is the unlayered result), the fill's triangles joined at order Q, the loops that
// bound the fill directly (the farfield, bodies without layers) as boundary lines from `surface`
// (ids valid by LayerResult's node-numbering contract), the outer front tagged `layers_outer`
// when there is no fill; then the optional quad split and node compaction.
Assembled2D assemble_hybrid_2d(const CurvedFront<2>& surface, const LayerResult<2>& layers,
                               const FillResult<2>* fill, const AssemblyOptions& options);

}  // namespace mesh
}  // namespace plaf
