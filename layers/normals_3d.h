// SPDX-License-Identifier: MIT
// The normal, height stretch and class of one node of a 3D front (PLAF Sec. II.E, issue 14 part
// 2), from the unit normals of the faces around it. Dimension-specific, shared by every 3D front
// node, vertex or high-order:
//  - the faces' normals are clustered (two faces belong to one side when their normals are within
//    the corner angle): one cluster is a smooth node, two a ridge, three or more a corner;
//  - a smooth node takes the weighted average (the 2D layers' panel average; with angle weights on
//    a triangulated extrusion it is exactly the 2D normal);
//  - a ridge or corner takes the normal that sees every face best: the direction maximising the
//    smallest cosine to the face normals (the centre of their smallest enclosing spherical cap;
//    the visibility cone of Kallinderis-Ward and Aubry-Loehner). A concave one (its neighbours lie
//    above the tangent plane) is stretched by 1 / that cosine, so the new node lies one height off
//    every face plane (the intersection of the offset planes at a 90-degree corner) -- the 3D form
//    of the 2D concave merge, with the same floor of 0.1 on the cosine.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plaf::layers {

enum class NodeClass : std::uint8_t { Smooth, ConvexRidge, ConcaveRidge, ConvexCorner, ConcaveCorner, SaddleCorner };
const char* node_class_name(NodeClass c);
inline bool is_concave(NodeClass c) { return c == NodeClass::ConcaveRidge || c == NodeClass::ConcaveCorner; }

struct NodeNormal {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  double stretch = 1;       // height factor (concave merges)
  double min_cosine = 1;    // smallest cosine between n and a face normal
  NodeClass kind = NodeClass::Smooth;
};

// The direction n maximising min_k n . f_k over unit vectors f (exact for up to a few dozen: the
// best of every single, pairwise-bisector and three-equal-angle candidate). Zero when no
// direction sees every f (they do not fit in an open hemisphere).
Eigen::Vector3d visibility_normal(const std::vector<Eigen::Vector3d>& f);

// The same maximiser also where the smallest cosine is not positive (at a cusp no direction sees
// every face): Aubry and Loehner's "most normal" direction, unit (zero only for no face).
Eigen::Vector3d most_normal(const std::vector<Eigen::Vector3d>& f);

// The node's normal from its faces' unit normals `faces` with weights, and the directions from
// the node to its neighbouring vertices (to tell convex from concave). corner_rad: the angle
// between face normals beyond which they belong to different sides. Throws MesherError when no
// direction sees every face (a cusp).
NodeNormal node_normal(const std::vector<Eigen::Vector3d>& faces, const std::vector<double>& weights,
                       const std::vector<Eigen::Vector3d>& to_neighbours, double corner_rad);

}  // namespace plaf::layers
