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

// The least angle, on the fill's side, between two faces of a new front along their common edge
// (a fold; the fill's tetrahedra at that edge can have no dihedral angle above it), and the
// least distance to 180 degrees of a face's largest angle (a cap). The ONERA M6's
// layers at their metric's count (configs/onera_m6_hybrid.yaml, 60 layers) folded to 1.5 degrees
// where the trailing edge meets the rounded tip, and TetGen's least dihedral there was 0.0005.
inline constexpr double kFoldMinDeg = 10;

// The angle in degrees between the faces (a, b, c) and (b, a, d) along their edge (a, b), on the
// side their right-hand normals point to (the domain's, curved_front.h): 180 for a flat pair,
// below it where they fold toward that side, above where they fold away.
double fill_side_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                           const Eigen::Vector3d& d);

// The largest angle in degrees of the triangle of nodes t (180 for a degenerate one).
double largest_angle_deg(const std::array<int, 3>& t, const std::vector<Eigen::Vector3d>& nodes);

// The faces of fronts[0] (by index) that
//  - crossings: have a sub-triangle that crosses a sub-triangle of any of the fronts (fronts[0]
//    itself included) with which it shares no mesh node, or only one and they cross beyond it (a
//    fold around the node), or (order > 1) whose chord (its vertices' triangle, what the fill
//    meets) so crosses another face's chord;
//  - folds: have a sub-triangle (or chord) that meets another of fronts[0] along a common edge at
//    a fill_side_angle_deg under kFoldMinDeg;
//  - caps (with `base_ids` only): have a chord (the face at order 1) whose largest angle is
//    within kFoldMinDeg of 180 (a tetrahedron on a cap has a dihedral angle near 0: on the M6's
//    60 layers a chord of 179.9 degrees at the tip gave TetGen's fill one of 0.015).
// With `base_ids` (fronts[0]'s nodes before the layer, by the same local ids: the layer kept the
// front's topology), a fold or cap counts only where the layer took the measure (the angle, the
// distance to 180 degrees) across its limit or halved it, from the same pair's or chord's on the
// base: a wall's own crevices and caps (a metric's stretched triangles are caps of up to 177
// degrees at the E387 wing's leading edge), which the layers carry out a little sharper or
// blunter, are not the layer's. Without it (a first layer whose fans changed the faces) caps are
// not judged. Sorted, unique. With `unmoved` (per face of
// fronts[0]: 1 when the layer left it where it was, every column under it stopped), a pair (or
// a cap) of which nothing moved is not a collision of this layer (the other fronts do not
// move either): it was there before, on the wall (the surface stage's to refuse) or not at all
// (an accepted front has none).
std::vector<std::size_t> front_collisions(const std::vector<FrontSurface>& fronts,
                                          const std::vector<Eigen::Vector3d>& nodes, int order,
                                          const std::vector<std::uint8_t>* unmoved = nullptr,
                                          const std::vector<NodeId>* base_ids = nullptr);

}  // namespace plaf::layers
