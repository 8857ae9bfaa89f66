// SPDX-License-Identifier: MIT
// High-order surface triangles (paper Sec. II.E: the initial front is a surface mesh of
// high-order triangles): order-Q edge and face nodes on the reference geometry, certified valid.
//
// Edge nodes: the straight edge's equispaced points projected onto the reference (onto the
// feature curve for curve edges). Face nodes: the flat lattice point plus the blended
// displacement of the edges (so interior nodes follow curved edges), then projected. A triangle
// is valid when its Jacobian relative to its flat triangle, J = det of the curved map's
// derivative expressed in the flat triangle's plane frame, is positive everywhere: certified by
// the Bezier test of validity.h on the nodes written in that frame. Invalid triangles are
// straightened step by step (their non-feature nodes moved toward the flat positions) and
// reported.
#pragma once

#include <cstddef>

#include "modules/hybrid_mesh.h"
#include "modules/tri_surface.h"
#include "modules/validity.h"
#include "surface3d/reference.h"

namespace plaf {

struct CurvingReport {
  std::size_t triangles = 0;
  std::size_t invalid = 0;       // still invalid after straightening (the run fails)
  std::size_t straightened = 0;  // triangles whose nodes were pulled back to become valid
  double min_scaled_jacobian = 0;
};

// Sets s.order = order and fills edge_nodes / face_nodes.
CurvingReport curve_surface(TriSurface& s, const ReferenceGeometry& reference, int order,
                            const ValidityOptions& validity = {});

// The certified bounds of one curved surface triangle (nodes in Gmsh order), relative to its
// flat triangle.
JacobianBounds certify_surface_triangle(JacobianCertifier& certifier, int order, const Eigen::Vector3d* nodes);

// Area of the curved surface, by Gauss quadrature of |x_u x x_v| on every triangle.
double surface_area(const TriSurface& s);

// The surface as a HybridMesh<3> without volume cells: one boundary triangle block of order Q
// per face tag, and one line block (HybridMesh::curves) per edge tag (e.g. the symmetry loop).
HybridMesh<3> surface_to_mesh(const TriSurface& s);

}  // namespace plaf
