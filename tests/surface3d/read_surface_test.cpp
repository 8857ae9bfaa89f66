// SPDX-License-Identifier: MIT
#include "surface3d/read_surface.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "surface3d/validate.h"
#include "tests/surface3d/test_surfaces.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

namespace plaf {
namespace {

using Vec3 = Eigen::Vector3d;


// Edge use of a soup: boundary edges (one triangle), and whether every interior edge is used by
// exactly two triangles in opposite directions (manifold and consistently oriented).
struct EdgeCount {
  std::size_t boundary = 0;
  bool manifold_oriented = true;
};

EdgeCount count_edges(const TriangleSoup& s) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]}];
  EdgeCount out;
  for (const auto& [e, n] : directed) {
    if (n != 1) out.manifold_oriented = false;
    if (!directed.count({e.second, e.first})) ++out.boundary;
  }
  return out;
}

// Signed volume by the divergence theorem (open loops in a plane through the origin add zero).
double signed_volume(const TriangleSoup& s) {
  double v = 0;
  for (const auto& t : s.triangles) {
    const Vec3& a = s.points[static_cast<std::size_t>(t[0])];
    const Vec3& b = s.points[static_cast<std::size_t>(t[1])];
    const Vec3& c = s.points[static_cast<std::size_t>(t[2])];
    v += a.dot(b.cross(c)) / 6;
  }
  return v;
}

bool all_points_referenced(const TriangleSoup& s) {
  std::vector<char> used(s.points.size(), 0);
  for (const auto& t : s.triangles)
    for (const int v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= s.points.size()) return false;
      used[static_cast<std::size_t>(v)] = 1;
    }
  return std::find(used.begin(), used.end(), 0) == used.end();
}

struct Expect {
  const char* file;
  std::size_t triangles;
  std::size_t vertices;
  std::size_t boundary_edges;
  double volume;
  double volume_tol;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Reads e.file (reporting the time when timed) and checks the soup against e.
void check_file(const Expect& e, bool timed = false) {
  CAPTURE(e.file);
  const auto t0 = std::chrono::steady_clock::now();
  const TriangleSoup s = read_surface_file(plaf::test::published(std::string("surfaces/") + e.file));
  if (timed) MESSAGE(std::string(e.file) << " read in " << seconds_since(t0) << " s");
  CHECK(s.source == plaf::test::published(std::string("surfaces/") + e.file));
  CHECK(s.triangles.size() == e.triangles);
  CHECK(s.points.size() == e.vertices);
  CHECK(all_points_referenced(s));
  const EdgeCount edges = count_edges(s);
  CHECK(edges.manifold_oriented);
  CHECK(edges.boundary == e.boundary_edges);
  CHECK(signed_volume(s) == doctest::Approx(e.volume).epsilon(e.volume_tol));
}

// A binary STL of the given triangles (normals zero), little-endian as the format says.
std::string binary_stl(const std::vector<std::array<Vec3, 3>>& tris, std::uint32_t count_in_header) {
  static_assert(std::endian::native == std::endian::little, "the test writes STL floats in host order");
  std::string out(80, '\0');
  out.replace(0, 11, "test binary");
  out.append(reinterpret_cast<const char*>(&count_in_header), 4);
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 0};
    out.append(reinterpret_cast<const char*>(normal), sizeof normal);
    for (const Vec3& p : t)
      for (int d = 0; d < 3; ++d) {
        const auto f = static_cast<float>(p[d]);
        out.append(reinterpret_cast<const char*>(&f), sizeof f);
      }
    out.append(2, '\0');
  }
  return out;
}

std::string ascii_stl(const std::vector<std::array<Vec3, 3>>& tris) {
  std::string out = "solid shape\n";
  char buf[128];
  for (const auto& t : tris) {
    out += "  facet normal 0 0 0\n    outer loop\n";
    for (const Vec3& p : t) {
      std::snprintf(buf, sizeof buf, "      vertex %.9g %.9g %.9g\n", p[0], p[1], p[2]);
      out += buf;
    }
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid shape\n";
}

// An octahedron, outward, as a triangle list (points exact in float).
std::vector<std::array<Vec3, 3>> octahedron() {
  const Vec3 px(1.5, 0, 0), mx(-1.5, 0, 0), py(0, 0.75, 0), my(0, -0.75, 0), pz(0, 0, 2.25), mz(0, 0, -2.25);
  return {{px, py, pz}, {py, mx, pz}, {mx, my, pz}, {my, px, pz},
          {py, px, mz}, {mx, py, mz}, {my, mx, mz}, {px, my, mz}};
}

}  // namespace

