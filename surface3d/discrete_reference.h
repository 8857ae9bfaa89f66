// SPDX-License-Identifier: MIT
// The discrete reference geometry (modules/geometry/reference.h): an input surface itself, which
// new vertices and high-order nodes are projected onto (its closest point, AABB tree). Feature
// curves are numbered as in the mesh's edge_curve (tri_surface.h); projecting onto curve c keeps
// ridge and symmetry-loop vertices on their curve.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"

namespace plaf {

// The input surface itself as the reference (closest point via an AABB tree; normals from the
// closest face, blended with its neighbours' by the barycentric coordinates; curves from
// feature_curves(input) as polylines). input must have its features detected; it is copied.
std::unique_ptr<ReferenceGeometry<3>> make_discrete_reference(const TriSurface& input);

// The surface's vertex points by index and the diagonal of their bounding box (0 without
// vertices): what both references (this one and smooth_reference.h) start from.
std::vector<Eigen::Vector3d> vertex_points(const TriSurface& s, double& diagonal);

}  // namespace plaf
