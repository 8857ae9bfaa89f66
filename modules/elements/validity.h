// SPDX-License-Identifier: MIT
// Implements certified validity of curved Lagrange cells from A. Johnen, J.-F. Remacle and
// C. Geuzaine, "Geometrical validity of curvilinear finite elements", J. Comput. Phys. 233 (2013).
//
// The Jacobian determinant of an order-Q cell is a polynomial (triangle: degree 2(Q-1),
// quadrilateral: (2Q-1) in each variable, tetrahedron: 3(Q-1), prism: 3Q-2 in the triangle
// times 3Q-1 along the prism axis). Its Bernstein (Bezier) coefficients bound it from below and
// above over the cell; where the bounds cannot decide the sign, the cell is subdivided and the
// coefficients recomputed on each part, until the sign is proven. Cells are in their own
// dimension: triangles and quadrilaterals in 2D, tetrahedra and prisms in 3D.
//
// Curved surface triangles in 3D (a surface mesh) have no volume Jacobian; they are certified
// relative to their flat triangle: the nodes are written in the flat triangle's plane frame
// (origin at vertex 0, first axis along edge 0-1, second axis in the plane, so the flat triangle
// is counter-clockwise) and certified as a 2D triangle. det J > 0 everywhere means the curved
// triangle projects one-to-one onto its flat triangle's plane, without folds over its edges.
// Surface quadrilaterals (the side faces of prisms on a symmetry plane) are certified the same
// way in the plane normal to their vector area (x2 - x0) x (x3 - x1), which is the plane of a
// planar quadrilateral and the best-fitting one of a warped one: origin at vertex 0, first axis
// along edge 0-1 projected onto the plane, so the vertices run counter-clockwise.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace elements {

struct ValidityOptions {
  // Refine until the bounds on min det J and max det J are within rel_tol * max det J.
  double rel_tol = 1e-2;
  // Subdivision depth at which refinement stops; an undecided sign then counts as invalid.
  int max_depth = 12;
};

struct JacobianBounds {
  bool valid = false;                   // det J > 0 at every point of the cell, proven
  bool proven = false;                  // the sign question was decided (false: depth exhausted; valid is false)
  double min_lower = 0, min_upper = 0;  // min over the cell of det J lies in [min_lower, min_upper]
  double max_lower = 0, max_upper = 0;  // max over the cell of det J lies in [max_lower, max_upper]
  int subdivisions = 0;                 // number of sub-cells examined beyond the cell itself
  // Bounds on the scaled Jacobian min det J / max det J (meaningful when max det J > 0).
  double scaled_lower() const;
  double scaled_upper() const;
};

// Reusable certifier: holds the Bernstein transforms per (type, order) and scratch space, so
// certifying a cell does not allocate once warmed up. Not thread-safe: use one per thread.
class JacobianCertifier {
 public:
  explicit JacobianCertifier(ValidityOptions options = {});
  ~JacobianCertifier();
  JacobianCertifier(const JacobianCertifier&) = delete;
  JacobianCertifier& operator=(const JacobianCertifier&) = delete;

  // coords: num_nodes(type, order) points of dimension ref_dim(type), row-major (x0 y0 [z0] x1 ...),
  // in Gmsh node order.
  JacobianBounds certify(CellType type, int order, const double* coords);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The nodes of an order-`order` surface triangle (num_nodes(Triangle, order) points, Gmsh order)
// written in its flat triangle's plane frame (see above), row-major (x0 y0 x1 y1 ...), into
// coords2d. False (coords2d unset) when the flat triangle is degenerate (zero area, to round-off,
// or a non-finite vertex).
bool surface_triangle_plane_coords(int order, const Eigen::Vector3d* nodes, double* coords2d);

// The certified bounds of one curved surface triangle relative to its flat triangle (det J of the
// plane-frame map; scaled_lower() is its certified min / max). A degenerate flat triangle is
// invalid (proven, all bounds 0). Throws InputError for a non-finite node, like certify().
JacobianBounds certify_surface_triangle(JacobianCertifier& certifier, int order, const Eigen::Vector3d* nodes);

// The nodes of an order-`order` surface quadrilateral (num_nodes(Quadrilateral, order) points,
// Gmsh order) in the plane frame of its vector area (see above), into coords2d. False when the
// vector area vanishes (to round-off relative to the diagonals) or a vertex is not finite.
bool surface_quad_plane_coords(int order, const Eigen::Vector3d* nodes, double* coords2d);

// The certified bounds of one curved surface quadrilateral in that plane frame; a degenerate one
// is invalid (proven, all bounds 0). Throws InputError for a non-finite node.
JacobianBounds certify_surface_quad(JacobianCertifier& certifier, int order, const Eigen::Vector3d* nodes);

// True when the corners of a simplex cell (its first Dim + 1 nodes, coordinates xs row-major in
// Dim dimensions) span a positive area (2D) or volume (3D), by the exact predicates; true for
// every other cell type. A curved cell can be certified (det J > 0 everywhere) with its corner
// simplex inverted, which `gmsh -check` and solvers that measure cells by their vertices reject:
// the layers and the quality stage ask both (cell_valid below); the fill's bend and untangler
// (bend_fill3d.h, untangle3d.h) check the corners by their own rules.
template <int Dim>
bool simplex_corners_positive(CellType type, const double* xs);

// The verdict the layers use: for a simplex its corners positive (exact, cheap: asked first) and
// certified det J > 0 (certifier.certify). coords as for certify, in Dim = ref_dim(type) dimensions.
template <int Dim>
bool cell_valid(JacobianCertifier& certifier, CellType type, int order, const double* coords) {
  return simplex_corners_positive<Dim>(type, coords) && certifier.certify(type, order, coords).valid;
}

// det J of the cell's mapping at reference point xi (for sampling and tests).
double jacobian_determinant(CellType type, int order, const double* coords, const double* xi);

}  // namespace elements
}  // namespace plaf
