// SPDX-License-Identifier: MIT
// The collision test of a new 3D layer front (grow_layers_3d.h, step 5): the front's curved
// triangles as the linear sub-triangles of their node lattice, and their chords, tested exactly
// (predicates.h) on the candidate pairs of an AABB tree (aabb_tree.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf::layers {

// The linear sub-triangles of the order-q triangle's node lattice, as triangle node indices
// (Gmsh order), counter-clockwise like the triangle: q^2 of them.
std::vector<std::array<int, 3>> sub_triangles(int q);

// A front as triangles over local nodes: tri holds (Q+1)(Q+2)/2 local ids per triangle (Gmsh
// order), ids maps a local node to its mesh node.
struct FrontSurface {
  const std::vector<int>* tri;
  const std::vector<NodeId>* ids;
};

// The faces of fronts[0] (by index) with a sub-triangle that crosses a sub-triangle of any of the
// fronts (fronts[0] itself included) with which it shares no mesh node, or only one and they
// cross beyond it (a fold around the node), or (order > 1) whose
// chord (its vertices' triangle, what the fill meets) so crosses another face's chord. Sorted,
// unique. With `unmoved` (per face of fronts[0]: 1 when the layer left it where it was, every
// column under it stopped), a pair of which neither side moved is not a collision of this layer
// (the other fronts do not move either): it was there before, on the wall (the surface stage's
// to refuse) or not at all (an accepted front has none).
std::vector<std::size_t> front_collisions(const std::vector<FrontSurface>& fronts,
                                          const std::vector<Eigen::Vector3d>& nodes, int order,
                                          const std::vector<std::uint8_t>* unmoved = nullptr);

}  // namespace plaf::layers
