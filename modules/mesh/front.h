// SPDX-License-Identifier: MIT
// Fronts: what crosses from one stage to the next in 2D. A CurvedFront is the surface mesh the
// layers grow from (order-Q curved segments); its outermost layer becomes a LinearFront for the
// fill.
//
// Conventions: loops keep the geometry's orientation (domain on the left: bodies clockwise,
// farfield counter-clockwise). Element e of a loop has order+1 node ids in Gmsh line order
// (start, end, then interior nodes from start to end); element e's end is element e+1's start,
// and the last element ends at the first element's start.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace mesh {

struct FrontLoop {
  std::string tag;
  BoundaryKind kind = BoundaryKind::Wall;
  int geometry_loop = -1;              // index into Geometry2D::loops, -1 if none
  std::vector<NodeId> elements;        // (order + 1) ids per element
  std::vector<std::uint8_t> corner;    // per element: its start node is a geometric corner
  std::size_t size() const { return corner.size(); }
};

template <int Dim>
struct CurvedFront;

template <>
struct CurvedFront<2> {
  int order = 1;
  std::vector<Eigen::Vector2d> nodes;
  std::vector<double> params;  // spline parameter of each node on its geometry loop
  std::vector<FrontLoop> loops;

  const NodeId* element(const FrontLoop& l, std::size_t e) const {
    return l.elements.data() + e * static_cast<std::size_t>(order + 1);
  }
};

// The front as a mesh of boundary lines only (order Q, one boundary block per tag), for output.
HybridMesh<2> front_mesh(const CurvedFront<2>& front);

}  // namespace mesh
}  // namespace plaf