TEST_CASE("read_surface: a 52,020-triangle binary STL reads welded, closed and outward") {
  // The icosphere with m = 51: 20 m^2 triangles and, closed of genus 0 (V - E + F = 2 with
  // E = 3F/2), 10 m^2 + 2 vertices, which the reader finds again by welding the STL's corners.
  const int m = 51;
  const TriangleSoup sphere = test::icosphere_soup(m);
  std::vector<std::array<Vec3, 3>> tris;
  for (const auto& t : sphere.triangles)
    tris.push_back({sphere.points[static_cast<std::size_t>(t[0])], sphere.points[static_cast<std::size_t>(t[1])],
                    sphere.points[static_cast<std::size_t>(t[2])]});
  const test::TempDir dir("read_stl_big");
  const auto path = test::write_text(dir / "icosphere.stl", binary_stl(tris, static_cast<std::uint32_t>(tris.size())));
  const auto t0 = std::chrono::steady_clock::now();
  const TriangleSoup s = read_surface_file(path);
  MESSAGE("icosphere.stl (" << tris.size() << " triangles) read in " << seconds_since(t0) << " s");
  CHECK(s.triangles.size() == std::size_t{20 * m * m});
  CHECK(s.points.size() == std::size_t{10 * m * m + 2});
  CHECK(all_points_referenced(s));
  const EdgeCount edges = count_edges(s);
  CHECK(edges.manifold_oriented);
  CHECK(edges.boundary == 0);
  // The same volume as the double-precision soup, to the float rounding of the STL's points.
  CHECK(signed_volume(s) == doctest::Approx(signed_volume(sphere)).epsilon(1e-6));
}

TEST_CASE("read_surface: an OBJ's unreferenced vertices are dropped, the referenced ones kept in order") {
  // The icosphere with m = 20 (8,000 triangles, 4,002 vertices), with an unused vertex line
  // after every fourth vertex: 1,001 extra vertices that the reader must drop. OpenMesh reads the
  // file; the vertices it keeps must be the referenced ones, in file order.
  const TriangleSoup sphere = test::icosphere_soup(20);
  std::string obj = "# icosphere with unused vertices\n";
  std::vector<int> line_of(sphere.points.size());
  int lines = 0;
  char buf[128];
  for (std::size_t i = 0; i < sphere.points.size(); ++i) {
    const Vec3& p = sphere.points[i];
    std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    obj += buf;
    line_of[i] = ++lines;
    if (i % 4 == 0) {
      obj += "v 5 5 5\n";
      ++lines;
    }
  }
  for (const auto& t : sphere.triangles) {
    std::snprintf(buf, sizeof buf, "f %d %d %d\n", line_of[static_cast<std::size_t>(t[0])],
                  line_of[static_cast<std::size_t>(t[1])], line_of[static_cast<std::size_t>(t[2])]);
    obj += buf;
  }
  const test::TempDir dir("read_obj_unused");
  const TriangleSoup s = read_surface_file(test::write_text(dir / "icosphere.obj", obj));
  CHECK(s.triangles == sphere.triangles);
  REQUIRE(s.points.size() == sphere.points.size());
  double moved = 0;  // OpenMesh reads OBJ coordinates as floats: up to 6e-8 on the unit sphere
  for (std::size_t i = 0; i < s.points.size(); ++i) moved = std::max(moved, (s.points[i] - sphere.points[i]).norm());
  CHECK(moved < 1e-7);
}

TEST_CASE("read_surface: the published Plot3D files read with merged interfaces and outward triangles") {
  PLAF_NEEDS_PUBLISHED("surfaces/onera_m6_small.fmt", "surfaces/bwb_half.fmt", "surfaces/wing_717_small.fmt", "surfaces/sphere_cube6_even.fmt", "surfaces/sphere_cube6_uneven.fmt");
  // Unique nodes and 2 x quads triangles (no quad of these files is collapsed: each wing is a
  // disc, V - E + F = 1 on the quads, so none is skipped); open only at the z = 0 root.
  check_file({"onera_m6_small.fmt", 2 * 15232, 15321, 176, 0.0338, 2e-3}, true);
  check_file({"bwb_half.fmt", 2 * 13376, 13457, 160, 1950.6, 1e-3});
  check_file({"wing_717_small.fmt", 2 * 12096, 12177, 160, 12.65, 2e-3});
  check_file({"sphere_cube6_even.fmt", 2 * 96, 98, 0, 3.92, 2e-3});
  check_file({"sphere_cube6_uneven.fmt", 2 * 1536, 1538, 0, 4.17, 2e-3});
  const TriangleSoup m6 = read_plot3d(plaf::test::published("surfaces/onera_m6_small.fmt"));
  REQUIRE(m6.patch.size() == m6.triangles.size());
  std::vector<std::size_t> per_block(9, 0);
  for (const int b : m6.patch) {
    REQUIRE(b >= 0);
    REQUIRE(b < 9);
    ++per_block[static_cast<std::size_t>(b)];
  }
  // Block 1 is 65 x 17 nodes: 64 x 16 quads.
  CHECK(per_block[0] == 2 * 64 * 16);
  CHECK(per_block[1] == 2 * 72 * 64);
}

