// SPDX-License-Identifier: MIT
// The reference geometry a mesh lives on, in either dimension: surface nodes, high-order nodes
// and the layers' first normals come from it. It is what crosses from the geometry stage to the
// surface-mesh and layer stages, so it lives in core; the stages implement it.
//
// Implementations:
//   2D: Geometry2D (geometry2d.h), the spline loops; its curves are the loops.
//   3D: the analytic bodies (surface3d/analytic.h) project exactly; a discrete input surface
//       projects to its closest point (surface3d/discrete_reference.h). Its curves are the
//       feature curves numbered as in TriSurface's edge_curve (tri_surface.h).
//
// Conventions: normal(x) is the unit normal at surface point x pointing into the domain, away
// from the body (2D: the spline's left normal; 3D: outward from the body's volume).
#pragma once

#include <Eigen/Core>

namespace plaf {
inline namespace geometry {

// Its queries are called from several threads at once (through metric fields that measure
// distances to it, on the quality stage's worker threads): an implementation keeps no mutable
// state.
template <int Dim>
class ReferenceGeometry {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  virtual ~ReferenceGeometry() = default;
  // The closest point of the reference to p.
  virtual Vec project(const Vec& p) const = 0;
  // The unit normal into the domain at (near) reference point x.
  virtual Vec normal(const Vec& x) const = 0;
  // The closest point and the normal there, in one search where the reference can (the 3D
  // remesher's relaxation asks for both at every move).
  virtual Vec project(const Vec& p, Vec& normal_out) const {
    const Vec x = project(p);
    normal_out = normal(x);
    return x;
  }
  // The closest point of curve c (0 <= c < num_curves()) to p: 2D a loop, 3D a feature curve.
  virtual Vec project_to_curve(const Vec& p, int curve) const = 0;
  virtual int num_curves() const = 0;
  // A length for tolerances (the bounding-box diagonal).
  virtual double scale() const = 0;
  // Whether x lies within tol of one of the reference's corners that no feature curve reaches (a
  // cone point: a projectile's nose), which a mesh judged against the reference keeps as a
  // corner; false where the reference knows none.
  virtual bool is_cone_point(const Vec& /*x*/, double /*tol*/) const { return false; }
};

}  // namespace geometry
}  // namespace plaf
