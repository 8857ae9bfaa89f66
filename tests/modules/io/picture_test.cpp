// SPDX-License-Identifier: MIT
#include "modules/io/picture.h"
#include "modules/io/picture3d.h"
#include "modules/io/chart.h"

#include <cairo.h>
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "modules/mesh/annulus.h"
#include "modules/base/error.h"
#include "tests/modules/mesh/spherical_shell.h"
#include "tests/modules/mesh/structured_mesh.h"
#include "tests/test_support.h"

using namespace plaf;
using test::TempDir;
namespace fs = std::filesystem;

namespace {

struct Rgb {
  int r, g, b;
};

// A PNG read back through cairo.
struct Image {
  int width = 0, height = 0;
  std::vector<Rgb> pixels;
  explicit Image(const fs::path& path) {
    cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
    const bool ok = cairo_surface_status(s) == CAIRO_STATUS_SUCCESS;
    if (ok) {
      width = cairo_image_surface_get_width(s);
      height = cairo_image_surface_get_height(s);
      const int stride = cairo_image_surface_get_stride(s);
      const unsigned char* data = cairo_image_surface_get_data(s);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          // RGB24 and ARGB32 pixels are native-endian 32-bit words 0xAARRGGBB.
          std::uint32_t p = 0;
          std::memcpy(&p, data + y * stride + 4 * x, 4);
          pixels.push_back(
              {static_cast<int>((p >> 16) & 0xff), static_cast<int>((p >> 8) & 0xff), static_cast<int>(p & 0xff)});
        }
    }
    cairo_surface_destroy(s);
    REQUIRE(ok);
  }
  Rgb at(int x, int y) const { return pixels[static_cast<std::size_t>(y * width + x)]; }
};

// The colour classes of picture.h: invalid red, straight light blue, curved light orange, and
// the white background.
bool red(const Rgb& c) {
  return c.r > 200 && c.g < 80 && c.b < 80;
}
bool light_blue(const Rgb& c) {
  return c.r > 150 && c.g > 150 && c.b > c.r + 20 && c.b > 200;
}
bool light_orange(const Rgb& c) {
  return c.r > 200 && c.g > c.b && c.r > c.b + 40;
}
bool white(const Rgb& c) {
  return c.r == 255 && c.g == 255 && c.b == 255;
}

std::string show(const Rgb& c) {
  return "rgb(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ")";
}

}  // namespace

TEST_CASE("picture: the invalid cell is red and straight cells light blue, in an image of the asked size") {
  // Three unit squares in a 300 x 200 picture. The view centres the bounding box [0,3] x [0,1]
  // and scales it uniformly to fit with a small margin: scale s = 100 px per unit less the
  // margin. The picture centre (150, 100) is then model (1.5, 0.5), the centre of cell 1, and
  // model (0.5, 0.5) and (2.5, 0.5) are at (150 -+ s, 100): x = 60 and 240 lie inside cells 0 and
  // 2 for any s in (64, 176), and (150, 10) is above the mesh (its top is at 100 - s/2).
  TempDir dir("picture_cells");
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    const auto s = plaf::test::quad_grid(3, 1, q);
    PictureOptions options;
    options.width = 300;
    options.height = 200;
    const fs::path path = dir.path / ("cells_Q" + std::to_string(q) + ".png");
    write_png(s.mesh, {1, 0, 1}, path, options);
    const Image image(path);
    CHECK(image.width == 300);
    CHECK(image.height == 200);
    CHECK_MESSAGE(red(image.at(150, 100)), show(image.at(150, 100)));
    CHECK_MESSAGE(light_blue(image.at(60, 100)), show(image.at(60, 100)));
    CHECK_MESSAGE(light_blue(image.at(240, 100)), show(image.at(240, 100)));
    CHECK_MESSAGE(white(image.at(150, 10)), show(image.at(150, 10)));

    // All valid (an empty flag list means all valid): no red anywhere.
    write_png(s.mesh, {}, path, options);
    const Image all_valid(path);
    CHECK(light_blue(all_valid.at(150, 100)));
    bool any_red = false;
    for (const Rgb& c : all_valid.pixels) any_red = any_red || red(c);
    CHECK_FALSE(any_red);
  }
}

