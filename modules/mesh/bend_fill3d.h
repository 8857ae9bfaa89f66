// SPDX-License-Identifier: MIT
// The fill's tetrahedra bent with a curved outer front: the front's curvature extended smoothly
// into the fill (issue 30: a valid transition from stopped columns to the fill).
//
// PLAF hands the fill a linear front (paper Sec. II: the layers attenuate their curvature until
// the front is linear, then the advancing front meshes the rest with linear cells). On a real
// body some columns stop before that (layers.events), and the front stays curved there: a
// triangle of 0.02 bulging by 0.0019 on the published spot (h0 1e-5 L, Q2). TetGen knows only its
// linear triangles and puts points as close as 3e-4 to them (around stopped columns the step
// faces are a few layers high), so a fill tetrahedron taking the curved triangle (or one of its
// edges) as its own is thinner than the bulge and inverts. Moving that cell's own nodes cannot
// help when its whole neighbourhood is thinner than the bulge: the neighbourhood has to move with
// the bulge (the paper is silent here; this is the robust choice, the one of the a-posteriori
// curving methods: the straight-sided mesh deformed by a smooth extension of the boundary's
// displacement).
//
// The map: every fill node that lies on no fill boundary (TetGen's points and the fill's own
// high-order nodes) moves by D(x), an inverse-distance (Shepard) blend of the displacements of the
// fill's boundary triangles near it. A boundary triangle F (the outer front's, a bare wall's, a
// plane's, the farfield's: a face of one fill tetrahedron whose nodes all belong to other cells or
// boundary facets) has the displacement D_F(xi) = X_F(xi) - L_F(xi) of its curved map from its
// linear one, zero on a straight triangle. At a node x, with delta_F its distance to F's plane
// triangle, xi_F the closest point there, h_F F's longest edge and t_F = delta_F / (reach h_F):
//     D(x) = sum_F w_F(x) s(t_F) D_F(xi_F) / sum_F w_F(x),  w_F = s(t_F) / (delta_F^2 + (1e-6 h_F)^2),
// over the triangles with t_F < 1, s(t) = 1 - 3 t^2 + 2 t^3 (1 at the triangle, 0 with zero slope at
// reach h_F). Near one triangle D tends to that triangle's displacement, so a point just outside a
// bulge moves with it, and a straight triangle near a curved one holds its neighbours in place; a
// triangle's reach ends smoothly, so D is continuous and its slope is about 1.5 sag / (reach h):
// 0.15 on the spot's front (sag / edge 0.1), a mild smooth deformation, which leaves the fill's
// small cells about as valid as TetGen made them. Every fill node takes D at its position on the
// linear fill (it is applied once, to the linear fill of the assembly), so each fill tetrahedron
// is the order-Q interpolant of x + D(x) over its linear self, and it meets the front's curved
// nodes where it touches them (D is the front's own displacement there).
// Measured on the published bodies (configs sized from the bounding box, TetGen fill): see the
// closing note of issue 30 and layers.fill_bent_nodes in the report. What the map leaves inverted
// is the untangler's work (untangle3d.h); the quality stage certifies every cell afterwards.
// Guarded: no cell turns invalid. The map is smooth but TetGen's slivers (dihedral angles of
// 0.001 degrees on the published bodies) invert under almost any motion; a cell valid before the
// map and not after, or whose corners (its vertices' straight tetrahedron) turn inverted, gets its
// moved nodes back, round after round, until every cell valid before is valid and no cell's
// corners inverted (with all nodes back the fill is as it was). A curved cell can be certified
// with inverted corners, but `gmsh -check` and solvers that measure cells by their vertices
// reject it.

#pragma once

#include <cstddef>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace mesh {

struct FillBending {
  std::size_t curved_faces = 0;    // the fill's boundary triangles off their linear position
  std::size_t nodes_moved = 0;     // fill nodes (TetGen's points and high-order nodes) displaced
  std::size_t nodes_returned = 0;  // ... of the map's, put back where a cell turned invalid
  double max_shift = 0;            // the largest displacement kept
  std::size_t invalid_before = 0;  // fill cells the map moves that were invalid before it
  std::size_t invalid_after = 0;   // ... and after it
};

// The fill's tetrahedra are cells [first_cell, end) of mesh.cells[block] (order Q, straight sided:
// as the assembly made them). reach: a triangle's displacement fades out at reach times its
// longest edge.
FillBending bend_fill_3d(HybridMesh<3>& mesh, std::size_t block, std::size_t first_cell, double reach = 1.0);

}  // namespace mesh
}  // namespace plaf
