// SPDX-License-Identifier: MIT
// End-to-end runs of 3D surface configurations on bad and repaired inputs, generated here as STL
// files (an icosphere with holes, with stray pieces inside, with a vertex pushed through, turned
// inside out) or read from data/ (the ONERA M6 half wing): each bad input stops the run with its
// own one-line error (the last stderr line), exit code 1 and no output file; a repair is reported
// and the run goes on. And the 3D wall_power_law metric through the whole run: the surface meshed
// at its sizes along the wall.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "tests/gmsh_support.h"
#include "tests/surface3d/test_surfaces.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

namespace fs = std::filesystem;
using plaf::TriangleSoup;
using plaf::test::PlafResult;
using plaf::test::read_text;
using plaf::test::TempDir;
using plaf::test::write_text;
using plaf::test::last_line;

namespace {

PlafResult run_config(const TempDir& d, const std::string& yaml) {
  const fs::path cfg = write_text(d / "case.yaml", yaml);
  return plaf::test::run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
}


// A surface_file configuration; `file` is relative to the configuration's folder or absolute.
std::string surface(const std::string& file, const std::string& extra = "") {
  return "geometry:\n  type: surface_file\n  file: " + file + "\n" + extra +
         "metric: {type: uniform, h: 0.2}\nsurface: {iterations: 2}\norder: 2\n";
}

// An ASCII STL of the soup (the reader welds the corners back into shared points).
std::string ascii_stl(const TriangleSoup& s) {
  std::string out = "solid generated\n";
  char buf[160];
  for (const auto& t : s.triangles) {
    out += "facet normal 0 0 0\n outer loop\n";
    for (const int v : t) {
      const Eigen::Vector3d& p = s.points[static_cast<std::size_t>(v)];
      std::snprintf(buf, sizeof buf, "  vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
      out += buf;
    }
    out += " endloop\nendfacet\n";
  }
  return out + "endsolid generated\n";
}

// b's points scaled by `scale` about the origin, then moved by `shift`, appended to a.
void append(TriangleSoup& a, const TriangleSoup& b, double scale, const Eigen::Vector3d& shift) {
  const int base = static_cast<int>(a.points.size());
  for (const Eigen::Vector3d& p : b.points) a.points.push_back(scale * p + shift);
  for (const auto& t : b.triangles) a.triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

// The unit icosphere (m = 6, 720 triangles) without `holes` triangles that share no vertex: as
// many open boundary loops of three edges, none on a plane a config declares.
TriangleSoup sphere_with_holes(int holes) {
  TriangleSoup s = plaf::test::icosphere_soup(6);
  std::set<int> used;
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : s.triangles) {
    const bool free = !used.count(t[0]) && !used.count(t[1]) && !used.count(t[2]);
    if (holes > 0 && free) {
      used.insert(t.begin(), t.end());
      --holes;
    } else {
      kept.push_back(t);
    }
  }
  s.triangles = kept;
  return s;
}

// The unit icosphere with two small tetrahedra (edge 0.14) inside, on either side of the centre
// along z, as the stray inner pieces a scanned or exported body may carry.
TriangleSoup sphere_with_inner_pieces() {
  TriangleSoup s = plaf::test::icosphere_soup(6);
  TriangleSoup tet;
  tet.points = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  tet.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  append(s, tet, 0.05, {0, 0, 0.4});
  append(s, tet, 0.05, {0, 0, -0.4});
  return s;
}

// The number after "KEY": in the report's object that starts with "SECTION": { (required there).
double report_number(const std::string& report, const std::string& section, const std::string& key) {
  const double v = plaf::test::report_value(report, {section, key});
  REQUIRE(!std::isnan(v));
  return v;
}

}  // namespace

TEST_CASE("surface cli: each bad surface gives its own one-line error, exit code 1 and no output") {
  struct Case {
    const char* name;
    TriangleSoup soup;  // written to case.stl unless empty
    std::string yaml;
    const char* message;
  };
  // The inner pieces, and the sphere's first vertex (on the plane z = 0, away from the pieces)
  // pushed through the centre to 1.5 on the other side: its fan of triangles crosses the sphere.
  TriangleSoup pierced = sphere_with_inner_pieces();
  pierced.points[0] *= -1.5;
  const Case cases[] = {
      {"open scan", sphere_with_holes(5), surface("case.stl"), "5 open boundary loops not on a symmetry plane"},
      {"stray inner pieces", sphere_with_inner_pieces(), surface("case.stl", "  inner_components: error\n"),
       "2 components inside another"},
      {"self-intersections", pierced, surface("case.stl"),
       "self-intersecting triangle pair"},
      // (the way out named as it is written in YAML: issue 35's words that lead somewhere)
      {"self-intersections, the way out", pierced, surface("case.stl"), "set geometry.self_intersections: skip"},
      {"missing file", {}, surface("no_such_file.stl"), "no_such_file.stl"},
      {"wing section missing", {}, "geometry: {type: wing, file: nothing.dat}\nmetric: {type: uniform, h: 0.2}\n",
       "nothing.dat"},
  };
  for (const Case& c : cases) {
    INFO(std::string(c.name));
    const TempDir d("surface_cli");
    if (!c.soup.triangles.empty()) write_text(d / "case.stl", ascii_stl(c.soup));
    const PlafResult r = run_config(d, c.yaml);
    INFO(r.err);
    CHECK(r.code == 1);
    const std::string line = last_line(r.err);
    CHECK(line.rfind("plaf: error: ", 0) == 0);
    CHECK(line.find(c.message) != std::string::npos);
    CHECK(plaf::test::count_files(d / "out") == 0);
  }
  // A malformed STL names the file and the line.
  const std::string bad_stl = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n";
  const TempDir d("surface_cli_stl");
  write_text(d / "bad.stl", bad_stl);
  const PlafResult r = run_config(d, "geometry: {type: surface_file, file: bad.stl}\nmetric: {type: uniform, h: 0.2}\n");
  CHECK(r.code == 1);
  CHECK(last_line(r.err).find("bad.stl") != std::string::npos);
  CHECK(plaf::test::count_files(d / "out") == 0);
}

TEST_CASE("surface cli: the published ONERA M6 half wing without its symmetry plane is refused as open") {
  PLAF_NEEDS_PUBLISHED("surfaces/onera_m6_small.fmt");
  const TempDir d("surface_cli_m6_open");
  const PlafResult r = run_config(d, surface("data:surfaces/onera_m6_small.fmt"));
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(last_line(r.err).rfind("plaf: error: ", 0) == 0);
  CHECK(last_line(r.err).find("open boundary loop") != std::string::npos);
  CHECK(plaf::test::count_files(d / "out") == 0);
}

TEST_CASE("surface cli: an inward surface is repaired and meshed") {
  {
    // An ellipsoid (semi-axes 1.5, 1.2, 1) from the icosphere with m = 12, turned inside out.
    TriangleSoup inward = plaf::test::icosphere_soup(12);
    for (Eigen::Vector3d& p : inward.points) p = p.cwiseProduct(Eigen::Vector3d(1.5, 1.2, 1.0));
    for (auto& t : inward.triangles) std::swap(t[1], t[2]);
    const TempDir d("surface_cli_ellipsoid");
    write_text(d / "case.stl", ascii_stl(inward));
    const PlafResult r = run_config(d, surface("case.stl"));
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("repaired: ") != std::string::npos);
    CHECK(r.err.find("flipped 1 inward component") != std::string::npos);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report.find("\"euler_characteristic\": 2") != std::string::npos);
    CHECK(report.find("\"invalid\": 0") != std::string::npos);
  }
}

