// SPDX-License-Identifier: MIT
// The smooth reference geometry (modules/geometry/reference.h) of a triangulated surface: a curved
// surface through its vertices, so that high-order nodes and the layers' normals follow the body
// the triangulation samples instead of its flat facets. Implements the weighted averaging of local
// fittings (WALF) of X. Jiao and D. Wang, *Reconstructing high-order surfaces for meshing*,
// Engineering with Computers 28, 2012, with feature curves kept sharp.
//
// - Local fits: at every vertex, one fit per side of the feature edges around it (a sector of its
//   fan; a vertex off the features has one). A fit is a height function over the tangent plane,
//   w(u, v) = sum of the monomials u^a v^b, 1 <= a + b <= 3 (cubic, 9 coefficients; quadratic or
//   tangent plane where the points are too few or the system is rank deficient), least squares on
//   the two-ring on that side (three-ring where it has fewer than 14 points), through the vertex
//   itself; the plane is fitted again at the first fit's normal. The fit's normal at the vertex is
//   the vertex normal of that side: O(h^3) accurate instead of the O(h) of averaged face normals.
// - Patches: a point with barycentric coordinates b of face (v0, v1, v2) is the blend
//   sum b_i Q_i(p), p = sum b_i v_i, where Q_i lifts p onto v_i's fit of that face's side (Jiao
//   and Wang's Eq. (5)). The faces on both sides of a smooth edge share both end fits, so the
//   surface is continuous (G0) and its normal jumps across edges only by O(h^3).
// - Feature curves: each curve (TriSurface::edge_curve) is the cubic Hermite curve through its
//   polyline's vertices. Its unit tangent at a vertex is the intersection of the two sides' fitted
//   tangent planes there (where they meet at more than ~6 degrees; else, or on a boundary, the
//   tangent of the parabola through the vertex and its neighbours along the curve, one-sided at a
//   corner or end), its derivatives' length that of the circular arc with those end tangents. A
//   face with a feature edge (i, j) opposite corner k adds the edge's defect
//   (1 - b_k) (c(t) - (1 - t) Q_i - t Q_j), t = b_j / (b_i + b_j), which is the curve on the edge
//   and vanishes on the face's other edges: both sides of a ridge meet on the curve (sharp, G0),
//   each side fitted on its own. A feature edge without a curve id is a one-segment curve.
// - Projection: the closest flat facet (TriangleTree) gives the start; Gauss-Newton on the
//   barycentric coordinates (damped; across an edge into the next patch at most 6 times, never
//   straight back, else along the edge) converges to the closest patch point. normal(x) is the patch's
//   unit normal there, oriented like the facet's (outward, tri_surface.h). A degenerate facet
//   (a needle or sliver of angle < 1e-10) is its own patch, flat; a patch normal turned against
//   its facet falls back to the facet's normal. Nothing mutable: thread-safe.
//
// Why WALF (measured in tests/surface3d/smooth_reference_test.cpp: points inside every face
// projected, their distance and normal angle to the exact body, max over the samples, at h, h/2,
// h/4; orders from the last halving):
//   body                     facets: distance, normal order    smooth: distance, normal order
//   sphere (icosphere)       2.0, 1.8                          3.8, 3.0   (h/4: 5.7e-6 vs 1.1e-3)
//   ellipsoid (1.5, 1.2, 1)  1.9, 1.1                          3.7, 2.7   (h/4: 3.4e-5 vs 2.6e-3)
//   NACA 0012 wing, flat ends 2.0, 1.2                         3.0, 1.9   (h/4: 3.5e-5 vs 1.5e-4)
// (the wing's orders are limited by its ridges: the patches beside a curve follow its Hermite
// interpolation.) On the published ellipsoid STL remeshed at h = 0.2, the order-3 surface's nodes
// are within 4.3e-6 of the true ellipsoid instead of 9.3e-4 on the facets. Quadratic Nagata or
// cubic PN patches built from vertex normals alone reach distance order 3 at best, and their
// normals are only as good as the vertex normals; the local cubic fits give the vertex normals
// and the surface from the same data and degrade gracefully (quadratic, then Phong's planes).
#pragma once

#include <memory>

#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"

namespace plaf {

// The smooth reference of `input`, whose features must be detected (features.h; the edge_feature,
// edge_curve and vertex_feature properties). The arrays it needs are copied. Throws MesherError
// for a surface without faces.
std::unique_ptr<ReferenceGeometry<3>> make_smooth_reference(const TriSurface& input);

// Whether r was made by make_smooth_reference (the surface stage rebuilds the reference its
// geometry stage chose after detecting features again).
bool is_smooth_reference(const ReferenceGeometry<3>& r);

}  // namespace plaf