TEST_CASE("read_surface: ASCII and binary STL of the same shape give the same soup") {
  const test::TempDir dir("read_stl_pair");
  const auto tris = octahedron();
  const TriangleSoup a = read_surface_file(test::write_text(dir / "oct_a.stl", ascii_stl(tris)));
  const TriangleSoup b = read_surface_file(test::write_text(dir / "oct_b.STL", binary_stl(tris, 8)));
  CHECK(a.triangles.size() == 8);
  CHECK(a.points.size() == 6);
  CHECK(a.points == b.points);
  CHECK(a.triangles == b.triangles);
  CHECK(signed_volume(a) == doctest::Approx(4.0 / 3.0 * 1.5 * 0.75 * 2.25));
  CHECK(count_edges(a).manifold_oriented);
  // A binary STL whose 80-byte header starts with "solid" is still binary.
  std::string solid_header = binary_stl(tris, 8);
  solid_header.replace(0, 11, "solid thing");
  const TriangleSoup c = read_surface_file(test::write_text(dir / "oct_c.stl", solid_header));
  CHECK(c.triangles == a.triangles);
  // A solid named with "outer" in it (OpenMesh starts a facet at any line containing "outer").
  std::string named = ascii_stl(tris);
  named.replace(0, 11, "solid outer_mold_line");
  named.replace(named.rfind("endsolid"), std::string::npos, "endsolid outer_mold_line\n");
  const TriangleSoup d = read_surface_file(test::write_text(dir / "named.stl", named));
  CHECK(d.points == a.points);
  CHECK(d.triangles == a.triangles);
}

TEST_CASE("read_surface: STL points closer than weld_rel x the bbox diagonal are welded") {
  const test::TempDir dir("read_stl_weld");
  auto tris = octahedron();
  // Move one copy of the +x apex by 1e-6 (relative 2e-7 of the diagonal, above float resolution).
  tris[0][0] += Vec3(1e-6, 0, 0);
  const auto path = test::write_text(dir / "near.stl", ascii_stl(tris));
  const TriangleSoup welded = read_surface_file(path, {.weld_rel = 1e-6});
  CHECK(welded.points.size() == 6);
  CHECK(count_edges(welded).boundary == 0);
  const TriangleSoup apart = read_surface_file(path, {.weld_rel = 1e-9});
  CHECK(apart.points.size() == 7);
  CHECK(count_edges(apart).boundary == 4);  // the moved copy opens two edges on each side
}

TEST_CASE("read_surface: OBJ, OFF and PLY polygons are fanned into triangles keeping their orientation") {
  const test::TempDir dir("read_poly");
  // A unit square (one quad, counter-clockwise seen from +z) and a triangle above it.
  const std::string points = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n";
  const auto check = [](const TriangleSoup& s) {
    REQUIRE(s.triangles.size() == 3);
    CHECK(s.points.size() == 5);
    CHECK(s.triangles[0] == std::array<int, 3>{0, 1, 2});
    CHECK(s.triangles[1] == std::array<int, 3>{0, 2, 3});
    CHECK(s.triangles[2] == std::array<int, 3>{0, 1, 4});
    const Vec3 n = (s.points[1] - s.points[0]).cross(s.points[2] - s.points[0]);
    CHECK(n.z() > 0);
  };
  std::string obj = "# square\n";
  for (const char* p : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "5 5 5"}) obj += std::string("v ") + p + "\n";
  obj += "vn 0 0 1\nf 1//1 2//1 3//1 4//1\nf -6 -5 -2\n";  // vertex 6 is unreferenced: dropped
  check(read_surface_file(test::write_text(dir / "poly.obj", obj)));
  check(read_surface_file(
      test::write_text(dir / "poly.off", "OFF\n# comment\n5 2 0\n" + points + "4 0 1 2 3\n3 0 1 4\n")));
  const std::string colored =
      "COFF\n5 2 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n"
      "0 1 0 9 9 9 255\n0 0 1 1 1 1 255\n4 0 1 2 3 0.5 0.5 0.5\n3 0 1 4 1 2 3\n";
  check(read_surface_file(test::write_text(dir / "colored.off", colored)));
  // The OFF reader keeps the header's variant between files: plain OFF again after COFF.
  check(read_surface_file(test::write_text(dir / "plain.off", "OFF\n5 2 0\n" + points + "4 0 1 2 3\n3 0 1 4\n")));
  const std::string ply_header =
      "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  check(read_surface_file(
      test::write_text(dir / "poly.ply", "ply\nformat ascii 1.0\n" + ply_header + points + "4 0 1 2 3\n3 0 1 4\n")));
  std::string body;
  for (const float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f})
    body.append(reinterpret_cast<const char*>(&f), 4);
  const auto face = [&body](std::initializer_list<int> vs) {
    body += static_cast<char>(vs.size());
    for (const int v : vs) body.append(reinterpret_cast<const char*>(&v), 4);
  };
  face({0, 1, 2, 3});
  face({0, 1, 4});
  const std::string binary_ply = "ply\nformat binary_little_endian 1.0\n" + ply_header + body;
  check(read_surface_file(test::write_text(dir / "poly_b.ply", binary_ply)));
  CHECK_THROWS_WITH_AS(
      read_surface_file(test::write_text(dir / "trunc_b.ply", binary_ply.substr(0, binary_ply.size() - 5))),
      doctest::Contains("trunc_b.ply: truncated binary PLY: the file ends in face 1 of 2"), InputError);
  std::string bad_index = binary_ply;
  bad_index[bad_index.size() - 4] = 7;  // the last index of the last face
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "index_b.ply", bad_index)),
                       doctest::Contains("index_b.ply: face 1 refers to vertex 7 of 5"), InputError);
  // Big-endian: the same values with their bytes reversed.
  std::string big_body;
  for (std::size_t k = 0; k < 60; k += 4) big_body += {body[k + 3], body[k + 2], body[k + 1], body[k]};
  for (std::size_t k = 60; k < body.size();) {
    const auto n = static_cast<std::size_t>(body[k]);
    big_body += body[k++];
    for (std::size_t m = 0; m < n; ++m, k += 4) big_body += {body[k + 3], body[k + 2], body[k + 1], body[k]};
  }
  check(read_surface_file(
      test::write_text(dir / "poly_be.ply", "ply\nformat binary_big_endian 1.0\n" + ply_header + big_body)));
  // Extra vertex and face properties are skipped.
  const std::string extra =
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty uchar red\nproperty float confidence\n"
      "element face 2\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n"
      "0 0 0 0 1 0.5\n1 0 0 0 2 0.5\n1 1 0 0 3 0.5\n0 1 0 0 4 0.5\n0 0 1 0 5 0.5\n4 0 1 2 3 7\n3 0 1 4 8\n";
  check(read_surface_file(test::write_text(dir / "extra.ply", extra)));
  // The ASCII reader again after the binary ones (no state left over).
  check(read_surface_file(dir / "poly.ply"));
}

