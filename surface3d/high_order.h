// SPDX-License-Identifier: MIT
// High-order surface triangles (paper Sec. II.E: the initial front is a surface mesh of
// high-order triangles): order-Q edge and face nodes on the reference geometry, certified valid.
//
// Edge nodes: the straight edge's equispaced points projected onto the reference (onto the
// feature curve for curve edges). Face nodes: the flat lattice point plus the blended
// displacement of the edges (so interior nodes follow curved edges), then projected. A triangle
// is valid when its Jacobian relative to its flat triangle, J = det of the curved map's
// derivative expressed in the flat triangle's plane frame, is positive everywhere: certified by
// the Bezier test of validity.h on the nodes written in that frame. Invalid triangles (and those
// below the scaled-Jacobian floor, when one is asked for) are straightened step by step: their non-vertex nodes are moved toward the flat positions (to
// 0.75, 0.5, 0.25, 0 of their displacement), face and smooth-edge nodes first, feature-curve edge
// nodes only if that is not enough; an edge's nodes are shared, so the neighbours across the
// moved edges are certified again (and straightened in turn if they broke).
#pragma once

#include <cstddef>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/geometry/tri_surface.h"
#include "modules/elements/validity.h"
#include "surface3d/discrete_reference.h"

namespace plaf {

struct CurvingReport {
  std::size_t triangles = 0;
  std::size_t invalid = 0;       // still invalid after straightening (the run fails)
  std::size_t straightened = 0;  // triangles whose nodes were pulled back to become valid (or
                                 // to reach the scaled-Jacobian floor)
  double min_scaled_jacobian = 0;
};

// Sets s.order = order and fills edge_nodes / face_nodes (order 1 clears them; every triangle is
// still certified). Curve edges (edge_curve >= 0) project onto reference.project_to_curve; a curve
// number the reference does not have throws MesherError. min_scaled_jacobian is the smallest
// certified lower bound of min det J / max det J over the final triangles.
// Triangles below min_scaled_jacobian (valid or not) are straightened like invalid ones, until
// they reach it (a flat triangle has 1).
CurvingReport curve_surface(TriSurface& s, const ReferenceGeometry<3>& reference, int order,
                            const ValidityOptions& validity = {}, double min_scaled_jacobian = 0);

// certify_surface_triangle(certifier, order, nodes) (validity.h, included here) certifies one
// curved surface triangle (nodes in Gmsh order) relative to its flat triangle; it lives in core so
// that assess_quality certifies surface meshes read back from files the same way.

// Area of the curved surface, by Gauss quadrature of |x_u x x_v| on every triangle (a collapsed
// 8 x 8 Gauss-Legendre rule on the square: exact for polynomials of degree 14).
double surface_area(const TriSurface& s);

// The surface as a HybridMesh<3> without volume cells: one boundary triangle block of order Q
// per face tag, and one line block (HybridMesh::curves) per edge tag (e.g. the symmetry loop),
// with the tags of s (same indices). Nodes are shared: the vertices, then the interior nodes of
// each edge, then of each face, so the mesh is conforming. Curve lines run along their face's
// boundary half-edge. Throws MesherError for a face or edge tag outside s.tags.
HybridMesh<3> surface_to_mesh(const TriSurface& s);

}  // namespace plaf