TEST_CASE("surface cli: a CAD tessellation's needle is repaired with a repair line, or kept with geometry.slivers: keep") {
  // The icosphere with a point 1e-4 along one edge from its end, both faces on the edge split
  // there: two needles, as a CAD tessellation makes where a finely sampled curve meets a coarse one.
  TriangleSoup s = plaf::test::icosphere_soup(6);
  const std::array<int, 3> t0 = s.triangles[0];
  const int a = t0[0], b = t0[1], c = t0[2];
  const int q = static_cast<int>(s.points.size());
  s.points.push_back(s.points[static_cast<std::size_t>(a)] +
                     1e-4 * (s.points[static_cast<std::size_t>(b)] - s.points[static_cast<std::size_t>(a)]));
  std::vector<std::array<int, 3>> tris;
  for (const auto& t : s.triangles) {
    if (t == t0) {
      tris.push_back({a, q, c});
      tris.push_back({q, b, c});
      continue;
    }
    bool split = false;
    for (int k = 0; k < 3 && !split; ++k)
      if (t[static_cast<std::size_t>(k)] == b && t[static_cast<std::size_t>((k + 1) % 3)] == a) {
        const int d = t[static_cast<std::size_t>((k + 2) % 3)];
        tris.push_back({b, q, d});
        tris.push_back({q, a, d});
        split = true;
      }
    if (!split) tris.push_back(t);
  }
  s.triangles = tris;
  {
    const TempDir d("surface_cli_needle");
    write_text(d / "case.stl", ascii_stl(s));
    const PlafResult r = run_config(d, surface("case.stl"));
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("2 sliver triangles") != std::string::npos);
    CHECK(r.err.find("1 short edge collapsed, 0 long edges flipped, each moving the surface by at most ") != std::string::npos);
    CHECK(r.err.find(", 0 left") != std::string::npos);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report_number(report, "input", "slivers") == 2);
    CHECK(report_number(report, "input", "slivers_left") == 0);
  }
  {
    const TempDir d("surface_cli_needle_kept");
    write_text(d / "case.stl", ascii_stl(s));
    const PlafResult r = run_config(d, surface("case.stl", "  slivers: keep\n"));
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("sliver triangles") == std::string::npos);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report_number(report, "input", "slivers") == 2);  // (counted, kept)
    CHECK(report_number(report, "input", "slivers_left") == 2);
  }
  const TempDir d("surface_cli_needle_bad_key");
  write_text(d / "case.stl", ascii_stl(s));
  const PlafResult r = run_config(d, surface("case.stl", "  slivers: mend\n"));
  CHECK(r.code == 1);
  CHECK(last_line(r.err).find("geometry.slivers") != std::string::npos);
}

