// SPDX-License-Identifier: MIT
// Surface readers (see read_surface.h): the dispatch by extension, and the triangle-file path.
//
// Triangle files go through OpenMesh's readers into SoupImporter, an importer that only records
// points and polygons: OpenMesh's own mesh importer would refuse non-manifold faces one by one
// (with a log line each), and validation (validate.h) must see them to name them. OpenMesh's
// readers trust their input, though, so each format is scanned first (surface_file_scans.cpp),
// then OpenMesh reads it, then the soup is checked against the scan (counts, index ranges, finite
// points). OpenMesh does the reading (in float for STL and OFF coordinates, as its readers do);
// it also drops STL facets and OBJ faces with a repeated vertex, which validation would drop
// anyway. The Plot3D reader is in read_plot3d.cpp, point welding in cluster_points.cpp.
#include "surface3d/read_surface.h"

// MeshIO.hh registers OpenMesh's reader modules with the IOManager.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/IO/reader/OFFReader.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <sstream>
#include <string>
#include <vector>

#include "modules/base/coordinates.h"
#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/io/text_cursor.h"
#include "surface3d/read_surface_detail.h"
#include "surface3d/triangulate_polygon.h"

namespace plaf {
namespace {

namespace fs = std::filesystem;
using Vec3 = Eigen::Vector3d;
using read_detail::Expected;
using read_detail::fail;

// Turns OpenMesh's log streams off while it reads (its messages are replaced by ours).
class QuietOpenMesh {
 public:
  QuietOpenMesh() : err_(omerr().is_enabled()), log_(omlog().is_enabled()), out_(omout().is_enabled()) {
    omerr().disable();
    omlog().disable();
    omout().disable();
  }
  ~QuietOpenMesh() {
    if (err_) omerr().enable();
    if (log_) omlog().enable();
    if (out_) omout().enable();
  }
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  bool err_, log_, out_;
};

// Records points and polygons as the readers deliver them; everything else is ignored.
class SoupImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VertexHandle = OpenMesh::VertexHandle;
  using FaceHandle = OpenMesh::FaceHandle;
  using HalfedgeHandle = OpenMesh::HalfedgeHandle;
  using EdgeHandle = OpenMesh::EdgeHandle;
  using Vec2f = OpenMesh::Vec2f;
  using Vec3f = OpenMesh::Vec3f;
  using Vec3d = OpenMesh::Vec3d;
  using Vec4f = OpenMesh::Vec4f;
  using Vec3uc = OpenMesh::Vec3uc;
  using Vec4uc = OpenMesh::Vec4uc;
  using Status = OpenMesh::Attributes::StatusInfo;

  std::vector<Vec3> points;
  std::vector<std::vector<int>> faces;

  VertexHandle add_vertex(const Vec3f& p) override { return add(Vec3(p[0], p[1], p[2])); }
  VertexHandle add_vertex(const Vec3d& p) override { return add(Vec3(p[0], p[1], p[2])); }
  VertexHandle add_vertex() override { return add(Vec3::Zero()); }
  void set_point(VertexHandle v, const Vec3f& p) override {
    if (v.is_valid() && static_cast<std::size_t>(v.idx()) < points.size())
      points[static_cast<std::size_t>(v.idx())] = Vec3(p[0], p[1], p[2]);
  }
  FaceHandle add_face(const VHandles& vs) override {
    std::vector<int> f;
    f.reserve(vs.size());
    for (const VertexHandle& v : vs) f.push_back(v.idx());
    faces.push_back(std::move(f));
    return FaceHandle(static_cast<int>(faces.size() - 1));
  }
  std::size_t n_vertices() const override { return points.size(); }
  std::size_t n_faces() const override { return faces.size(); }
  std::size_t n_edges() const override { return 0; }