TEST_CASE("picture: curved annulus cells are light orange, the same cells at Q = 1 are straight") {
  // A quarter annulus r in [1, 2] with size 0.8: the mid-radius arc 1.5 pi/2 = 2.36 measures 2.9,
  // rounded to 3 cells of 30 degrees; the radial line measures 1.25, rounded to 1 (annulus.h).
  // The bounding box [0, 2]^2 is centred in the square picture, so its centre pixel shows model
  // (1, 1): radius sqrt 2 and angle 45 degrees, inside the middle cell, far from its edges.
  AnnulusParams params;
  params.angle_deg = 90;
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.8));
  TempDir dir("picture_annulus");
  for (int q = 1; q <= max_order; ++q) {
    INFO("Q=", q);
    const HybridMesh<2> mesh = mesh_annulus(params, q, metric);
    REQUIRE(mesh.num_cells() == 3);
    const CellBlock& b = mesh.cells[0];
    for (std::size_t i = 0; i < b.size(); ++i) CHECK(is_curved(mesh, b, i) == (q > 1));
    PictureOptions options;
    options.width = options.height = 240;
    const fs::path path = dir.path / "annulus.png";
    write_png(mesh, {}, path, options);
    const Image image(path);
    const Rgb c = image.at(120, 120);
    CHECK_MESSAGE((q > 1 ? light_orange(c) : light_blue(c)), show(c));
  }
}

TEST_CASE("picture: is_curved is false for affine cells of every order, scale 1e-8 .. 1e8 and position") {
  // Affine and bilinear cells: every node on its order-1 position, up to rounding of the node
  // coordinates themselves (a relative 1e-16 of their magnitude, which may exceed the cell).
  Eigen::Matrix2d a;
  a << 1.0, 0.4, -0.3, 0.7;
  for (int q = 1; q <= max_order; ++q)
    for (const CellType t : {CellType::Triangle, CellType::Quadrilateral})
      for (const double scale : {1e-8, 1e-3, 1.0, 1e3, 1e8})
        for (const double offset : {0.0, 10.0, 1e6}) {
          INFO(std::string(cell_name(t)), " Q=", q, " scale=", scale, " offset/scale=", offset);
          const LagrangeElement& e = lagrange_element(t, q);
          HybridMesh<2> m;
          CellBlock& b = m.block(t, q);
          for (int i = 0; i < e.size(); ++i) {
            const auto r = e.ref_node(i);
            Eigen::Vector2d x = a * Eigen::Vector2d(r[0], r[1]);
            if (t == CellType::Quadrilateral) x[1] += 0.5 * r[0] * r[1];  // bilinear, not affine
            m.nodes.push_back(scale * (x + Eigen::Vector2d(offset, -0.7 * offset)));
            b.connectivity.push_back(i);
          }
          CHECK_FALSE(is_curved(m, b, 0));
          if (q == 1) continue;
          // One node moved by 1e-6 of the cell size is curved.
          m.nodes.back() += Eigen::Vector2d(0, 1e-6 * scale);
          CHECK(is_curved(m, b, 0));
        }
}

TEST_CASE("picture: zoom panels keep the image size and show the boxed region") {
  // Two zoom boxes, each well inside one cell: every panel pixel away from its frame and label
  // shows that cell's colour. The panels lie side by side below the main view, so the pixels
  // (w/4, h - 8) and (3w/4, h - 8) are in panels 1 and 2.
  const auto s = plaf::test::quad_grid(3, 1, 2);
  TempDir dir("picture_zoom");
  PictureOptions options;
  options.width = 400;
  options.height = 300;
  options.zooms = {ZoomBox{"bad cell", 1.4, 1.6, 0.4, 0.6}, ZoomBox{"good cell", 0.45, 0.55, 0.45, 0.55}};
  options.title = "zoomed";
  const fs::path path = dir.path / "zoom.png";
  write_png(s.mesh, {1, 0, 1}, path, options);
  const Image image(path);
  CHECK(image.width == 400);
  CHECK(image.height == 300);
  CHECK_MESSAGE(red(image.at(100, 292)), show(image.at(100, 292)));
  CHECK_MESSAGE(light_blue(image.at(300, 292)), show(image.at(300, 292)));
}