TEST_CASE("read_surface: missing, unknown, empty and triangle-less files give one-line errors") {
  const test::TempDir dir("read_bad_files");
  const auto p = [&dir](const char* name) { return (dir / name).string(); };
  CHECK_THROWS_WITH_AS(read_surface_file(dir / "absent.stl"), (p("absent.stl") + ": no such file").c_str(), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(dir / "absent.fmt"), doctest::Contains("absent.fmt: no such file"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "shape.step", "x")),
                       doctest::Contains("shape.step: unknown surface format '.step'"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "noext", "x")),
                       doctest::Contains("unknown surface format 'noext'"), InputError);
  for (const char* name : {"empty.stl", "empty.obj", "empty.off", "empty.ply", "empty.fmt", "empty.p3d"})
    CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / name, "")), (p(name) + ": the file is empty").c_str(),
                         InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "zero.stl", "solid z\nendsolid z\n")),
                       (p("zero.stl") + ": no triangles").c_str(), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "zero_b.stl", binary_stl({}, 0))),
                       (p("zero_b.stl") + ": no triangles").c_str(), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")),
                       (p("zero.obj") + ": no triangles").c_str(), InputError);
  // Every facet degenerate (a repeated point): OpenMesh drops them, nothing is left.
  const Vec3 o(0, 0, 0), x(1, 0, 0);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "flat.stl", ascii_stl({{o, o, x}}))),
                       doctest::Contains("flat.stl: no triangles"), InputError);
}

TEST_CASE("read_surface: malformed STL gives the reason and the line") {
  const test::TempDir dir("read_bad_stl");
  const auto tris = octahedron();
  // Binary: the count disagrees with the size (OpenMesh would read it as ASCII, with no facet).
  CHECK_THROWS_WITH_AS(
      read_surface_file(test::write_text(dir / "count.stl", binary_stl(tris, 9))),
      doctest::Contains("count.stl: binary STL header says 9 triangles (534 bytes) but the file has 484"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "short.stl", binary_stl(tris, 8).substr(0, 60))),
                       doctest::Contains("short.stl: truncated binary STL: 60 bytes"), InputError);
  auto nan_tris = tris;
  nan_tris[2][1].y() = std::nan("");
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "nan_b.stl", binary_stl(nan_tris, 8))),
                       doctest::Contains("nan_b.stl: triangle 3 has a non-finite coordinate"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "text.stl", "hello\nworld\n")),
                       doctest::Contains("text.stl: not an STL file"), InputError);
  // ASCII: line 4 is the first vertex of the first facet.
  const std::string good = ascii_stl(tris);
  const auto with_line4 = [&good](const std::string& line) {
    std::string s = good;
    const std::size_t b = s.find("      vertex");
    return s.replace(b, s.find('\n', b) - b, line);
  };
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "word.stl", with_line4("vertex 1.5 abc 0"))),
                       ((dir / "word.stl").string() + ":4: bad coordinate 'abc'").c_str(), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "nan.stl", with_line4("vertex 1.5 nan 0"))),
                       doctest::Contains("nan.stl:4: non-finite coordinate 'nan'"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "inf.stl", with_line4("vertex -inf 0 0"))),
                       doctest::Contains("inf.stl:4: non-finite coordinate '-inf'"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "big.stl", with_line4("vertex 1e39 0 0"))),
                       doctest::Contains("big.stl:4: coordinate '1e39' is out of float range"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "two.stl", with_line4("vertex 1.5 0"))),
                       doctest::Contains("two.stl:4: a vertex needs 3 coordinates, found 2"), InputError);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "gap.stl", with_line4(""))),
                       doctest::Contains("gap.stl:4: expected 'vertex x y z'"), InputError);
  CHECK_THROWS_WITH_AS(
      read_surface_file(test::write_text(dir / "cut.stl", good.substr(0, good.find('\n', good.find("vertex")) + 1))),
      doctest::Contains("cut.stl:3: unexpected end of file in the loop"), InputError);
}

