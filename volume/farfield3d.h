// SPDX-License-Identifier: MIT
// The farfield of a 3D run (issue 15): a sphere or an axis-aligned box around the bodies, as
// linear triangles whose right-hand normals point inward (into the region to fill,
// linear_front.h), every edge at most `size` long. The sphere is an icosahedron whose faces are
// split into n^2 triangles (n the smallest that keeps the edges under size) and pushed onto the
// sphere; the box's faces are grids of n_a x n_b cells, two triangles each, sharing the nodes of
// their common edges.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plaf::volume {

struct FarfieldParams3 {
  std::string shape = "sphere";     // sphere | box
  double radius = 0;                 // sphere; 0: 10 x the bodies' bounding-box diagonal
  std::array<double, 3> size = {0, 0, 0};  // box edge lengths; 0: 20 x the bodies' diagonal
  bool has_center = false;           // else the bodies' bounding-box centre
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double h = 0;                      // largest edge; 0: from the metric at the farfield (plugin)
};

struct FarfieldMesh3 {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<int, 3>> triangles;  // normals inward
};

// The farfield surface for bodies in [lo, hi] (params' zeros resolved against them; h > 0
// required). Throws ConfigError naming fill.farfield.* when it does not enclose the bodies (the
// sphere's inscribed polyhedron by 5 % of its inradius, the box by 5 % of its half sizes), or for
// a non-positive h.
FarfieldMesh3 make_farfield(const FarfieldParams3& params, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// The resolved centre and extent (the radius, or the box's half sizes) of a farfield.
Eigen::Vector3d farfield_center(const FarfieldParams3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

}  // namespace plaf::volume
