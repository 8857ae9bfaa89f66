// SPDX-License-Identifier: MIT
// MeshBuilder and the shared checks of the analytic bodies (see analytic_builder.h).
#include "surface3d/analytic_builder.h"

#include <cmath>
#include <sstream>

#include "modules/base/error.h"

namespace plaf::analytic_detail {

namespace {

// Initial meshes larger than this are refused: h is then surely a unit mistake.
constexpr double kMaxTriangles = 2e7;

}  // namespace

void check_h(const std::string& body, double h, double size) {
  if (!(h > 0) || !std::isfinite(h))
    throw ConfigError(body + ": the mesh size h must be positive and finite, got " + num(h));
  if (4 * (size / h) * (size / h) > kMaxTriangles)
    throw ConfigError(body + ": the mesh size h = " + num(h) + " is too small for a body of size " + num(size) +
                      " (more than " + num(kMaxTriangles) + " initial triangles)");
}

void MeshBuilder::add_quad(int a, int b, int c, int d) {
  if ((points_[a] - points_[c]).squaredNorm() <= (points_[b] - points_[d]).squaredNorm()) {
    add_triangle(a, b, c);
    add_triangle(a, c, d);
  } else {
    add_triangle(a, b, d);
    add_triangle(b, c, d);
  }
}

void MeshBuilder::end_patch(bool reverse) {
  for (auto t : patch_) {
    if (reverse) std::swap(t[1], t[2]);
    triangles_.push_back(t);
  }
  patch_.clear();
}

TriSurface MeshBuilder::build(const std::string& name) const {
  TriSurface s;
  const int wall = s.add_tag("wall", BoundaryKind::Wall);
  const int sym = symmetry_ ? s.add_tag("symmetry", BoundaryKind::Symmetry) : -1;
  std::vector<TriMesh::VertexHandle> vh;
  vh.reserve(points_.size());
  for (const Eigen::Vector3d& p : points_) vh.push_back(s.mesh.add_vertex(p));
  for (const auto& t : triangles_) {
    const auto f = s.mesh.add_face(vh[t[0]], vh[t[1]], vh[t[2]]);
    if (!f.is_valid())
      throw MesherError(name + ": initial triangulation is not manifold at triangle (" + std::to_string(t[0]) + ", " +
                        std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")");
    s.mesh.property(s.face_tag, f) = wall;
  }
  for (const auto e : s.mesh.edges()) {
    s.mesh.property(s.edge_tag, e) = -1;
    s.mesh.property(s.edge_curve, e) = -1;
    s.mesh.property(s.edge_feature, e) = EdgeFeature::Smooth;
  }
  for (const auto v : s.mesh.vertices()) s.mesh.property(s.vertex_feature, v) = VertexFeature::Smooth;
  for (const auto& [key, info] : features_) {
    const auto h = s.mesh.find_halfedge(vh[key.first], vh[key.second]);
    if (!h.is_valid())
      throw MesherError(name + ": feature edge (" + std::to_string(key.first) + ", " + std::to_string(key.second) +
                        ") is not an edge of the initial triangulation");
    const auto e = s.mesh.edge_handle(h);
    s.mesh.property(s.edge_curve, e) = info.first;
    s.mesh.property(s.edge_feature, e) = info.second;
    for (const auto v : {vh[key.first], vh[key.second]}) s.mesh.property(s.vertex_feature, v) = VertexFeature::Curve;
  }
  for (const auto& [v, f] : corners_) s.mesh.property(s.vertex_feature, vh[v]) = f;
  std::size_t open = 0;
  for (const auto e : s.mesh.edges()) {
    if (!s.mesh.is_boundary(e)) continue;
    if (s.mesh.property(s.edge_feature, e) != EdgeFeature::Boundary || sym < 0) ++open;
    s.mesh.property(s.edge_tag, e) = sym;
  }
  if (open > 0)
    throw MesherError(name + ": initial triangulation has " + std::to_string(open) +
                      " open edges that are not on a symmetry plane");
  return s;
}

}  // namespace plaf::analytic_detail
