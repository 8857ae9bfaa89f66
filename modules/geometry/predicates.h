// SPDX-License-Identifier: MIT
// Exact orientation predicates (orient2d, orient3d) and the exact segment and triangle intersection
// tests built on them. Implements the adaptive idea of J. R. Shewchuk, "Adaptive Precision
// Floating-Point Arithmetic and Fast Robust Geometric Predicates", Discrete Comput. Geom. 18, 1997:
// a double evaluation with a rigorous forward error bound, and, only when the result is within the
// bound, an exact evaluation with floating-point expansions (error-free two_sum, and two_product
// through std::fma as in Ogita, Rump and Oishi, "Accurate Sum and Dot Product", SIAM J. Sci.
// Comput. 26, 2005).
//
// Conventions (written once, here):
//   orient2d(a, b, c) = det [[bx - ax, by - ay], [cx - ax, cy - ay]]
//                     = twice the signed area of triangle abc;
//     > 0 iff a, b, c are counter-clockwise, < 0 iff clockwise, 0 iff collinear.
//   orient3d(a, b, c, d) = det [[a - d], [b - d], [c - d]]   (rows)
//                        = -det [[b - a], [c - a], [d - a]] = -6 * signed volume of tet abcd;
//     > 0 iff d lies below the plane of a, b, c, where "below" means a, b, c appear
//     counter-clockwise seen from above (Shewchuk's convention); 0 iff the four points are
//     coplanar. Hence a tetrahedron (a, b, c, d) has positive volume in the right-handed sense of
//     hybrid_mesh.h (det [b - a, c - a, d - a] > 0) iff orient3d(a, b, c, d) < 0.
//
// Exactness: the SIGN of orient2d/orient3d is the sign of the exact determinant of the given
// doubles. The magnitude is an approximation (relative error about 1e-15, clamped to the double
// range). This holds for every finite input whose nonzero coordinates are all at least 2^-480
// (orient2d) or 2^-300 (orient3d) times the largest coordinate magnitude of the call; no mesh
// comes near that dynamic range, and there is no overflow or underflow limit otherwise (the exact
// stage rescales by a power of two). Non-finite inputs give NaN (sign 0).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace plaf {
inline namespace geometry {

double orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);
double orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d);

// -1, 0 or +1: the exact sign of orient2d/orient3d.
int sign_orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);
int sign_orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d);
// True iff the tetrahedron (a, b, c, d) has positive volume in hybrid_mesh.h's sense
// (det [b - a, c - a, d - a] > 0), exactly: orient3d(a, b, c, d) < 0.
inline bool positive_tet(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
  return sign_orient3d(a, b, c, d) < 0;
}

// Segments ab and cd cross at exactly one point interior to both: no endpoint lies on the other
// segment (or its line) and the segments are not collinear. A degenerate segment never crosses.
bool segments_cross_properly(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                             const Eigen::Vector2d& d);
// The closed segments ab and cd share at least one point: proper crossing, an endpoint touching
// the other segment, shared endpoints, or collinear overlap. Degenerate segments (a == b) are
// points and are handled exactly.
bool segments_intersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                        const Eigen::Vector2d& d);
// p lies on segment ab strictly between a and b (false when a == b).
bool point_on_open_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// x inside the closed polygon (vertices in order, the last joined to the first), by the even-odd
// rule (floating point: a point on an edge may go either way).
bool inside_polygon(const Eigen::Vector2d& x, const std::vector<Eigen::Vector2d>& polygon);

// The closed triangles t1[0..2] and t2[0..2] in 3D share at least one point. Touching counts: a
// shared vertex, a vertex on the other triangle, edges meeting, coplanar overlap or containment.
// Exact (orient3d, and orient2d on an exactly chosen coordinate projection for coplanar parts).
// Degenerate triangles (collinear or coincident vertices) are handled as the segment or point
// they are.
bool triangles_intersect(const Eigen::Vector3d* t1, const Eigen::Vector3d* t2);

}  // namespace geometry
}  // namespace plaf