TEST_CASE("surface cli: the published ONERA M6 half wing on its plane is tagged symmetry") {
  PLAF_NEEDS_PUBLISHED("surfaces/onera_m6_small.fmt");
  {
    const TempDir d("surface_cli_m6");
    // At h = 0.2 (a quarter of the chord) the surface cannot follow the wing within the default
    // fidelity tolerance (1e-3 of the diagonal; measured: 0.031); this case checks the repairs and
    // the tags, and bounds the distance at 0.05.
    std::string config = surface("data:surfaces/onera_m6_small.fmt", "  symmetry_planes: [{normal: [0, 0, 1]}]\n");
    config.replace(config.find("surface: {iterations: 2}"), 24, "surface: {iterations: 2, fidelity_tol: 0.05}");
    const PlafResult r = run_config(d, config);
    INFO(r.err);
    CHECK(r.code == 0);
    const std::string msh = read_text(d / "out" / "case.msh");
    CHECK(msh.find("\"symmetry\"") != std::string::npos);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report.find("\"euler_characteristic\": 1") != std::string::npos);  // a disc: the root is open
  }
}

TEST_CASE("surface cli: a curvature size not below the metric's stops the run before anything is written") {
  const TempDir d("surface_cli_hmin");
  const PlafResult r = run_config(d, "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.1}\n"
                                 "surface: {curvature_factor: 0.3, curvature_h_min: 0.2}\n");
  CHECK(r.code == 1);
  CHECK(last_line(r.err).find("surface.curvature_h_min: 0.2") != std::string::npos);
  CHECK(last_line(r.err).find("must be smaller than the metric's smallest size 0.1") != std::string::npos);
  CHECK(plaf::test::count_files(d / "out") == 0);
}

TEST_CASE("surface cli: gradation is reported when curvature sizes are on, and a beta not above 1 is refused") {
  {
    const TempDir d("surface_cli_gradation_bad");
    const PlafResult r = run_config(d, "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.3}\n"
                                   "surface: {curvature_factor: 0.3, gradation: 0.8}\n");
    CHECK(r.code == 1);
    CHECK(last_line(r.err).find("surface.gradation") != std::string::npos);
    CHECK(last_line(r.err).find("0.8 is outside 0 or (1, 100]") != std::string::npos);
    CHECK(plaf::test::count_files(d / "out") == 0);
  }
  {
    // An ellipsoid's tips ask for finer sizes than its flanks: the H-correction spreads them.
    const TempDir d("surface_cli_gradation");
    const PlafResult r = run_config(d, "geometry: {type: ellipsoid, semi_axes: [3, 1, 1]}\n"
                                   "metric: {type: uniform, h: 0.5}\nsurface: {curvature_factor: 0.3}\n");
    REQUIRE(r.code == 0);
    const std::string report = read_text(d / "out" / "case.report.json");
    const std::size_t at = report.find("\"corrected_points\": ");
    REQUIRE(at != std::string::npos);
    CHECK(std::strtod(report.c_str() + at + 20, nullptr) > 0);
  }
}