TEST_CASE("read_surface: malformed OBJ, OFF and PLY give the reason and the line") {
  const test::TempDir dir("read_bad_indexed");
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const auto bad = [&dir](const char* name, const std::string& text) {
    return read_surface_file(test::write_text(dir / name, text));
  };
  CHECK_THROWS_WITH_AS(bad("range.obj", v3 + "f 1 2 4\n"),
                       doctest::Contains("range.obj:4: face vertex index 4 is out of range 1..3"), InputError);
  CHECK_THROWS_WITH_AS(bad("neg.obj", v3 + "f 1 2 -4\n"),
                       doctest::Contains("neg.obj:4: face vertex index -4 is out of range (3 vertices so far)"),
                       InputError);
  CHECK_THROWS_WITH_AS(bad("zero.obj", v3 + "f 1 2 0\n"), doctest::Contains("zero.obj:4: bad face vertex index '0'"),
                       InputError);
  CHECK_THROWS_WITH_AS(bad("short.obj", v3 + "f 1 2\n"),
                       doctest::Contains("short.obj:4: a face needs at least 3 vertices, found 2"), InputError);
  CHECK_THROWS_WITH_AS(bad("nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"),
                       doctest::Contains("nan.obj:2: non-finite coordinate 'nan'"), InputError);
  CHECK_THROWS_WITH_AS(bad("word.obj", "v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n"),
                       doctest::Contains("word.obj:2: bad coordinate 'x'"), InputError);
  const std::string off_points = "0 0 0\n1 0 0\n0 1 0\n";
  CHECK_THROWS_WITH_AS(bad("range.off", "OFF\n3 1 0\n" + off_points + "3 0 1 5\n"),
                       doctest::Contains("range.off:6: face vertex index 5 is outside 0..2"), InputError);
  CHECK_THROWS_WITH_AS(bad("word.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"),
                       doctest::Contains("word.off:4: bad vertex coordinate 'x'"), InputError);
  CHECK_THROWS_WITH_AS(bad("trunc.off", "OFF\n3 2 0\n" + off_points + "3 0 1 2\n"),
                       doctest::Contains("trunc.off:7: unexpected end of file (expected face size)"), InputError);
  // OpenMesh loops for ever on this one.
  CHECK_THROWS_WITH_AS(
      bad("huge.off", "OFF\n3000000000 1 0\n0 0 0\n"),
      doctest::Contains("huge.off:2: vertex count 3000000000 exceeds what the rest of the file can hold"), InputError);
  CHECK_THROWS_WITH_AS(bad("bin.off", "OFF BINARY\n"), doctest::Contains("bin.off:1: binary OFF is not supported"),
                       InputError);
  CHECK_THROWS_WITH_AS(bad("notoff.off", "3 1 0\n"), doctest::Contains("notoff.off:1: not an OFF file"), InputError);
  CHECK_THROWS_WITH_AS(bad("late.off", "# a comment first\nOFF\n"), doctest::Contains("late.off:2: not an OFF file"),
                       InputError);
  CHECK_THROWS_WITH_AS(
      bad("color.off", "OFF\n3 1 0\n" + off_points + "3 0 1 2 255 0 0\n"),
      doctest::Contains("color.off:6: unexpected '255' after face 0 (face colors need the COFF header)"), InputError);
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
      off_points;
  CHECK_THROWS_WITH_AS(bad("range.ply", ply + "3 0 1 9\n"),
                       doctest::Contains("range.ply:13: face vertex index 9 is outside 0..2"), InputError);
  CHECK_THROWS_WITH_AS(bad("trunc.ply", ply),
                       doctest::Contains("trunc.ply:13: unexpected end of file (expected list count)"), InputError);
  CHECK_THROWS_WITH_AS(bad("nan.ply", ply.substr(0, ply.size() - 6) + "inf 0 0\n3 0 1 2\n"),
                       doctest::Contains("nan.ply:12: bad vertex coordinate 'inf'"), InputError);
  CHECK_THROWS_WITH_AS(bad("extra.ply", ply + "3 0 1 2\n7\n"),
                       doctest::Contains("extra.ply:14: unexpected '7' after the last element"), InputError);
  CHECK_THROWS_WITH_AS(bad("notply.ply", "solid\n"), doctest::Contains("notply.ply:1: not a PLY file"), InputError);
  // OpenMesh loops for ever on these headers.
  std::string format = ply;
  format.replace(format.find("ascii"), 5, "ascii float");
  CHECK_THROWS_WITH_AS(bad("format.ply", format), doctest::Contains("format.ply:2: bad PLY version 'float'"),
                       InputError);
  std::string count = ply;
  count.replace(count.find("vertex 3"), 8, "vertex x3");
  CHECK_THROWS_WITH_AS(bad("count.ply", count), doctest::Contains("count.ply:3: bad element count 'x3'"), InputError);
  CHECK_THROWS_WITH_AS(bad("noend.ply", ply.substr(0, ply.find("end_header"))),
                       doctest::Contains("noend.ply:9: unexpected end of file (expected end_header)"), InputError);
  std::string list = ply;
  list.replace(list.find("uchar int"), 9, "uint int");
  CHECK_THROWS_WITH_AS(bad("list.ply", list), doctest::Contains("list.ply:8: unsupported list count type 'uint'"),
                       InputError);
}

