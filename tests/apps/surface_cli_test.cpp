// SPDX-License-Identifier: MIT
// End-to-end runs of 3D surface configurations on the shared data's bad and repaired inputs:
// each bad input stops the run with its own one-line error (the last stderr line), exit code 1
// and no output file; a repair is reported and the run goes on. And the 3D wall_power_law metric
// through the whole run: the surface meshed at its sizes along the wall.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/test_support.h"

namespace fs = std::filesystem;
using plaf::test::PlafResult;
using plaf::test::read_text;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

PlafResult run_config(const TempDir& d, const std::string& yaml) {
  const fs::path cfg = write_text(d / "case.yaml", yaml);
  return plaf::test::run_plaf("run " + cfg.string() + " --out " + (d / "out").string(), d);
}

std::string last_line(const std::string& text) {
  const std::size_t end = text.find_last_not_of('\n');
  if (end == std::string::npos) return "";
  const std::size_t begin = text.rfind('\n', end);
  return text.substr(begin == std::string::npos ? 0 : begin + 1, end - (begin == std::string::npos ? 0 : begin + 1) + 1);
}


const std::string data = std::string(PLAF_SHARED_DATA) + "/surfaces/";

std::string surface(const std::string& file, const std::string& extra = "") {
  return "geometry:\n  type: surface_file\n  file: " + data + file + "\n" + extra +
         "metric: {type: uniform, h: 0.2}\nsurface: {iterations: 2}\norder: 2\n";
}

}  // namespace

TEST_CASE("surface cli: each bad surface gives its own one-line error, exit code 1 and no output") {
  struct Case {
    const char* name;
    std::string yaml;
    const char* message;
  };
  const std::string bad_stl = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n";
  const Case cases[] = {
      {"open scan", surface("stanford_bunny.obj"), "5 open boundary loops not on a symmetry plane"},
      {"open half wing without its plane", surface("onera_m6_small.fmt"), "open boundary loop"},
      {"stray inner pieces", surface("orion_capsule_binary.stl"), "2 components inside another"},
      {"self-intersections", surface("orion_capsule_binary.stl", "  inner_components: drop\n"),
       "self-intersecting triangle pair"},
      {"missing file", surface("no_such_file.stl"), "no_such_file.stl"},
      {"wing section missing",
       "geometry: {type: wing, file: " + data + "nothing.dat}\nmetric: {type: uniform, h: 0.2}\n", "nothing.dat"},
  };
  for (const Case& c : cases) {
    INFO(std::string(c.name));
    const TempDir d("surface_cli");
    const PlafResult r = run_config(d, c.yaml);
    INFO(r.err);
    CHECK(r.code == 1);
    const std::string line = last_line(r.err);
    CHECK(line.rfind("plaf: error: ", 0) == 0);
    CHECK(line.find(c.message) != std::string::npos);
    CHECK(plaf::test::count_files(d / "out") == 0);
  }
  // A malformed STL names the file and the line.
  const TempDir d("surface_cli_stl");
  write_text(d / "bad.stl", bad_stl);
  const PlafResult r = run_config(d, "geometry: {type: surface_file, file: bad.stl}\nmetric: {type: uniform, h: 0.2}\n");
  CHECK(r.code == 1);
  CHECK(last_line(r.err).find("bad.stl") != std::string::npos);
  CHECK(plaf::test::count_files(d / "out") == 0);
}

TEST_CASE("surface cli: an inward surface is repaired and meshed, an open half wing on its plane is tagged symmetry") {
  {
    const TempDir d("surface_cli_ellipsoid");
    const PlafResult r = run_config(d, surface("ellipsoid_binary.stl"));
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("repaired: ") != std::string::npos);
    CHECK(r.err.find("flipped 1 inward component") != std::string::npos);
    const std::string report = read_text(d / "out" / "case.report.json");
    CHECK(report.find("\"euler_characteristic\": 2") != std::string::npos);
    CHECK(report.find("\"invalid\": 0") != std::string::npos);
  }
  {
    const TempDir d("surface_cli_m6");
    const PlafResult r = run_config(d, surface("onera_m6_small.fmt", "  symmetry_planes: [{normal: [0, 0, 1]}]\n"));
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
  // On the wall the sizes along it are h_wall_max: the shipped wing (uniform h = 0.08, whose
  // initial triangulation is sized at its root's leading edge, on the wall) meshed with
  // wall_power_law and h_wall_max = 0.08 writes the same file.
  std::string wing = read_text(std::string(PLAF_CONFIGS) + "/wing_symmetry_surface.yaml");
  const std::string section_file = "file: ../../shared/data/", uniform = "metric:\n  type: uniform\n  h: 0.08\n";
  REQUIRE(wing.find(section_file) != std::string::npos);
  REQUIRE(wing.find(uniform) != std::string::npos);
  wing.replace(wing.find(section_file), section_file.size(), "file: " + std::string(PLAF_SHARED_DATA) + "/");
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
