// SPDX-License-Identifier: MIT
// The reference geometry a surface mesh lives on: new vertices and high-order nodes are projected
// onto it. Analytic bodies (analytic.h) project exactly; a discrete input surface projects to its
// closest point (the input mesh itself, AABB tree). Feature curves are numbered as in the mesh's
// edge_curve (tri_surface.h); projecting onto curve c keeps ridge and symmetry-loop vertices on
// their curve.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "modules/geometry/tri_surface.h"

namespace plaf {

class ReferenceGeometry {
 public:
  virtual ~ReferenceGeometry() = default;
  // The closest point of the surface to p.
  virtual Eigen::Vector3d project(const Eigen::Vector3d& p) const = 0;
  // The outward unit normal at (near) surface point x.
  virtual Eigen::Vector3d normal(const Eigen::Vector3d& x) const = 0;
  // The closest point and the outward normal there, in one search where the reference can (the
  // remesher's relaxation asks for both at every move).
  virtual Eigen::Vector3d project(const Eigen::Vector3d& p, Eigen::Vector3d& normal_out) const {
    const Eigen::Vector3d x = project(p);
    normal_out = normal(x);
    return x;
  }
  // The closest point of feature curve c (0 <= c < num_curves()) to p.
  virtual Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int curve) const = 0;
  virtual int num_curves() const = 0;
  // A length for tolerances (the bounding-box diagonal).
  virtual double scale() const = 0;
};

// The input surface itself as the reference (closest point via an AABB tree; normals from the
// closest face, blended with its neighbours' by the barycentric coordinates; curves from
// feature_curves(input) as polylines). input must have its features detected; it is copied.
std::unique_ptr<ReferenceGeometry> make_discrete_reference(const TriSurface& input);

}  // namespace plaf