TEST_CASE("surface cli: a wall_power_law metric meshes the surface at its sizes along the wall") {
  // The number after "key": at or after `from` in the report.
  const auto number = [](const std::string& json, const std::string& key, std::size_t from) {
    const std::size_t at = json.find("\"" + key + "\": ", from);
    return at == std::string::npos ? -1.0 : std::strtod(json.c_str() + at + key.size() + 4, nullptr);
  };
  // The unit sphere at h_wall_max = 0.2: its area 4 pi over an equilateral triangle's
  // sqrt(3)/4 h^2 is 726 triangles. In the full metric, the normal size h0 = 1e-3 would ask for
  // chords of sqrt(2 R h0) = 0.045, some 14000 triangles (wall_metric_3d.h).
  const TempDir d("surface_cli_wall");
  const PlafResult r =
      run_config(d, "geometry: {type: sphere}\nmetric: {type: wall_power_law, h0: 1e-3, h_wall_max: 0.2, h_max: 1}\n");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string report = read_text(d / "out" / "case.report.json");
  const std::size_t surface = report.find("\"surface\": {");
  const double triangles = number(report, "triangles", surface);
  CHECK(triangles >= 726 / 2);
  CHECK(triangles <= 726 * 2);
  CHECK(number(report, "area", surface) == doctest::Approx(4 * M_PI).epsilon(1e-4));
  CHECK(number(report, "unit_fraction", report.find("\"metric\": {")) >= 0.9);  // in the sizes along the wall
  // With the surface stage's curvature sizes (intersected with the sizes along the wall), and on a
  // body with ridges and corners.
  for (const char* yaml : {"geometry: {type: ellipsoid, semi_axes: [1.5, 1, 0.4]}\n"
                           "metric: {type: wall_power_law, h0: 1e-5, h_wall_max: 0.2}\n"
                           "surface: {curvature_factor: 0.5}\n",
                           "geometry: {type: box}\nmetric: {type: wall_power_law, h0: 1e-4, h_wall_max: 0.25}\n"}) {
    const TempDir e("surface_cli_wall_more");
    const PlafResult s = run_config(e, yaml);
    INFO(yaml << s.err);
    CHECK(s.code == 0);
  }
}

TEST_CASE("surface cli: on the wall the sizes along it are h_wall_max: the E387 wing's surface as at a uniform size") {
  // The shipped wing (uniform h = 0.08, whose initial triangulation is sized at its root's leading
  // edge, on the wall) meshed with wall_power_law and h_wall_max = 0.08 writes the same file. Its
  // section is data:airfoils/e387.dat, found from any folder.
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  std::string wing = read_text(std::string(PLAF_CONFIGS) + "/wing_symmetry_surface.yaml");
  const std::string uniform = "metric:\n  type: uniform\n  h: 0.08\n";
  REQUIRE(wing.find("file: data:airfoils/e387.dat") != std::string::npos);
  REQUIRE(wing.find(uniform) != std::string::npos);
  std::string walled = wing;
  walled.replace(wing.find(uniform), uniform.size(),
                 "metric:\n  type: wall_power_law\n  h0: 1e-5\n  h_wall_max: 0.08\n");
  const TempDir e("surface_cli_wall_wing");
  for (const auto& [name, yaml] : {std::pair{"uniform", wing}, std::pair{"wall", walled}}) {
    const fs::path cfg = write_text(e / (std::string(name) + ".yaml"), yaml);
    const PlafResult s = plaf::test::run_plaf("run " + cfg.string() + " --out " + (e / name).string(), e);
    INFO(s.err);
    REQUIRE(s.code == 0);
  }
  CHECK(read_text(e / "uniform" / "wing_symmetry_surface.msh") == read_text(e / "wall" / "wing_symmetry_surface.msh"));
}

