// SPDX-License-Identifier: MIT
// The fill's tetrahedra that a curved outer front inverts, untangled by moving their own
// high-order nodes (issue 30: a valid transition from stopped columns to the fill).
//
// The fill is linear (TetGen's tetrahedra) and is assembled at the layers' order on the outer
// front's own nodes (hybrid3d.h). Where columns stopped curved, or before their first layer (the
// wall itself is then the front), a fill tetrahedron takes the front's curved triangles and edges.
// Over a thin tetrahedron (TetGen may put no point on the front, so an "ear" spanning two wall
// triangles in a fold of the wall is as thick as the fold) a curved edge bulging by as much as the
// cell is thick inverts it: on the published 717 wing (h0 1e-5 L, Q2) a wall edge 0.062 long
// with a sag of 2.7e-3 under an ear 2.7e-3 thick (scaled Jacobian -2.2), while the ear's free edge
// beside it, 3e-3 away, stayed straight.
//
// The fill has been bent with the curved front first (bend_fill3d.h); this is for what that leaves.
// A high-order node that is no cell's vertex and lies on no boundary facet or curve is free to
// move (the fill's own edges, and the layers' column edges and top faces where the front has a
// step around stopped columns): the cells' shapes are their vertices', high-order nodes only bend
// them. Every free node of an invalid fill tetrahedron and of the fill tetrahedra sharing a
// vertex with it is tried, node by node: at its linear position, at that plus a half and a whole
// of each of the 8 largest displacements from the linear position of the curved nodes in the
// fill tetrahedra around it and of their mean (so a straight edge beside a bent one bends with
// it), then by a compass search (the axes, the cube's face diagonals and the largest
// displacement, the step halved 6 times). Then each vertex of a cell still invalid that lies on
// no boundary facet or curve (the fill's own points, the layers' column nodes off the wall) by a
// compass search over its shift, carrying every node of the cells around it along by the node's
// linear weight on it (their curvature kept; a node with weight on such a vertex is on no
// boundary); and the free nodes of each invalid cell shifted together, where each node alone
// trades one cell for another. A move is kept when it inverts none of the layers' cells (all
// certified valid by the layer stage: a move may not trade a fill cell's inversion for one of
// theirs), then lowers the number of invalid cells around the node (every cell of the mesh holding
// it, layers' prisms and tetrahedra too) or, at the same number, raises their smallest certified min det J over each cell's largest when
// first seen (Bezier bounds, validity.h). Up to 30 sweeps, until every cell of the region is
// valid, a sweep moves nothing or 2 million cells have been certified (the compass search takes at
// most 24 steps per node and sweep): bounded work on any front.
// The last resort for a fill cell still invalid: it is made straight (TetGen's linear cell is
// valid), and each cell that turns invalid by it too, in turn (at most 2048; a layers' cell too, which
// straight hands its bend to the cell under it, down to the wall if need be), kept when all are then
// valid. Where those cells' nodes are on the boundary (a bare wall edge) the wall's curvature is
// given up there, as the surface stage straightens a triangle it cannot curve validly: counted
// and measured in the report (layers.fill_straightened_cells, fill_straightened_boundary_nodes).
// The quality stage certifies every cell afterwards as always: what stays invalid fails the run.
// Measured on the published bodies (h0 1e-5 L, Q2, TetGen fill, configs sized from the bounding
// box): see the closing note of issue 30 and layers.fill_untangled in the report.
#pragma once

#include <cstddef>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace mesh {

struct FillUntangling {
  std::size_t curved = 0;              // fill tetrahedra with a node off its linear position
  std::size_t flat = 0;                // straight fill tetrahedra not certified valid (flat slivers)
  std::size_t invalid_before = 0;      // of those and the curved, not certified valid before
  std::size_t invalid_after = 0;       // ... and after
  std::size_t nodes_moved = 0;         // free high-order nodes moved
  std::size_t vertices_moved = 0;      // vertices off the boundary moved (their cells' nodes carried along)
  std::size_t certified = 0;           // cells certified on the way (the cost)
  std::size_t cells_straightened = 0;  // cells made straight (the last resort)
  std::size_t straightened = 0;        // ... their boundary nodes put back on the straight sides
  double straightened_max = 0;         // ... the farthest any of them moved (the geometry given up)
};

// The fill's tetrahedra are cells [first_cell, end) of mesh.cells[block] (order Q tetrahedra).
// Movable: every high-order node (a vertex of no cell) on no boundary facet or curve.
struct UntangleMoves {
  bool nodes = true;     // the free high-order nodes
  bool vertices = true;  // the invalid cells' vertices off the boundary
};
FillUntangling untangle_fill_3d(HybridMesh<3>& mesh, std::size_t block, std::size_t first_cell,
                                UntangleMoves moves = {});

}  // namespace mesh
}  // namespace plaf