TEST_CASE("picture: an unwritable path or a wrong flag count throws plaf::Error and leaves no file") {
  const auto s = plaf::test::quad_grid(2, 2, 2);
  TempDir dir("picture_unwritable");
  PictureOptions options;
  options.width = 64;
  options.height = 48;
  // Parent missing; parent a regular file; target an existing directory (refused at the rename,
  // even for root).
  std::ofstream(dir.path / "plain").put('x');
  fs::create_directory(dir.path / "taken");
  for (const fs::path& p : {dir.path / "missing" / "a.png", dir.path / "plain" / "a.png", dir.path / "taken"}) {
    INFO(p.string());
    CHECK_THROWS_AS(write_png(s.mesh, {}, p, options), Error);
  }
  CHECK_FALSE(fs::exists(dir.path / "missing"));
  CHECK(fs::is_directory(dir.path / "taken"));
  // Wrong number of validity flags (4 cells).
  for (const std::vector<std::uint8_t>& flags : {std::vector<std::uint8_t>{1, 1, 1}, std::vector<std::uint8_t>(5, 1)})
    CHECK_THROWS_AS(write_png(s.mesh, flags, dir.path / "flags.png", options), Error);
  auto entries = dir.entries();
  std::sort(entries.begin(), entries.end());
  CHECK(entries == std::vector<std::string>{"plain", "taken"});
}

// 3D pictures (picture3d.h) of the curved spherical shell (tests/modules/mesh/spherical_shell.h).
TEST_CASE("picture 3D: the half shell's symmetry plane is the default cut, drawn filled, the outer front shaded") {
  plaf::test::ShellOptions o;
  o.base = plaf::test::ShellBase::Octahedron;
  o.half = true;
  o.order = 2;
  const plaf::test::SphericalShell s = plaf::test::spherical_shell(o);
  Eigen::Vector3d point, normal;
  default_cut(s.mesh, point, normal);
  CHECK(std::abs(point.z()) < 1e-12);
  CHECK(std::abs(std::abs(normal.z()) - 1) < 1e-12);
  TempDir dir("picture3d_half");
  Picture3Options po;
  po.width = 400;
  po.height = 300;
  po.cut_point = point;
  po.cut_normal = normal;
  // One invalid cell: its facet on the plane is red. The cut panel is the left 11/20.
  std::vector<std::uint8_t> valid(s.mesh.num_cells(), 1);
  const fs::path path = dir.path / "half.png";
  write_png(s.mesh, valid, path, po);
  const Image good(path);
  CHECK(good.width == 400);
  CHECK(good.height == 300);
  std::size_t orange = 0, blue_shaded = 0, reds = 0;
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 400; ++x) {
      const Rgb c = good.at(x, y);
      if (x < 220 && light_orange(c)) ++orange;  // the shell's curved side faces on the plane
      if (x >= 220 && !white(c) && c.b > c.r + 20) ++blue_shaded;
      reds += red(c) ? 1 : 0;
    }
  CHECK(orange > 100);
  CHECK(blue_shaded > 1000);
  CHECK(reds == 0);
  valid.assign(valid.size(), 0);
  write_png(s.mesh, valid, path, po);
  const Image bad(path);
  std::size_t red_cut = 0;
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 220; ++x) red_cut += red(bad.at(x, y)) ? 1 : 0;
  CHECK(red_cut > 100);
}