// A body of revolution about z: a cylinder of radius 1 from z = 0 to 2, then a cone to radius 0.75
// at z = 3 (a crease of 14 degrees at z = 2, under the 30-degree ridge angle), flat caps.
TriangleSoup creased_body(int sectors) {
  std::vector<std::array<double, 2>> profile = {{0, 0}, {1, 0}};
  for (int k = 1; k <= 20; ++k) profile.push_back({1, 0.1 * k});
  for (int k = 1; k <= 10; ++k) profile.push_back({1 - 0.025 * k, 2 + 0.1 * k});
  profile.push_back({0, 3});
  TriangleSoup s;
  std::vector<std::vector<int>> ring;
  for (const auto& [r, z] : profile) {
    ring.emplace_back();
    for (int j = 0; j < (r == 0 ? 1 : sectors); ++j) {
      const double a = 2 * M_PI * j / sectors;
      ring.back().push_back(static_cast<int>(s.points.size()));
      s.points.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
  }
  auto at = [&](std::size_t i, int j) { return ring[i][static_cast<std::size_t>(ring[i].size() == 1 ? 0 : j % sectors)]; };
  for (std::size_t i = 0; i + 1 < ring.size(); ++i)
    for (int j = 0; j < sectors; ++j) {
      const int a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
      if (ring[i].size() > 1) s.triangles.push_back({a, b, ring[i + 1].size() > 1 ? c : d});
      if (ring[i + 1].size() > 1) s.triangles.push_back({ring[i].size() > 1 ? a : b, c, d});
    }
  return s;
}

TEST_CASE("surface cli: a crease under the ridge angle is refined until the surface meets fidelity_tol") {
  // At order 1 and size 0.3 the flat triangles across the 14-degree crease leave the body by
  // 2.6e-3 of the diagonal (measured), over the tolerance 1e-3 that the curvature sizes meet
  // elsewhere: without the fidelity loop the run fails; with it one round brings it to 7.4e-4.
  const std::string yaml = "name: case\norder: 1\ngeometry: {type: surface_file, file: case.stl}\n"
                           "metric: {type: uniform, h: 0.3}\n";
  auto relative = [](const std::string& report) {
    const std::size_t at = report.find("\"relative\": ");
    return at == std::string::npos ? -1.0 : std::strtod(report.c_str() + at + 12, nullptr);
  };
  {
    const TempDir d("surface_cli_crease_off");
    write_text(d / "case.stl", ascii_stl(creased_body(96)));
    const PlafResult r = run_config(d, yaml + "surface: {iterations: 2, curvature_factor: 0.3, fidelity_rounds: 0}\n");
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find("the surface leaves the body") != std::string::npos);
  }
  const TempDir d("surface_cli_crease");
  write_text(d / "case.stl", ascii_stl(creased_body(96)));
  const PlafResult r = run_config(d, yaml + "surface: {iterations: 2, curvature_factor: 0.3}\n");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string report = read_text(d / "out" / "case.report.json");
  CHECK(report.find("\"fidelity_refinement\": [{\"spots\": ") != std::string::npos);
  const double rel = relative(report.substr(report.find("\"fidelity\": {")));
  MESSAGE("relative Hausdorff distance after the loop: " << rel);
  CHECK(rel > 0);
  CHECK(rel <= 1e-3);
  CHECK(report.find("\"relative_before\": ") != std::string::npos);
}

