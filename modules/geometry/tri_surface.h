// SPDX-License-Identifier: MIT
// The 3D surface type: an OpenMesh half-edge triangle mesh with Eigen points, carrying plaf's
// tags, features and high-order nodes as OpenMesh properties. It is what the surface3d stage
// produces (read, validated, remeshed, curved) and what the 3D layers will grow from.
//
// Conventions (written once, here):
// - Points are Eigen::Vector3d. Faces are counter-clockwise seen from outside: their normals
//   point out of the body, into the domain.
// - A face's vertices (v0, v1, v2) are face_vertices(): from_vertex(h), to_vertex(h),
//   to_vertex(next(h)) with h = halfedge_handle(f). High-order nodes follow Gmsh's triangle order
//   on (v0, v1, v2) (lagrange.h).
// - Edge e's interior nodes (order - 1 of them) run from from_vertex(halfedge_handle(e, 0)) to its
//   to_vertex; a face whose halfedge on that edge is halfedge 1 reads them reversed.
// - Face interior nodes ((order - 1)(order - 2) / 2 of them) are in Gmsh order relative to
//   (v0, v1, v2): the nodes from index 3 order on of the triangle's Gmsh node list.
// - Features: an edge is a ridge when the dihedral angle between its faces departs from flat by
//   more than a threshold (features.h); boundary edges (open loops, allowed only on symmetry
//   planes) are features too. Chains of feature edges between corners are feature curves, numbered
//   0.. in edge_curve; the reference geometry (surface3d/discrete_reference.h) projects onto curve c.
//   Corners are vertices where the curves end or meet, or with a large angle defect.
#pragma once

// OpenMesh's vector_traits must be declared before EigenVectorT.hh specialises it for Eigen.
// clang-format off
#include <OpenMesh/Core/Utils/vector_traits.hh>
#include <OpenMesh/Core/Geometry/EigenVectorT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
// clang-format on

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace geometry {

struct TriMeshTraits : public OpenMesh::DefaultTraits {
  using Point = Eigen::Vector3d;
  using Normal = Eigen::Vector3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge | OpenMesh::Attributes::Status);
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<TriMeshTraits>;

// What a reader returns: points and triangles with no topology checked yet.
struct TriangleSoup {
  std::string source;                        // file name (or body name), for messages
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;  // indices into points
  std::vector<int> patch;                     // per triangle, e.g. the Plot3D block; empty: none
  std::vector<std::string> repairs;           // what the reader mended (validation reports them with its own)
};

enum class EdgeFeature : std::uint8_t { Smooth = 0, ConvexRidge, ConcaveRidge, Boundary };
enum class VertexFeature : std::uint8_t {
  Smooth = 0,     // not on a feature curve
  Curve,          // inside a feature curve (two feature edges continuing each other)
  ConvexCorner,   // a corner where all ridges are convex (box corner) or a convex cone point
  ConcaveCorner,  // all ridges concave, or a concave cone point
  SaddleCorner,   // mixed convex and concave ridges
  BoundaryCorner  // where a boundary (symmetry) curve meets a ridge, or a boundary corner
};
const char* edge_feature_name(EdgeFeature f);
const char* vertex_feature_name(VertexFeature f);
inline bool is_corner(VertexFeature f) { return f >= VertexFeature::ConvexCorner; }

class TriSurface {
 public:
  TriSurface();
  TriSurface(const TriSurface&) = default;
  TriSurface& operator=(const TriSurface&) = default;
  TriSurface(TriSurface&&) = default;
  TriSurface& operator=(TriSurface&&) = default;

  TriMesh mesh;
  int order = 1;                   // geometry order of the high-order nodes (1: none)
  std::vector<BoundaryTag> tags;   // face tags (walls) and edge tags (symmetry)

  OpenMesh::FPropHandleT<int> face_tag;                 // index into tags
  OpenMesh::EPropHandleT<int> edge_tag;                 // boundary edges: index into tags; else -1
  OpenMesh::EPropHandleT<EdgeFeature> edge_feature;     // default Smooth
  OpenMesh::EPropHandleT<int> edge_curve;               // feature curve id, -1 if none
  OpenMesh::VPropHandleT<VertexFeature> vertex_feature;  // default Smooth
  OpenMesh::EPropHandleT<std::vector<Eigen::Vector3d>> edge_nodes;  // order - 1 interior nodes
  OpenMesh::FPropHandleT<std::vector<Eigen::Vector3d>> face_nodes;  // face interior nodes

  int add_tag(const std::string& name, BoundaryKind kind);  // existing index if the name is known

  // (v0, v1, v2) of face f (see the conventions above).
  std::array<TriMesh::VertexHandle, 3> face_vertices(TriMesh::FaceHandle f) const;
  // The num_nodes(Triangle, order) nodes of face f in Gmsh order (vertices, edge nodes, face
  // nodes); straight (order 1) if the high-order nodes are not set.
  std::vector<Eigen::Vector3d> triangle_nodes(TriMesh::FaceHandle f) const;
  // Number of feature curves (1 + the largest edge_curve).
  int num_curves() const;
  // Euler characteristic V - E + F of the (garbage-collected) mesh.
  long euler_characteristic() const;
};

// The triangles of a soup as a TriSurface (all faces tag 0 "wall"), no checks (validate.h
// checks); throws MesherError if OpenMesh refuses a face (non-manifold input).
TriSurface surface_from_soup(const TriangleSoup& soup);
// The vertices and faces of a surface as a soup (deleted elements skipped, vertices renumbered).
TriangleSoup soup_from_surface(const TriSurface& s);

}  // namespace geometry
}  // namespace plaf