TEST_CASE("picture 3D: a plane across the closed shell cuts its cells into lines, bad flags throw, no file") {
  plaf::test::ShellOptions o;
  const plaf::test::SphericalShell s = plaf::test::spherical_shell(o);
  Eigen::Vector3d point, normal;
  default_cut(s.mesh, point, normal);  // no symmetry plane: the bounding box's mid-plane
  CHECK(point.norm() < 1e-9);
  TempDir dir("picture3d_closed");
  Picture3Options po;
  po.width = 400;
  po.height = 300;
  po.cut_point = point;
  po.cut_normal = normal;
  po.zooms = {{"wall", 0.9, 1.4, -0.25, 0.25}};
  const fs::path path = dir.path / "closed.png";
  write_png(s.mesh, {}, path, po);
  const Image image(path);
  // Dark cut lines on the left, both in the main panel and in the zoom (the lower third).
  std::size_t dark_main = 0, dark_zoom = 0;
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 220; ++x) {
      const Rgb c = image.at(x, y);
      if (c.r < 100 && c.g < 100 && c.b < 120) (y < 200 ? dark_main : dark_zoom) += 1;
    }
  CHECK(dark_main > 100);
  CHECK(dark_zoom > 50);
  const fs::path bad = dir.path / "bad.png";
  CHECK_THROWS_AS(write_png(s.mesh, std::vector<std::uint8_t>(3, 1), bad, po), plaf::Error);
  CHECK_FALSE(fs::exists(bad));
}

TEST_CASE("picture 3D: columns that ended short colour the wall from yellow to red, in place of the outer front") {
  plaf::test::ShellOptions o;
  o.order = 2;
  const plaf::test::SphericalShell s = plaf::test::spherical_shell(o);
  TempDir dir("picture3d_coverage");
  Picture3Options po;
  po.width = 400;
  po.height = 300;
  default_cut(s.mesh, po.cut_point, po.cut_normal);
  po.layers = 4;
  // The wall's corner nodes, each a column's base.
  std::vector<NodeId> corners;
  for (const CellBlock& b : s.mesh.boundary)
    if (s.mesh.tags[static_cast<std::size_t>(b.tag)].kind == BoundaryKind::Wall)
      for (std::size_t i = 0; i < b.size(); ++i) corners.insert(corners.end(), b.cell(i), b.cell(i) + 3);
  REQUIRE_FALSE(corners.empty());
  // Count the shaded panel's (x >= 220) warm pixels (red to yellow: red high, blue low) and blue ones.
  auto panel = [&](const char* name) {
    const fs::path path = dir.path / name;
    write_png(s.mesh, {}, path, po);
    const Image image(path);
    std::array<std::size_t, 2> n{0, 0};
    for (int y = 40; y < 300; ++y)
      for (int x = 220; x < 400; ++x) {
        const Rgb c = image.at(x, y);
        if (white(c)) continue;
        if (c.r > 100 && c.r > c.b + 60) ++n[0];
        if (c.b > c.r + 20) ++n[1];
      }
    return n;
  };
  const std::array<std::size_t, 2> none = panel("none.png");  // the outer front, blue
  CHECK(none[0] == 0);
  CHECK(none[1] > 1000);
  // Every column ended in layer 1, its point a little above its wall node: all red.
  for (NodeId id : corners) po.short_columns.push_back({1.001 * s.mesh.nodes[static_cast<std::size_t>(id)], 1});
  const std::array<std::size_t, 2> all = panel("all.png");
  MESSAGE("warm, blue pixels: " << all[0] << ", " << all[1]);
  CHECK(all[0] > 1000);
  CHECK(all[1] == 0);
  // One column ended in layer 3 (2 of 4 layers): its facets orange, the rest of the wall blue.
  // (The column nearest the viewer, who looks along po.view: the smallest depth x . view.)
  const NodeId front = *std::min_element(corners.begin(), corners.end(), [&](NodeId a, NodeId b) {
    return s.mesh.nodes[static_cast<std::size_t>(a)].dot(po.view) < s.mesh.nodes[static_cast<std::size_t>(b)].dot(po.view);
  });
  po.short_columns = {{1.001 * s.mesh.nodes[static_cast<std::size_t>(front)], 3}};
  const std::array<std::size_t, 2> one = panel("one.png");
  MESSAGE("warm, blue pixels: " << one[0] << ", " << one[1]);
  CHECK(one[1] > 1000);
  CHECK(one[0] > 20);
  CHECK(one[0] < all[0] / 2);  // one corner of a coarse shell: its few facets
}