TEST_CASE("surface cli: columns that cannot grow stop locally, and below layers.min_coverage the run fails into NAME.failed/") {
  // Two unit spheres 0.005 apart, 8 layers from 0.005 growing by 1.2: where the gap runs out the
  // heights shrink to the floor (1/16) and, where even that crosses, the columns stop
  // (layer_core.h, step 3; measured: 62 of 2884 columns, 97.7 % coverage); the others grow their
  // 8 layers. That is with the proximity rule off; on (the default), the facing columns stop
  // before they meet, after their first layer, and every column reached its stop rule.
  TriangleSoup two = plaf::test::icosphere_soup(6);
  const TriangleSoup b = plaf::test::icosphere_soup(6);
  const int off = static_cast<int>(two.points.size());
  for (const Eigen::Vector3d& p : b.points) two.points.push_back(p + Eigen::Vector3d(2.005, 0, 0));
  for (auto t : b.triangles) two.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  const std::string yaml = "name: case\norder: 2\ngeometry: {type: surface_file, file: case.stl}\n"
                           "metric: {type: wall_power_law, h0: 0.005, growth: 1.2, h_wall_max: 0.1, h_max: 1}\n"
                           "surface: {iterations: 2, fidelity_tol: 0.01}\n";  // the coverage is the point here
  auto coverage = [](const std::string& report) {
    const std::size_t at = report.find("\"complete\": ");
    return at == std::string::npos ? -1.0 : std::strtod(report.c_str() + at + 12, nullptr);
  };
  // A run that must pass: its report.
  auto passing_report = [&](const char* dir, const std::string& layers) {
    const TempDir d(dir);
    write_text(d / "case.stl", ascii_stl(two));
    const PlafResult r = run_config(d, yaml + layers);
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(fs::exists(d / "out" / "case.msh"));
    const std::string report = read_text(d / "out" / "case.report.json");
    // The report's verdict is the exit code's (its first "ok" is the top level's).
    CHECK(report.substr(report.find("\"ok\": "), 10) == "\"ok\": true");
    CHECK(report.find("\"exit_code\": 0,\n  \"failures\": []") != std::string::npos);
    return report;
  };
  {  // the proximity rule: no failure, the stack that fits, and the report says where
    const std::string report = passing_report("surface_cli_cover_near", "layers: {max: 8}\n");
    CHECK(coverage(report) == 1);
    const std::size_t near = report.find("\"proximity\": ");
    REQUIRE(near != std::string::npos);
    const double share = std::strtod(report.c_str() + near + 13, nullptr);
    MESSAGE("wall share stopped by the proximity rule: " << share);
    CHECK(share > 0);
    CHECK(share < 0.05);
    CHECK(report.find("columns stopped where their stacks fill their share of the gap") != std::string::npos);
    CHECK(report.find("columns stopped where no valid cell could be grown") == std::string::npos);
  }
  {  // with a fill: the columns stopped in the gap keep the curved front they stopped on (their
     // faces grow no layer to straighten, two layers being too few for the gentle attenuation of
     // a layer with stops, grow_layers_3d.h, step 7), and the layers make those faces straight in
     // place where the cells under them stay valid (grow_layers_3d.cpp,
     // straighten_outer_front): here all of them, so the fill meets a linear front. Every cell
     // valid by plaf's certificate and Gmsh's.
    const TempDir d("surface_cli_cover_fill");
    write_text(d / "case.stl", ascii_stl(two));
    const PlafResult r = run_config(
        d, yaml + "layers: {max: 2, proximity: 0, stop_when_linear: true}\n"
                  "fill: {type: tetgen, farfield: {shape: box, size: [20, 20, 20], center: [1, 0, 0]}}\n");
    INFO(r.err);
    REQUIRE(r.code == 0);
    const std::string report = read_text(d / "out" / "case.report.json");
    const std::size_t at = report.find("\"curved_front_triangles\": ");
    REQUIRE(at != std::string::npos);
    const long curved = std::strtol(report.c_str() + at + 26, nullptr, 10);
    MESSAGE("outer front triangles still curved under the fill: " << curved);
    CHECK(curved == 0);
    const std::size_t made = report.find("curved triangles made straight in place");
    REQUIRE(made != std::string::npos);
    const std::size_t of = report.rfind("the layers' outer front: ", made);
    REQUIRE(of != std::string::npos);
    const long straight = std::strtol(report.c_str() + of + 25, nullptr, 10);
    MESSAGE(report.substr(of, made - of + 40));
    CHECK(straight > 0);
    CHECK(report.substr(of, made - of).find(" of " + std::to_string(straight) + " ") != std::string::npos);  // all of them
    if (plaf::test::gmsh_on_path()) {
      CHECK(plaf::test::gmsh_complaints(plaf::test::run_gmsh("out/case.msh -check", d).out).empty());
      const plaf::test::GmshJacobians gj = plaf::test::gmsh_jacobians("out/case.msh", d);
      MESSAGE("Gmsh: min J " << gj.min_j << ", worst minJ/maxJ " << gj.worst_ratio);
      CHECK(gj.min_j > 0);
      const std::size_t sj = report.find("\"scaled_jacobian\"");
      REQUIRE(sj != std::string::npos);
      const double plaf_min = std::strtod(report.c_str() + report.find("\"min\": ", sj) + 7, nullptr);
      CHECK(gj.worst_ratio == doctest::Approx(plaf_min).epsilon(0.01));
    } else {
      plaf::test::request_skip("gmsh is not on PATH: Gmsh's check of the curved tetrahedra not run");
    }
  }
  {  // the default min_coverage (0.95): the run passes, saying how much of the wall has its stack
    const std::string report = passing_report("surface_cli_cover_ok", "layers: {max: 8, proximity: 0}\n");
    CHECK(coverage(report) < 1);
    CHECK(coverage(report) >= 0.95);
    CHECK(report.find("columns stopped where no valid cell could be grown") != std::string::npos);
  }
  for (const bool keep : {false, true}) {  // all of it asked for: the run fails
    CAPTURE(keep);
    const TempDir d("surface_cli_cover_fail");
    write_text(d / "case.stl", ascii_stl(two));
    // A cut across the gap (output.cuts): a picture of its own, NAME.cut1.png, zoomed on the gap.
    const fs::path cfg = write_text(d / "case.yaml", yaml + "layers: {max: 8, min_coverage: 1, proximity: 0}\n"
                                                            "output: {cuts: [{point: [1.0025, 0, 0], normal: [0, 1, 0], "
                                                            "radius: 0.05, label: the gap}]}\n");
    const PlafResult r = plaf::test::run_plaf(
        "run " + cfg.string() + " --out " + (d / "out").string() + (keep ? " --keep-invalid" : ""), d);
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find("layers: the boundary layer asked for is NOT there") != std::string::npos);
    CHECK(r.err.find("layers.min_coverage 100.0 %") != std::string::npos);
    const fs::path failed = d / "out" / "case.failed";
    CHECK(fs::exists(failed / "case.report.json"));
    CHECK(fs::exists(failed / "case.png"));
    CHECK(fs::exists(failed / "case.cut1.png"));
    CHECK(fs::exists(failed / "case.msh") == keep);
    CHECK_FALSE(fs::exists(d / "out" / "case.msh"));
    const std::string report = read_text(failed / "case.report.json");
    // Every cell is valid, but the run failed: the report says so as the exit code does (it said
    // "ok": true, which a script reading it trusted).
    CHECK(report.substr(report.find("\"ok\": "), 11) == "\"ok\": false");
    CHECK(report.find("\"invalid\": 0,") != std::string::npos);
    CHECK(report.find("\"exit_code\": 2,\n  \"failures\": [\"layers: the boundary layer asked for is NOT there") !=
          std::string::npos);
    // The picture looks where the columns stopped: in the gap (x = 1.0025), at a stopped column's
    // top (within the 8 layers' 0.2 of a sphere).
    const std::size_t at = report.find("\"focus\": {\"point\": [");
    REQUIRE(at != std::string::npos);
    const char* c = report.c_str() + at + 20;
    char* end = nullptr;
    const double x = std::strtod(c, &end), y = std::strtod(end + 1, &end), z = std::strtod(end + 1, &end);
    CHECK(std::abs(x - 1.0025) < 0.02);
    CHECK(std::min(std::hypot(x, y, z), std::hypot(x - 2.005, y, z)) - 1 < 0.2);
    CHECK(report.find("largest region of columns stopped early") != std::string::npos);
    // The layers' report groups the stops by region, the gap's first.
    const std::string regions_key = "\"regions\": [{\"point\": [";
    const std::size_t regions = report.find(regions_key);
    REQUIRE(regions != std::string::npos);
    CHECK(std::abs(std::strtod(report.c_str() + regions + regions_key.size(), nullptr) - 1.0025) < 0.02);
  }
}