TEST_CASE(
    "read_surface: Plot3D blocks merge on interfaces, split quads on the shorter diagonal and skip collapsed ones") {
  const test::TempDir dir("read_p3d");
  // Two 3 x 2 blocks on z = 0 sharing the edge (2, 0)-(2, 1). Block 1: x in {0, 1, 2}, y in
  // {0, 1}, its row j = 1 shifted by 0.4 in x (except on the interface) so that its quads' shorter
  // diagonal is (i+1, j)-(i, j+1). Block 2: row j = 0 collapses to the pole (2, 0), row j = 1 runs
  // (2, 1), (3, 1), (4, 1): each of its quads keeps one triangle.
  const std::string text =
      "2\n"
      "3 2 1\n3 2 1\n"
      "0 1 2  0.4 1.4 2\n"
      "0 0 0  1 1 1\n"
      "0 0 0  0 0 0\n"
      "2 2 2  2 3 4\n"
      "0 0 0  1 1 1\n"
      "0 0 0  0 0 0\n";
  const TriangleSoup s = read_surface_file(test::write_text(dir / "blocks.p3d", text));
  // 12 raw nodes: block 2's pole row is block 1's node (2, 0), and (2, 1) is shared.
  CHECK(s.points.size() == 12 - 3 - 1);
  REQUIRE(s.triangles.size() == 4 + 2);
  CHECK(s.patch == std::vector<int>{0, 0, 0, 0, 1, 1});
  for (const auto& t : s.triangles) {
    const Vec3 n = (s.points[static_cast<std::size_t>(t[1])] - s.points[static_cast<std::size_t>(t[0])])
                       .cross(s.points[static_cast<std::size_t>(t[2])] - s.points[static_cast<std::size_t>(t[0])]);
    CHECK(n.z() > 0);  // i x j is +z: the quads' orientation is kept
  }
  const auto point_of = [&s](const Vec3& p) {
    for (std::size_t k = 0; k < s.points.size(); ++k)
      if (s.points[k] == p) return static_cast<int>(k);
    return -1;
  };
  // Block 1's first quad (0,0)-(1,0)-(1.4,1)-(0.4,1): diagonal (1,0)-(0.4,1) is the shorter.
  CHECK(s.triangles[0] == std::array<int, 3>{point_of({0, 0, 0}), point_of({1, 0, 0}), point_of({0.4, 1, 0})});
  CHECK(s.triangles[1] == std::array<int, 3>{point_of({1, 0, 0}), point_of({1.4, 1, 0}), point_of({0.4, 1, 0})});
  const EdgeCount edges = count_edges(s);
  CHECK(edges.manifold_oriented);
  CHECK(edges.boundary == 8);
}

TEST_CASE("read_surface: malformed Plot3D gives the line") {
  const test::TempDir dir("read_bad_p3d");
  const auto bad = [&dir](const char* name, const std::string& text) {
    return read_surface_file(test::write_text(dir / name, text));
  };
  const std::string one = "1\n2 2 1\n0 1 0 1\n0 0 1 1\n0 0 0 0\n";
  CHECK_NOTHROW(bad("ok.fmt", one));
  CHECK_THROWS_WITH_AS(bad("nk.fmt", "1\n2 2 2\n"),
                       doctest::Contains("nk.fmt:2: block 1 has nk = 2: a surface grid has nk = 1"), InputError);
  CHECK_THROWS_WITH_AS(bad("word.fmt", "1\n2 2 1\n0 1 0 1\n0 0 x 1\n0 0 0 0\n"),
                       doctest::Contains("word.fmt:4: bad y coordinate 'x'"), InputError);
  CHECK_THROWS_WITH_AS(bad("nan.fmt", "1\n2 2 1\n0 1 0 1\n0 0 1 1\n0 nan 0 0\n"),
                       doctest::Contains("nan.fmt:5: bad z coordinate 'nan'"), InputError);
  CHECK_THROWS_WITH_AS(bad("cut.fmt", one.substr(0, one.size() - 4)),
                       doctest::Contains("cut.fmt:5: unexpected end of file (expected z coordinate)"), InputError);
  CHECK_THROWS_WITH_AS(bad("iblank.fmt", one + "1 1 1 1\n"),
                       doctest::Contains("iblank.fmt:6: unexpected '1' after the last block (IBLANK is not supported)"),
                       InputError);
  CHECK_THROWS_WITH_AS(bad("huge.fmt", "1\n100000 100000 1\n0\n"),
                       doctest::Contains("huge.fmt:2: block 1 of 100000 x 100000 points exceeds"), InputError);
  CHECK_THROWS_WITH_AS(bad("zero.fmt", "0\n"), doctest::Contains("zero.fmt:1: no blocks"), InputError);
  CHECK_THROWS_WITH_AS(bad("line.fmt", "1\n2 1 1\n0 1\n0 0\n0 0\n"), doctest::Contains("line.fmt: no triangles"),
                       InputError);
}