  // Half-edge level construction is used only by OpenMesh's own .om format, which is not read.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}

  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(VertexHandle, const Status&) override {}
  void set_status(HalfedgeHandle, const Status&) override {}
  void set_status(EdgeHandle, const Status&) override {}
  void set_status(FaceHandle, const Status&) override {}
  void request_face_texcoords2D() override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void add_texture_information(int, std::string) override {}
  // The readers' size hints come from the file's header; the scans have checked them, but
  // nothing is reserved from them anyway.
  void reserve(unsigned int, unsigned int, unsigned int) override {}

 private:
  VertexHandle add(const Vec3& p) {
    points.push_back(p);
    return VertexHandle(static_cast<int>(points.size() - 1));
  }
};

// Reads `text` (the contents of `path`) with OpenMesh's reader for `ext` and checks the result
// against the scan: counts, then indices and coordinates.
// A polygon's triangles, in its orientation: a fan from its first vertex where every fan
// triangle turns the polygon's way in its plane (convex polygons, and every triangle and quad as
// the files give them), else ear clipping in the polygon's plane (a concave polygon's fan would
// cross itself: an L-shaped face of an OBJ was 12 self-intersecting pairs, issue 37 item 7).
void triangulate_face(TriangleSoup& soup, const std::vector<int>& poly) {
  const std::size_t n = poly.size();
  auto fan = [&] {
    for (std::size_t k = 1; k + 1 < n; ++k) soup.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  };
  if (n == 3) return fan();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // Newell's: the polygon's area vector
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d& a = soup.points[static_cast<std::size_t>(poly[k])];
    const Eigen::Vector3d& b = soup.points[static_cast<std::size_t>(poly[(k + 1) % n])];
    normal += a.cross(b);
  }
  if (!(normal.norm() > 0)) return fan();
  const Eigen::Vector3d& o = soup.points[static_cast<std::size_t>(poly[0])];
  bool convex = true;
  for (std::size_t k = 1; k + 1 < n && convex; ++k)
    convex = (soup.points[static_cast<std::size_t>(poly[k])] - o).cross(soup.points[static_cast<std::size_t>(poly[k + 1])] - o).dot(normal) > 0;
  if (convex) return fan();
  // The plane's frame (u, v) with u x v along the normal: the polygon is counter-clockwise in it.
  const Eigen::Vector3d w = normal.normalized();
  const Eigen::Vector3d u = (std::abs(w.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY()).cross(w).normalized();
  const Eigen::Vector3d v = w.cross(u);
  std::vector<Eigen::Vector2d> flat;
  for (const int id : poly) {
    const Eigen::Vector3d d = soup.points[static_cast<std::size_t>(id)] - o;
    flat.emplace_back(d.dot(u), d.dot(v));
  }
  try {
    for (const auto& t : analytic_detail::triangulate_polygon(flat, soup.source))
      soup.triangles.push_back({poly[static_cast<std::size_t>(t[0])], poly[static_cast<std::size_t>(t[1])], poly[static_cast<std::size_t>(t[2])]});
  } catch (const MesherError&) {
    fan();  // not simple in its plane (a warped polygon): the fan, and validation judges it
  }
}

TriangleSoup read_with_openmesh(const fs::path& path, const std::string& ext, const std::string& text,
                                const Expected& expected) {
  SoupImporter importer;
  bool ok = false;
  try {
    const QuietOpenMesh quiet;
    // The OFF reader takes the header's variant (colors, normals, texture coordinates) from its
    // can_u_read(file name), which a read from a stream does not call: without it the variant of
    // the previous OFF file would be used.
    if (ext == "off" && !OpenMesh::IO::OFFReader().can_u_read(path.string()))
      fail(path, "the OpenMesh off reader does not accept the header");
    std::istringstream in(text, std::ios::binary);
    OpenMesh::IO::Options options;
    if (expected.binary) options += OpenMesh::IO::Options::Binary;
    ok = OpenMesh::IO::IOManager().read(in, ext, importer, options);
  } catch (const std::exception& e) {
    fail(path, std::string("the OpenMesh reader failed: ") + e.what());
  }
  if (!ok) fail(path, "the OpenMesh " + ext + " reader could not read the file");
  const std::size_t nv = importer.points.size(), nf = importer.faces.size();
  if (expected.vertices >= 0 && nv != static_cast<std::size_t>(expected.vertices))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nv) + " vertices, the file has " +
                   std::to_string(expected.vertices));
  if (expected.faces >= 0 && nf != static_cast<std::size_t>(expected.faces))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nf) + " faces, the file has " +
                   std::to_string(expected.faces));
  if (expected.max_faces >= 0 && nf > static_cast<std::size_t>(expected.max_faces))
    fail(path, "the OpenMesh reader delivered " + std::to_string(nf) + " faces, the file has " +
                   std::to_string(expected.max_faces));
  for (std::size_t v = 0; v < nv; ++v) {
    if (!importer.points[v].allFinite()) fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    if (importer.points[v].cwiseAbs().maxCoeff() > kMaxCoordinate)
      fail(path, "vertex " + std::to_string(v) + " has a coordinate beyond +-" + num(kMaxCoordinate) + " (" +
                     num(importer.points[v].cwiseAbs().maxCoeff()) + ")");
  }
  TriangleSoup soup;
  soup.source = path.string();
  soup.points = std::move(importer.points);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::vector<int>& poly = importer.faces[f];
    if (poly.size() < 3) fail(path, "face " + std::to_string(f) + " has " + std::to_string(poly.size()) + " vertices");
    for (const int v : poly)
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        fail(path,
             "face " + std::to_string(f) + " refers to vertex " + std::to_string(v) + " of " + std::to_string(nv));
    triangulate_face(soup, poly);
  }
  if (expected.max_faces >= 0 && nf < static_cast<std::size_t>(expected.max_faces))
    soup.repairs.push_back(path.string() + ": dropped " + std::to_string(expected.max_faces - static_cast<std::int64_t>(nf)) +
                           " face(s) with a repeated vertex (the reader skips them)");
  return soup;
}

}  // namespace

