// SPDX-License-Identifier: MIT
// How far the final surface mesh is from the body it meshes (issue 13): the two-sided (Hausdorff)
// distance between the order-Q surface and the reference, each side sampled:
//  - mesh -> reference: every curved triangle at the points of its 2Q-sub-lattice (Q = 1: 2),
//    interior included, projected onto the reference (reference.h): the largest |x - project(x)|;
//  - reference -> mesh: points of the body, from the input triangulation: a surface file's own
//    vertices, edge midpoints and face centroids (it is the body), or the points of an analytic
//    body's initial triangulation on its triangles' 8-sub-lattice projected onto it; each sample's
//    closest point on the mesh is found on the Q-sub-lattice's flat sub-triangles (an AABB tree)
//    and refined on the curved triangle (Gauss-Newton kept inside it): the largest distance.
// The Hausdorff distance is the larger of the two; relative is it over the reference samples'
// bounding-box diagonal. A notch cut into a trailing edge shows on the reference -> mesh side;
// a bulge or fold on the mesh -> reference side.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"

namespace plaf {

struct FidelityReport {
  double to_reference = 0;                            // mesh -> reference
  Eigen::Vector3d worst_on_mesh = Eigen::Vector3d::Zero();
  double to_mesh = 0;                                 // reference -> mesh
  Eigen::Vector3d worst_on_reference = Eigen::Vector3d::Zero();
  double hausdorff = 0, diagonal = 0, relative = 0;
  Eigen::Vector3d worst = Eigen::Vector3d::Zero();    // the point of the larger side
  std::size_t mesh_samples = 0, reference_samples = 0;
};

// Points on the reference from a triangulation of it (see above); input_is_reference: the input
// is the body itself (a surface file), so its points are taken as they are.
std::vector<Eigen::Vector3d> reference_samples(const TriSurface& input, const ReferenceGeometry<3>& reference,
                                               bool input_is_reference);

// The fidelity of `surface` (its high-order nodes set, or straight) to the reference.
FidelityReport measure_fidelity(const TriSurface& surface, const ReferenceGeometry<3>& reference,
                                const std::vector<Eigen::Vector3d>& samples);

}  // namespace plaf