TEST_CASE("surface cli: a machined post (a CAD-tessellated cylinder with flat ends) grows every layer along its circular ridges") {
  // A cylinder of radius 0.5 and height 1 as CAD exports it: 64 strips the whole height, each end
  // a fan about its centre. The fans along its two circles leave sector strips 1e-4 as wide as
  // they are long; without the lean cap on the high-order tops (layer_tops_3d.cpp, tops()) 98
  // columns stopped along the circles in layers 8-9 at Q2 (99.3 % coverage; a Gmsh-meshed STL of
  // the same cylinder 94.6 %), and at Q3 with the Q2 cap 473 (97.1 %). Now every column reaches
  // its stop rule at Q2, all but 5 at Q3.
  constexpr int m = 64;
  TriangleSoup post;
  for (int i = 0; i < m; ++i)
    for (double z : {0.0, 1.0}) post.points.emplace_back(0.5 * std::cos(2 * M_PI * i / m), 0.5 * std::sin(2 * M_PI * i / m), z);
  const int bottom = static_cast<int>(post.points.size()), top = bottom + 1;
  post.points.emplace_back(0, 0, 0);
  post.points.emplace_back(0, 0, 1);
  for (int i = 0; i < m; ++i) {
    const int a0 = 2 * i, a1 = 2 * ((i + 1) % m), b0 = a0 + 1, b1 = a1 + 1;
    post.triangles.push_back({a0, a1, b1});
    post.triangles.push_back({a0, b1, b0});
    post.triangles.push_back({top, b0, b1});
    post.triangles.push_back({bottom, a1, a0});
  }
  for (const int q : {2, 3}) {
    CAPTURE(q);
    const TempDir d("surface_cli_post_q" + std::to_string(q));
    write_text(d / "case.stl", ascii_stl(post));
    const PlafResult r = run_config(d, "name: case\norder: " + std::to_string(q) +
                                           "\ngeometry: {type: surface_file, file: case.stl}\n"
                                           "metric: {type: wall_power_law, h0: 1e-5, growth: 1.2, h_wall_max: 0.04, h_max: 3}\n"
                                           "surface: {curvature_factor: 0.3}\nlayers: {max: 12}\noutput: {formats: [report]}\n");
    INFO(r.err);
    REQUIRE(r.code == 0);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report.find("\"ridge_fans\": {\"edges\": 0") == std::string::npos);
    const double columns = report_number(report, "coverage", "columns");
    const double complete = report_number(report, "coverage", "columns_complete");
    MESSAGE("Q" << q << ": " << complete << " of " << columns << " columns reached their stop rule");
    CHECK(columns > 1000);
    // Q2: every column; Q3: all but a few (4866 of 4871, one region; 4398 with the Q2 cap).
    CHECK(complete >= columns - (q == 2 ? 0 : std::floor(columns / 200)));
  }
}

