// SPDX-License-Identifier: MIT
// The farfield of a 3D run (issue 15): a sphere or an axis-aligned box around the bodies, as
// linear triangles whose right-hand normals point inward (into the region to fill,
// linear_front.h). The sphere is an icosahedron whose faces are split into n^2 triangles (every
// edge at most h) and pushed onto the sphere; the box's faces are grids of n_a x n_b cells of
// sides at most h, two triangles each (their diagonals up to sqrt 2 h), sharing the nodes of
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
  // Symmetry planes x[axis] = offset (box only): the box's face on each is left out (the plane's
  // own triangles close the domain there) and the box is cut to the bodies' side of it.
  struct Cut {
    int axis = 0;
    double offset = 0;
    int side = 1;  // +1: the bodies lie at x[axis] > offset
  };
  std::vector<Cut> cuts;
};

struct FarfieldMesh3 {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<int, 3>> triangles;  // normals inward
  // Per cut (FarfieldParams3::cuts, same order): the node ids around the left-out face, in order.
  std::vector<std::vector<int>> cut_loops;
};

// The farfield surface for bodies in [lo, hi] (params' zeros resolved against them; h > 0
// required). Throws ConfigError naming fill.farfield.* when it does not enclose the bodies (the
// sphere's inscribed polyhedron by 5 % of its inradius, the box by 5 % of its half sizes), or for
// a non-positive h.
FarfieldMesh3 make_farfield(const FarfieldParams3& params, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// The resolved centre and extent (the radius, or the box's half sizes) of a farfield.
Eigen::Vector3d farfield_center(const FarfieldParams3& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

}  // namespace plaf::volume
