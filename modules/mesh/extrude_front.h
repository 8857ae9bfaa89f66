// SPDX-License-Identifier: MIT
// A 2D front extruded along z into the 3D front between two symmetry planes: the section's wing
// (issues 14 and 16: the 3D layers on an extruded section reproduce the 2D layers on the section).
//
// Every wall loop of the 2D front becomes a band of order-Q triangles between z0 and z1 in n_z
// rows: each 2D element [a, b] and row [z_j, z_j+1] give the triangles (A, C, B) and (A, D, C)
// (A = (a, z_j), B = (b, z_j), C = (b, z_j+1), D = (a, z_j+1)), facing the domain as the 2D loop
// does (its left). A lattice node of barycentric weights (l0, l1, l2) sits at the section
// element's own Lagrange map x(s) at s = the weighted section parameter, z = the weighted z: the
// triangles are exactly the ruled surface of the curved 2D elements, and every node is a 2D node
// (s = k/Q) at some z = z0 + m (z1 - z0) / (n_z Q), with the 2D node's normal (z = 0). The ends
// are rims tagged "z0" and "z1" (kind Symmetry) on the planes z = z0 and z = z1. Farfield loops
// are left out.
#pragma once

#include "modules/mesh/curved_front.h"

namespace plaf {
inline namespace mesh {

// Throws MesherError for z1 <= z0, n_z < 1 or a front without wall loops.
CurvedFront<3> extrude_front(const CurvedFront<2>& section, double z0, double z1, int n_z);

}  // namespace mesh
}  // namespace plaf
