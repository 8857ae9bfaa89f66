// SPDX-License-Identifier: MIT
// The measure of a curved Lagrange cell (area of a 2D cell, volume of a 3D cell): the integral
// of det J over its reference cell (lagrange.h), by Gauss-Legendre rules collapsed onto the
// simplices (the Duffy map u = a (1 - b), v = b on the triangle, and its 3D analogue on the
// tetrahedron), with enough points to integrate det J, a polynomial, exactly (its degrees are in
// validity.h: 2(Q-1) on the triangle, 2Q-1 per axis on the quadrilateral, 3(Q-1) on the
// tetrahedron, 3Q-2 on the prism's triangle times 3Q-1 along its axis). A cell is measured in its
// own dimension, like JacobianCertifier::certify: triangles and quadrilaterals in 2D,
// tetrahedra and prisms in 3D. The measure is signed: negative where det J is.
#pragma once

#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace elements {

// coords: num_nodes(type, order) points of dimension ref_dim(type), row-major, Gmsh order.
// Throws InputError for a line cell (no area or volume in its own dimension).
double cell_measure(CellType type, int order, const double* coords);

}  // namespace elements
}  // namespace plaf
