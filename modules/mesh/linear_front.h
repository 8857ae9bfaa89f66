// SPDX-License-Identifier: MIT
// LinearFront<Dim>: the straight-sided boundary of the region left to fill; what crosses from the
// layer stage (layers/) to the fill stage (volume/): PLAF Sec. II.C in 2D, the TetGen volume in
// 3D. The fill meshes the region between its loops (2D) or surfaces (3D) with linear cells.
//
// Node-numbering contract:
// - `nodes` are the nodes of the mesh the front was taken from (the layer stage's HybridMesh),
//   with the same ids; a front node id is a mesh node id. Nodes no loop or facet uses are allowed
//   and left alone.
// - A fill returns these nodes first, unchanged and with the same ids, then the nodes it adds, so
//   its cells join the layer mesh without renumbering.
// Orientation: 2D loops have the region to fill on their left (bodies clockwise, the farfield
// counter-clockwise); 3D triangles have their right-hand normal pointing into the region to fill.
// Loops (2D) must be simple and must not touch; the 3D triangles must form closed, non-crossing
// surfaces.
// Holes: for fills that need them (TetGen, 3D), a point strictly inside every body (a region not
// to fill). The 2D layers leave them empty: the advancing front tells the sides by orientation.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace mesh {

// One closed loop of the 2D front: its vertex ids in order.
struct LinearLoop {
  std::string tag;
  BoundaryKind kind = BoundaryKind::Wall;
  bool layered = false;  // the outer front of grown layers (else a loop of the surface mesh itself)
  int source_loop = -1;  // index of the CurvedFront<2> loop it bounds or grew from
  std::vector<NodeId> nodes;
};

template <int Dim>
struct LinearFront;

template <>
struct LinearFront<2> {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<LinearLoop> loops;
  std::vector<Eigen::Vector2d> holes;
};

template <>
struct LinearFront<3> {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<NodeId, 3>> triangles;  // normal into the region to fill
  std::vector<int> triangle_tag;                 // per triangle: index into tags
  std::vector<BoundaryTag> tags;
  std::vector<Eigen::Vector3d> holes;
};

// What a fill returns (the contract above): front.nodes first, same ids, then the new nodes; its
// linear simplices (2D counter-clockwise triangles, 3D tetrahedra of positive volume).
// A fill may also close the domain with boundary facets of its own (3D: the farfield surface the
// TetGen plugin adds): linear, on `nodes`, each with a tag of its own `tags` (2D: none).
template <int Dim>
struct FillResult {
  std::vector<Eigen::Matrix<double, Dim, 1>> nodes;
  std::vector<std::array<NodeId, Dim + 1>> simplices;
  std::vector<std::array<NodeId, Dim>> boundary;
  std::vector<int> boundary_tag;  // per boundary facet: index into tags
  std::vector<BoundaryTag> tags;
};

}  // namespace mesh
}  // namespace plaf