TriangleSoup read_surface_file(const fs::path& path, const ReadSurfaceOptions& options) {
  const std::string ext = read_detail::lower(path.extension().string());
  const bool plot3d = ext == ".fmt" || ext == ".p3d";
  if (!plot3d && ext != ".stl" && ext != ".obj" && ext != ".off" && ext != ".ply")
    fail(path, "unknown surface format " + TextCursor::quote(ext.empty() ? path.filename().string() : ext) +
                   " (expected .stl, .obj, .off, .ply, .fmt or .p3d)");
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (plot3d) return read_plot3d(path, options);

  std::string text = read_whole_file(path);
  if (text.empty()) fail(path, "the file is empty");
  Expected expected;
  if (ext == ".stl") expected = read_detail::check_stl(path, text);
  if (ext == ".obj") expected = read_detail::check_obj(path, text);
  if (ext == ".off") {
    expected = read_detail::check_off(path, text);
    read_detail::blank_comments(text);
  }
  if (ext == ".ply") expected = read_detail::check_ply(path, text);
  TriangleSoup soup = read_with_openmesh(path, ext.substr(1), text, expected);
  if (soup.triangles.empty()) {
    const std::int64_t given = std::max(expected.faces, expected.max_faces);
    double largest = 0;
    for (const Eigen::Vector3d& x : soup.points) largest = std::max(largest, x.cwiseAbs().maxCoeff());
    // A body at the scale 1e-40 is read as floats in STL: every facet collapses to a point.
    if (given > 0)
      fail(path, "no triangles: all " + std::to_string(given) + " of the file's faces collapsed to a point or an edge as read " +
                     "(the largest coordinate is " + num(largest) + (ext == ".stl" ? "; STL holds single precision" : "") +
                     "): check the file's units and scale");
    fail(path, "no triangles");
  }
  if (ext == ".stl") {
    // OpenMesh has merged exactly equal points already; close ones are merged here.
    weld_points(soup, options.weld_rel * read_detail::bbox_diagonal(soup.points));
  } else {
    // Indexed formats keep their vertices as given; unreferenced ones are dropped.
    read_detail::renumber_and_compact(soup, nullptr);
  }
  return soup;
}

}  // namespace plaf