TEST_CASE("surface cli: a flange with bores (Gmsh's OpenCASCADE tessellation) keeps its layers along its convex rims") {
  // A disk of radius 2 and thickness 0.4 with a hub (radius 0.8, to z = 1), a bore of 0.5 and six
  // bolt holes of 0.15, tessellated by Gmsh as a CAD user's STL. Around a convex rim a ray back
  // from a column's front can miss the column's own wall (it grazes the ridge) and meet the body's
  // far side: a rim column's ray met the hub 1.2 away, its stack counted 1.2 thick, and 74
  // columns along the rim stopped for proximity in layer 2 (every later layer then cut into
  // tetrahedra, 98.7 % coverage; at 40 layers 93.3 %). The proximity rule now takes the distance
  // back as at most twice the column's stack (grow_layers_3d.cpp, stop_point_room).
  if (!plaf::test::gmsh_on_path()) {
    plaf::test::request_skip("gmsh is not on PATH: the flange is tessellated by Gmsh");
    return;
  }
  const TempDir d("surface_cli_flange");
  write_text(d / "flange.geo",
             "SetFactory(\"OpenCASCADE\");\n"
             "Cylinder(1) = {0, 0, 0, 0, 0, 0.4, 2};\nCylinder(2) = {0, 0, 0, 0, 0, 1, 0.8};\n"
             "BooleanUnion(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};\n"
             "Cylinder(4) = {0, 0, -1, 0, 0, 3, 0.5};\n"
             "For k In {0:5}\n  Cylinder(10 + k) = {1.4 * Cos(k * Pi / 3), 1.4 * Sin(k * Pi / 3), -1, 0, 0, 3, 0.15};\nEndFor\n"
             "BooleanDifference{Volume{3}; Delete;}{Volume{4, 10:15}; Delete;}\n"
             "Mesh.MeshSizeFromCurvature = 20;\nMesh.MeshSizeMax = 0.1;\nMesh.MeshSizeMin = 0.002;\nMesh.Algorithm = 6;\n");
  const plaf::test::GmshRun g = plaf::test::run_gmsh("flange.geo -2 -format stl -o case.stl", d);
  INFO(g.out);
  REQUIRE(g.code == 0);
  const PlafResult r = run_config(d,
                                  "name: case\norder: 2\ngeometry: {type: surface_file, file: case.stl}\n"
                                  "metric: {type: wall_power_law, h0: 4e-5, growth: 1.2, h_wall_max: 0.16, h_max: 3}\n"
                                  "surface: {curvature_factor: 0.3}\nlayers: {max: 12}\noutput: {formats: [report]}\n");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string report = read_text(d / "out" / "case.report.json");
  const double complete = report_number(report, "coverage", "complete");
  MESSAGE("coverage " << complete);
  CHECK(complete > 0.995);
  // No column stops for proximity before the last layers (the bolt holes are 0.3 wide, the
  // stack of 12 layers 0.0016 thick). The first stops (measured in layers 10-12) are columns over a bolt
  // hole's rim fan at the top face, at the concave-focus limit between them (measured: focal room
  // 3.9e-5 where the hole leaves 0.118), not deep in a hole; that limit firing there is a known
  // weakness of the focal rule at fans (issue 30's closing note), not the ray-grazing fixed above.
  std::size_t earliest = 99, events = 0;
  for (std::size_t at = report.find("\"layer "); at != std::string::npos; at = report.find("\"layer ", at + 1)) {
    const std::size_t end = report.find('"', at + 1);
    ++events;
    if (report.substr(at, end - at).find("columns stopped where their stacks fill their share") == std::string::npos) continue;
    earliest = std::min(earliest, static_cast<std::size_t>(std::strtoul(report.c_str() + at + 7, nullptr, 10)));
  }
  REQUIRE(events > 0);  // the last layer's proximity stops at least (the events are read)
  MESSAGE("first layer with proximity stops: " << earliest);
  CHECK(earliest >= 10);
}

TEST_CASE("surface cli: a thin analytic body starts from a lattice sized by its largest extent, not its thickness") {
  // Issue 37, item 1: a box 1 x 1 x 0.001 was first triangulated at half its thickness, a
  // 2000 x 2000 lattice (16M triangles, 6 GB, minutes) for a final mesh of a few hundred nodes;
  // a wing of span 0.001 was refused, blaming an h of 0.00025 the configuration never set.
  struct Case {
    std::string label, geometry;
  };
  for (const Case& c : {Case{"flat box", "{type: box, lo: [0, 0, 0], hi: [1, 1, 0.001]}"},
                        Case{"thin box", "{type: box, lo: [0, 0, 0], hi: [1, 0.002, 1]}"},
                        Case{"short wing", "{type: wing, naca: \"0012\", chord: 1, span: 0.001}"}}) {
    CAPTURE(c.label);
    const TempDir d("surface_cli_thin");
    const PlafResult r = run_config(d, "geometry: " + c.geometry + "\nmetric: {type: uniform, h: 0.1}\norder: 2\n");
    REQUIRE(r.code == 0);
    const std::string report = read_text(d / "out" / "case.report.json");
    const double first = report_number(report, "surface", "input_triangles");
    CHECK(first > 0);
    CHECK(first < 2e4);
    CHECK(report_number(report, "cells", "invalid") == 0);
  }
}