TEST_CASE("read_surface: coordinates beyond +-1e12 are refused in every format, naming the file") {
  // Two bodies at +-1.5e308 used to overflow a bounding box to inf (issue 17, item 6).
  const test::TempDir dir("read_huge");
  const auto bad = [&dir](const char* name, const std::string& text) {
    return read_surface_file(test::write_text(dir / name, text));
  };
  CHECK_THROWS_WITH_AS(bad("far.obj", "v 0 0 0\nv 1e20 0 0\nv 0 1 0\nf 1 2 3\n"),
                       doctest::Contains("far.obj: vertex 1 has a coordinate beyond +-1e+12 (1e+20)"), InputError);
  CHECK_THROWS_WITH_AS(bad("far.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 -3e13 0\n3 0 1 2\n"),
                       doctest::Contains("far.off: vertex 2 has a coordinate beyond +-1e+12 (3e+13)"), InputError);
  CHECK_THROWS_WITH_AS(bad("far.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                      "vertex 0 1 2e15\nendloop\nendfacet\nendsolid s\n"),
                       doctest::Contains("far.stl: vertex 2 has a coordinate beyond +-1e+12"), InputError);
  CHECK_THROWS_WITH_AS(bad("far.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                                      "property double z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                      "end_header\n0 0 0\n1.5e308 0 0\n0 1 0\n3 0 1 2\n"),
                       doctest::Contains("far.ply: vertex 1 has a coordinate beyond +-1e+12"), InputError);
  CHECK_THROWS_WITH_AS(bad("far.fmt", "1\n2 2 1\n0 1 0 -1.5e308\n0 0 1 1\n0 0 0 0\n"),
                       doctest::Contains("far.fmt:3: x coordinate '-1.5e308' is beyond +-1e+12"), InputError);
  // At the bound itself a coordinate is taken.
  CHECK_NOTHROW(bad("edge.obj", "v 0 0 0\nv 1e12 0 0\nv 0 1e12 0\nf 1 2 3\n"));
}

TEST_CASE("read_surface: a binary PLY header is read by lines: 'comment end_header' is a comment") {
  const test::TempDir dir("read_ply_comment");
  std::string body;
  for (const float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f})
    body.append(reinterpret_cast<const char*>(&f), 4);
  for (const std::array<int, 3> t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}) {
    body += static_cast<char>(3);
    body.append(reinterpret_cast<const char*>(t.data()), 12);
  }
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment end_header is not the end of this header\n"
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\ncomment end_header\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const TriangleSoup soup = read_surface_file(test::write_text(dir / "tet.ply", header + body));
  REQUIRE(soup.points.size() == 4);
  REQUIRE(soup.triangles.size() == 4);
  CHECK(soup.points[1] == Vec3(1, 0, 0));
  CHECK(soup.points[3] == Vec3(0, 0, 1));
  // A truncated body is still found, measured from the real end of the header.
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "cut.ply", header + body.substr(0, body.size() - 3))),
                       doctest::Contains("cut.ply: truncated binary PLY: the file ends in face 3 of 4"), InputError);
}

TEST_CASE("read_surface: weld_points merges near points, renumbers and drops unreferenced ones") {
  for (const double scale : {1e-8, 1.0, 1e8}) {
    CAPTURE(scale);
    TriangleSoup s;
    // Two triangles sharing an edge whose copies differ by 1e-7 x scale; point 6 unreferenced.
    s.points = {Vec3(0, 0, 0), Vec3(1, 0, 0),           Vec3(0, 1, 0), Vec3(1 + 1e-7, 0, 0),
                Vec3(1, 1, 0), Vec3(0, 1 - 1e-7, 1e-7), Vec3(5, 5, 5)};
    for (Vec3& p : s.points) p *= scale;
    s.triangles = {{0, 1, 2}, {3, 4, 5}};
    s.patch = {7, 8};
    CHECK(weld_points(s, 1e-6 * scale) == 3);
    REQUIRE(s.points.size() == 4);
    CHECK(s.triangles == std::vector<std::array<int, 3>>{{0, 1, 2}, {1, 3, 2}});
    CHECK(s.points[1] == Vec3(1, 0, 0) * scale);  // the first of a cluster represents it
    CHECK(s.points[3] == Vec3(1, 1, 0) * scale);
    CHECK(s.patch == std::vector<int>{7, 8});
  }
  TriangleSoup apart;
  apart.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1e-3, 0, 0)};
  apart.triangles = {{0, 1, 2}, {3, 1, 2}};
  CHECK(weld_points(apart, 1e-6) == 0);
  CHECK(apart.points.size() == 4);
  // tol 0 merges exactly equal points only.
  TriangleSoup exact;
  exact.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 0), Vec3(0, 0, 1e-300)};
  exact.triangles = {{0, 1, 2}, {3, 4, 1}};
  CHECK(weld_points(exact, 0) == 1);
  CHECK(exact.triangles[1] == std::array<int, 3>{0, 3, 1});
  // Many points on a grid with a jittered copy each: the hash grid merges every pair.
  TriangleSoup grid;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      grid.points.emplace_back(i, j, 0.5 * i);
      grid.points.emplace_back(i + 1e-9 * (j % 3 - 1), j - 1e-9, 0.5 * i + 1e-9);
    }
  for (int k = 0; k + 3 < static_cast<int>(grid.points.size()); k += 2) grid.triangles.push_back({k, k + 1, k + 3});
  CHECK(weld_points(grid, 1e-6) == 1600);
  CHECK(grid.points.size() == 1600);
}

