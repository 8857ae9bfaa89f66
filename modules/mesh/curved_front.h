// SPDX-License-Identifier: MIT
// CurvedFront<Dim>: the order-Q surface mesh the layers grow from (PLAF Sec. II.B, II.E); what
// crosses from the surface-mesh stage (2D: modules/mesh/curve_mesh.h, 3D: surface3d/) to the
// layer stage. It carries the reference normal at every node, linear and high-order, so the layers
// never ask the geometry.
//
// Conventions:
// - normals[i] is the unit normal of the reference geometry at node i, pointing into the domain
//   (reference.h); at a corner (2D) or on a feature curve (3D) it is the normal of one side and
//   the layers classify the node themselves.
// - 2D: loops keep the geometry's orientation (domain on the left: bodies clockwise, farfield
//   counter-clockwise). Element e of a loop has order+1 node ids in Gmsh line order (start, end,
//   then interior nodes from start to end); element e's end is element e+1's start, and the last
//   element ends at the first element's start.
// - 3D: triangles of (Q+1)(Q+2)/2 node ids each in Gmsh triangle order, counter-clockwise seen
//   from the domain (their right-hand normal points into the domain, out of the body). A closed
//   body has no rim; a half body ends on symmetry planes along its rim: the edges used by one
//   triangle only, listed in rim_edges (Q+1 ids each in Gmsh line order, running as in their
//   triangle) with the tag of the plane they lie on (the layers keep those nodes on the plane).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/geometry/reference.h"
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
  std::vector<Eigen::Vector2d> normals;  // per node, into the domain
  std::vector<double> params;            // spline parameter of each node on its geometry loop
  std::vector<FrontLoop> loops;

  const NodeId* element(const FrontLoop& l, std::size_t e) const {
    return l.elements.data() + e * static_cast<std::size_t>(order + 1);
  }
};

template <>
struct CurvedFront<3> {
  int order = 1;
  std::vector<Eigen::Vector3d> nodes;
  std::vector<Eigen::Vector3d> normals;  // per node, into the domain
  std::vector<NodeId> triangles;         // (Q+1)(Q+2)/2 ids per triangle, Gmsh order
  std::vector<int> triangle_tag;         // per triangle: index into tags
  std::vector<BoundaryTag> tags;
  std::vector<NodeId> rim_edges;         // (Q+1) ids per open edge, on a symmetry plane
  std::vector<int> rim_tag;              // per rim edge: index into tags
  // Quadrilaterals ((Q+1)^2 ids each, Gmsh order, facing the domain like the triangles). Neither
  // the surface stage nor the layers (whose outer front is all triangles, grow_layers_3d.h) make
  // any; a consumer of a front given otherwise must handle or refuse them.
  std::vector<NodeId> quads;
  std::vector<int> quad_tag;

  std::size_t num_triangles() const { return triangle_tag.size(); }
  std::size_t num_quads() const { return quad_tag.size(); }
  const NodeId* triangle(std::size_t t) const {
    return triangles.data() + t * static_cast<std::size_t>((order + 1) * (order + 2) / 2);
  }
};

// The front as a mesh of boundary facets only (order Q, one boundary block per tag), for output.
HybridMesh<2> front_mesh(const CurvedFront<2>& front);

// The 3D front of a surface mesh (its triangle boundary blocks, all of one order; its curves
// blocks of kind Symmetry become the rim), with every node's normal from the reference. Throws
// MesherError when the blocks mix orders or a curve of the rim is not an open edge.
CurvedFront<3> surface_front(const HybridMesh<3>& surface, const ReferenceGeometry<3>& reference);

}  // namespace mesh
}  // namespace plaf
