// SPDX-License-Identifier: MIT
#include "modules/geometry/tri_surface.h"

#include <algorithm>

#include "modules/base/error.h"
#include "modules/elements/lagrange.h"

namespace plaf {
inline namespace geometry {

const char* edge_feature_name(EdgeFeature f) {
  switch (f) {
    case EdgeFeature::Smooth: return "smooth";
    case EdgeFeature::ConvexRidge: return "convex_ridge";
    case EdgeFeature::ConcaveRidge: return "concave_ridge";
    case EdgeFeature::Boundary: return "boundary";
  }
  return "?";
}

const char* vertex_feature_name(VertexFeature f) {
  switch (f) {
    case VertexFeature::Smooth: return "smooth";
    case VertexFeature::Curve: return "curve";
    case VertexFeature::ConvexCorner: return "convex_corner";
    case VertexFeature::ConcaveCorner: return "concave_corner";
    case VertexFeature::SaddleCorner: return "saddle_corner";
    case VertexFeature::BoundaryCorner: return "boundary_corner";
  }
  return "?";
}

TriSurface::TriSurface() {
  mesh.add_property(face_tag, "plaf:face_tag");
  mesh.add_property(edge_tag, "plaf:edge_tag");
  mesh.add_property(edge_feature, "plaf:edge_feature");
  mesh.add_property(edge_curve, "plaf:edge_curve");
  mesh.add_property(vertex_feature, "plaf:vertex_feature");
  mesh.add_property(edge_nodes, "plaf:edge_nodes");
  mesh.add_property(face_nodes, "plaf:face_nodes");
  // Defaults for elements added later are set by whoever adds them; OpenMesh default-constructs
  // new property values (0 / Smooth / empty), so -1 defaults are written explicitly by
  // surface_from_soup and the stages.
}

int TriSurface::add_tag(const std::string& name, BoundaryKind kind) {
  for (std::size_t i = 0; i < tags.size(); ++i)
    if (tags[i].name == name) return static_cast<int>(i);
  tags.push_back({name, kind});
  return static_cast<int>(tags.size()) - 1;
}

std::array<TriMesh::VertexHandle, 3> TriSurface::face_vertices(TriMesh::FaceHandle f) const {
  const auto h = mesh.halfedge_handle(f);
  const auto n = mesh.next_halfedge_handle(h);
  return {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h), mesh.to_vertex_handle(n)};
}

std::vector<Eigen::Vector3d> TriSurface::triangle_nodes(TriMesh::FaceHandle f) const {
  const int q = order;
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<std::size_t>(num_nodes(CellType::Triangle, q)));
  const auto h0 = mesh.halfedge_handle(f);
  const std::array<TriMesh::HalfedgeHandle, 3> hs = {h0, mesh.next_halfedge_handle(h0),
                                                     mesh.next_halfedge_handle(mesh.next_halfedge_handle(h0))};
  for (const auto h : hs) out.push_back(mesh.point(mesh.from_vertex_handle(h)));
  if (q == 1) return out;
  bool curved = true;
  for (const auto h : hs) {
    const auto e = mesh.edge_handle(h);
    const std::vector<Eigen::Vector3d>& en = mesh.property(edge_nodes, e);
    const Eigen::Vector3d a = mesh.point(mesh.from_vertex_handle(h)), b = mesh.point(mesh.to_vertex_handle(h));
    if (static_cast<int>(en.size()) != q - 1) {
      curved = false;
      for (int k = 1; k < q; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / q));
      continue;
    }
    const bool forward = mesh.halfedge_handle(e, 0) == h;
    for (int k = 0; k < q - 1; ++k) out.push_back(en[static_cast<std::size_t>(forward ? k : q - 2 - k)]);
  }
  const std::vector<Eigen::Vector3d>& fn = mesh.property(face_nodes, f);
  const int n_face = num_nodes(CellType::Triangle, q) - 3 * q;
  if (curved && static_cast<int>(fn.size()) == n_face) {
    out.insert(out.end(), fn.begin(), fn.end());
  } else if (n_face > 0) {
    // Straight interior nodes: the order-q Lagrange lattice on the flat triangle.
    const LagrangeElement& el = lagrange_element(CellType::Triangle, q);
    for (int k = 3 * q; k < num_nodes(CellType::Triangle, q); ++k) {
      const std::array<double, 3> r = el.ref_node(k);
      const double u = r[0], v = r[1];
      out.push_back(out[0] * (1 - u - v) + out[1] * u + out[2] * v);
    }
  }
  return out;
}

int TriSurface::num_curves() const {
  int n = 0;
  for (const auto e : mesh.edges()) n = std::max(n, mesh.property(edge_curve, e) + 1);
  return n;
}

long TriSurface::euler_characteristic() const {
  long v = 0, e = 0, f = 0;
  for (const auto vh : mesh.vertices()) { (void)vh; ++v; }
  for (const auto eh : mesh.edges()) { (void)eh; ++e; }
  for (const auto fh : mesh.faces()) { (void)fh; ++f; }
  return v - e + f;
}

TriSurface surface_from_soup(const TriangleSoup& soup) {
  TriSurface s;
  s.add_tag("wall", BoundaryKind::Wall);
  std::vector<TriMesh::VertexHandle> vh;
  vh.reserve(soup.points.size());
  for (const Eigen::Vector3d& p : soup.points) vh.push_back(s.mesh.add_vertex(p));
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& tri = soup.triangles[t];
    const auto f = s.mesh.add_face(vh[static_cast<std::size_t>(tri[0])], vh[static_cast<std::size_t>(tri[1])],
                                   vh[static_cast<std::size_t>(tri[2])]);
    if (!f.is_valid())
      throw MesherError(soup.source + ": triangle " + std::to_string(t) + " (" + std::to_string(tri[0]) + ", " +
                        std::to_string(tri[1]) + ", " + std::to_string(tri[2]) +
                        ") cannot join the half-edge mesh (a non-manifold edge or vertex)");
    s.mesh.property(s.face_tag, f) = 0;
  }
  for (const auto e : s.mesh.edges()) {
    s.mesh.property(s.edge_tag, e) = -1;
    s.mesh.property(s.edge_curve, e) = -1;
  }
  return s;
}

TriangleSoup soup_from_surface(const TriSurface& s) {
  TriangleSoup soup;
  std::vector<int> index(s.mesh.n_vertices(), -1);
  for (const auto v : s.mesh.vertices()) {
    index[static_cast<std::size_t>(v.idx())] = static_cast<int>(soup.points.size());
    soup.points.push_back(s.mesh.point(v));
  }
  for (const auto f : s.mesh.faces()) {
    const auto fv = s.face_vertices(f);
    soup.triangles.push_back({index[static_cast<std::size_t>(fv[0].idx())], index[static_cast<std::size_t>(fv[1].idx())],
                              index[static_cast<std::size_t>(fv[2].idx())]});
  }
  return soup;
}

}  // namespace geometry
}  // namespace plaf