TEST_CASE("read_surface: mutated files give a soup or an InputError, never a crash or a hang") {
  const test::TempDir dir("read_fuzz");
  const auto tris = octahedron();
  const std::string points = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n";
  std::string obj;
  for (const char* p : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1"}) obj += std::string("v ") + p + "\n";
  obj += "f 1 2 3 4\nf 1 2 5\n";
  const std::string ply_header =
      "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  std::string ply_body;
  for (const float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f})
    ply_body.append(reinterpret_cast<const char*>(&f), 4);
  for (const std::vector<int>& face : {std::vector<int>{0, 1, 2, 3}, std::vector<int>{0, 1, 4}}) {
    ply_body += static_cast<char>(face.size());
    for (const int v : face) ply_body.append(reinterpret_cast<const char*>(&v), 4);
  }
  const std::vector<std::pair<std::string, std::string>> bases = {
      {"a.stl", ascii_stl(tris)},
      {"b.stl", binary_stl(tris, 8)},
      {"c.obj", obj},
      {"d.off", "OFF\n5 2 0\n" + points + "4 0 1 2 3\n3 0 1 4\n"},
      {"e.ply", "ply\nformat ascii 1.0\n" + ply_header + points + "4 0 1 2 3\n3 0 1 4\n"},
      {"f.ply", "ply\nformat binary_little_endian 1.0\n" + ply_header + ply_body},
      {"g.fmt",
       "2\n3 2 1\n3 2 1\n0 1 2 0.4 1.4 2\n0 0 0 1 1 1\n0 0 0 0 0 0\n"
       "2 2 2 2 3 4\n0 0 0 1 1 1\n0 0 0 0 0 0\n"}};
  std::mt19937 rng(12345);
  const std::string alphabet = "0123456789-+.eE x#\n\t\0\xff/fvn";
  std::size_t read_ok = 0, rejected = 0;
  for (const auto& [name, base] : bases) {
    CAPTURE(name);
    for (int trial = 0; trial < 150; ++trial) {
      std::string text = base;
      const int edits = 1 + static_cast<int>(rng() % 3);
      for (int e = 0; e < edits && !text.empty(); ++e) {
        const std::size_t at = rng() % text.size();
        switch (rng() % 4) {
          case 0:
            text[at] = alphabet[rng() % alphabet.size()];
            break;
          case 1:
            text.erase(at, 1 + rng() % 8);
            break;
          case 2:
            text.insert(at, text.substr(rng() % text.size(), 1 + rng() % 8));
            break;
          default:
            text.resize(at);
            break;
        }
      }
      CAPTURE(text);
      try {
        const TriangleSoup s = read_surface_file(test::write_text(dir / name, text));
        REQUIRE_FALSE(s.triangles.empty());
        REQUIRE(all_points_referenced(s));
        for (const Vec3& p : s.points) REQUIRE(p.allFinite());
        ++read_ok;
      } catch (const InputError& e) {
        REQUIRE(std::string(e.what()).find('\n') == std::string::npos);  // one line
        ++rejected;
      }
    }
  }
  MESSAGE("mutated files: " << read_ok << " read, " << rejected << " rejected");
  CHECK(read_ok > 0);
  CHECK(rejected > 0);
}

TEST_CASE("read_surface: a concave polygon is triangulated in its plane, a repeated-vertex face is reported, a collapsed file says why") {
  // Issue 37, item 7. An L-shaped prism whose two ends are single concave hexagons: their fans
  // crossed each other (12 "self-intersecting" pairs the file does not contain).
  const test::TempDir dir("read_concave");
  const std::vector<std::array<double, 2>> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::string obj;
  for (const double z : {0.0, 1.0})
    for (const auto& p : l) obj += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(z) + "\n";
  obj += "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n";  // bottom (seen from below), top
  for (int i = 0; i < 6; ++i) {
    const int j = (i + 1) % 6;
    obj += "f " + std::to_string(i + 1) + " " + std::to_string(j + 1) + " " + std::to_string(j + 7) + " " + std::to_string(i + 7) + "\n";
  }
  obj += "f 1 1 2\n";  // a face with a repeated vertex: skipped by the reader, and said so
  const TriangleSoup s = read_surface_file(test::write_text(dir / "lprism.obj", obj));
  CHECK(s.triangles.size() == 2 * 4 + 6 * 2);
  REQUIRE(s.repairs.size() == 1);
  CHECK(s.repairs[0].find("dropped 1 face(s) with a repeated vertex") != std::string::npos);
  SurfaceCheckReport rep;
  const TriSurface checked = validate_surface(s, {}, &rep);  // self-intersections checked: none
  CHECK(rep.volume == doctest::Approx(3));
  CHECK(rep.repairs.front() == s.repairs.front());
  // Each end's triangles turn the end's way: their normals along -z (bottom) and +z (top).
  for (const auto& t : s.triangles) {
    const Vec3 n = (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]);
    if (std::abs(n.z()) > 0) CHECK(n.z() * (s.points[t[0]].z() - 0.5) > 0);
  }
  // A body at a scale single precision cannot hold: every facet collapses, and the error says so.
  const double tiny = 1e-40;
  const Vec3 a(0, 0, 0), b(tiny, 0, 0), c(0, tiny, 0), d(0, 0, tiny);
  CHECK_THROWS_WITH_AS(read_surface_file(test::write_text(dir / "tiny.stl", ascii_stl({{a, c, b}, {a, b, d}, {a, d, c}, {b, c, d}}))),
                       doctest::Contains("tiny.stl: no triangles: all 4 of the file's faces collapsed to a point or an edge as read"),
                       InputError);
}

}  // namespace plaf