TEST_CASE("picture 3D: a cut that reaches a farfield is framed on the wall and its layers") {
  // The closed shell cut by z = 0 draws a ring of cut lines; one more tetrahedron 40 across
  // (a farfield's) crossing the plane widens the cut twentyfold, and the frame keeps the ring's
  // size: about as many dark pixels as without it (unframed, the ring would shrink to a dot).
  plaf::test::ShellOptions o;
  plaf::test::SphericalShell s = plaf::test::spherical_shell(o);
  TempDir dir("picture3d_frame");
  Picture3Options po;
  po.width = 400;
  po.height = 300;
  po.cut_point = Eigen::Vector3d::Zero();
  po.cut_normal = Eigen::Vector3d::UnitZ();
  auto dark = [&](const HybridMesh<3>& mesh, const char* name) {
    const fs::path path = dir.path / name;
    write_png(mesh, {}, path, po);
    const Image image(path);
    std::size_t n = 0;
    for (int y = 40; y < 300; ++y)
      for (int x = 0; x < 220; ++x) {
        const Rgb c = image.at(x, y);
        n += c.r < 100 && c.g < 100 && c.b < 120 ? 1 : 0;
      }
    return n;
  };
  const std::size_t alone = dark(s.mesh, "alone.png");
  HybridMesh<3> far = s.mesh;
  const NodeId base = static_cast<NodeId>(far.nodes.size());
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(-20, -20, -20), Eigen::Vector3d(20, -20, -20), Eigen::Vector3d(0, 20, -20),
                                   Eigen::Vector3d(0, 0, 20)})
    far.nodes.push_back(x);
  far.cells.push_back(CellBlock{CellType::Tetrahedron, 1, -1, {base, base + 1, base + 2, base + 3}});
  const std::size_t framed = dark(far, "far.png");
  MESSAGE("dark pixels of the ring: " << alone << " alone, " << framed << " with the farfield cell");
  CHECK(alone > 200);
  CHECK(framed > alone / 2);
}

TEST_CASE("chart: series drawn in their palette colours on linear and log axes, and side by side keeps both panels") {
  TempDir d("chart");
  std::vector<ChartSeries> series(2);
  series[0].label = "2D";
  series[0].x = {1, 2, 3, 4};
  series[0].y = {2.0, 1.0, 0.5, 0.0};
  series[1].label = "3D";
  series[1].dashed = true;
  series[1].color = 1;
  series[1].x = {1, 2, 3, 4};
  series[1].y = {4.0, NAN, 1.0, 0.0};  // a gap
  ChartOptions o;
  o.width = 900;
  o.height = 600;
  o.title = "clip";
  write_chart_png(series, d / "a.png", o);
  const Image a(d / "a.png");
  CHECK(a.width == 900);
  CHECK(a.height == 600);
  // The palette's first two colours (blue, orange) appear; most of the picture is white.
  int blue = 0, orange = 0, whites = 0;
  for (const Rgb& c : a.pixels) {
    blue += c.r < 60 && c.g > 100 && c.g < 140 && c.b > 160;
    orange += c.r > 240 && c.g > 110 && c.g < 150 && c.b < 40;
    whites += white(c);
  }
  CHECK(blue > 100);
  CHECK(orange > 100);
  CHECK(whites > a.width * a.height / 2);
  // A log axis leaves out what it cannot draw; nothing drawable is an error and no file.
  o.log_x = o.log_y = true;
  write_chart_png(series, d / "b.png", o);
  CHECK(Image(d / "b.png").width == 900);
  std::vector<ChartSeries> none(1);
  none[0].x = {1, 2};
  none[0].y = {0, -1};
  CHECK_THROWS_AS(write_chart_png(none, d / "c.png", o), Error);
  CHECK_FALSE(fs::exists(d / "c.png"));
  none[0].y = {1};
  CHECK_THROWS_AS(write_chart_png(none, d / "c.png", o), Error);
  // Side by side: the panels scaled to one height, next to each other under their labels.
  write_side_by_side_png({d / "a.png", d / "b.png"}, {"left", "right"}, "both", d / "ab.png", 300);
  const Image ab(d / "ab.png");
  CHECK(ab.width == 900);  // two 900 x 600 panels at height 300: 450 each
  CHECK(ab.height > 300);
  CHECK_THROWS_AS(write_side_by_side_png({d / "a.png", d / "missing.png"}, {}, "", d / "x.png"), Error);
  CHECK_FALSE(fs::exists(d / "x.png"));
}
