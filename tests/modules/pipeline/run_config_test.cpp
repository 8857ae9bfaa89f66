// SPDX-License-Identifier: MIT
#include "modules/pipeline/run_config.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/geometry2d.h"
#include "modules/pipeline/writers.h"
#include "modules/metric/metric_fields.h"
#include "modules/metric/wall_metric.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stage_report.h"
#include "surface3d/plugins.h"
#include "tests/test_support.h"

using namespace plaf;
using test::TempDir;
namespace fs = std::filesystem;

namespace {

const std::string one_body = "geometry:\n  type: airfoils\n  bodies:\n    - file: a.dat\n";

// A YAML text with one '^' before the character an error must point at: the text without the
// marker, and "name:line:col" of that character (1-based, as yaml-cpp's marks are reported).
struct Marked {
  std::string text, position;
};

Marked unmark(const std::string& marked, const std::string& name) {
  const std::size_t at = marked.find('^');
  REQUIRE_MESSAGE(at != std::string::npos, "no ^ marker in: ", marked);
  const std::size_t line_start = marked.rfind('\n', at);
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(marked.begin(), marked.begin() + at, '\n'));
  const std::size_t col = line_start == std::string::npos ? at + 1 : at - line_start;
  return {marked.substr(0, at) + marked.substr(at + 1), name + ":" + std::to_string(line) + ":" + std::to_string(col)};
}

std::string config_error(const std::string& text, const std::string& name = "t.yaml") {
  try {
    parse_run_config(text, name);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

// A section's keys as its plugin parses them, after the whole config was checked.
AirfoilsParams airfoils(const std::string& yaml, const std::string& name) {
  parse_run_config(yaml, name);
  return parse_airfoils_params(ConfigNode::load_string(yaml, name).child("geometry"));
}
Geometry3Params geometry3(const std::string& yaml) {
  const RunConfig c = parse_run_config(yaml, "t.yaml");
  return parse_geometry3_params(ConfigNode::load_string(yaml, "t.yaml").child("geometry"), c.geometry.type);
}
SurfaceParams surface(const std::string& yaml) {
  parse_run_config(yaml, "t.yaml");
  return parse_surface_params(ConfigNode::load_string(yaml, "t.yaml").child("surface"));
}
WallLawParams wall_law(const std::string& yaml) {
  parse_run_config(yaml, "t.yaml");
  return parse_wall_law_params(ConfigNode::load_string(yaml, "t.yaml").child("metric"), 2);
}
BackgroundParams background(const std::string& yaml) {
  parse_run_config(yaml, "t.yaml");
  return parse_background_params(ConfigNode::load_string(yaml, "t.yaml").child("metric"));
}

}  // namespace

TEST_CASE("run config: airfoil bodies with names, corners and the default tags wall, wall_2, ...") {
  const std::string yaml =
      "geometry:\n"
      "  type: airfoils\n"
      "  bodies:\n"
      "    - file: /data/slat.dat\n"
      "      corners: [[0.5, 0.125], [-1, 2e-3]]\n"
      "    - {file: /data/main.dat, name: main}\n"
      "    - {file: /data/flap.dat}\n"
      "  corner_angle_deg: 45\n";
  const RunConfig c = parse_run_config(yaml, "cases/high_lift.yaml");
  CHECK(c.name == "high_lift");  // the stem of the config's name
  CHECK(c.geometry.type == "airfoils");
  const AirfoilsParams a = airfoils(yaml, "cases/high_lift.yaml");
  REQUIRE(a.bodies.size() == 3);
  CHECK(a.bodies[0].file == "/data/slat.dat");
  CHECK(a.bodies[0].name == "wall");
  CHECK(a.bodies[0].corners == std::vector<std::array<double, 2>>{{0.5, 0.125}, {-1.0, 2e-3}});
  CHECK(a.bodies[1].name == "main");
  CHECK(a.bodies[1].corners.empty());
  CHECK(a.bodies[2].name == "wall_3");  // the default counts the body's position, named or not
  CHECK(a.corner_angle_deg == 45);
  // A string config resolves relative paths against the folder of its name.
  CHECK(airfoils(one_body, "cases/x.yaml").bodies[0].file == "cases/a.dat");
}

TEST_CASE("run config: farfield keys and their documented defaults") {
  // Defaults from the header of the plugin's options.
  const AirfoilsParams d = airfoils(one_body, "t.yaml");
  CHECK(d.corner_angle_deg == 30);
  CHECK(d.farfield.shape == "circle");
  CHECK(d.farfield.radius == 20);
  CHECK(d.farfield.size == std::array<double, 2>{40, 40});
  CHECK_FALSE(d.farfield.has_center);

  const AirfoilsParams r =
      airfoils(one_body + "  farfield: {shape: rectangle, size: [30, 12.5], center: [0.5, -1]}\n", "t.yaml");
  CHECK(r.farfield.shape == "rectangle");
  CHECK(r.farfield.size == std::array<double, 2>{30, 12.5});
  CHECK(r.farfield.has_center);
  CHECK(r.farfield.center == std::array<double, 2>{0.5, -1});
  const AirfoilsParams c = airfoils(one_body + "  farfield: {radius: 7.5}\n", "t.yaml");
  CHECK(c.farfield.shape == "circle");
  CHECK(c.farfield.radius == 7.5);
}

TEST_CASE("run config: wall_power_law keys, the exponential law's delta defaulting to h0") {
  // Defaults from the header of the plugin's options.
  const WallLawParams d = wall_law(one_body + "metric: {type: wall_power_law}\n");
  CHECK(d.h0 == 0.005);
  CHECK(d.growth == 1.2);
  CHECK_FALSE(d.exponential);
  CHECK(d.delta == d.h0);
  CHECK(d.h_max == 1);
  CHECK(d.h_wall_max == 0.05);
  CHECK(d.curvature_factor == 0.25);
  CHECK(d.h_corner == 0.01);

  const WallLawParams e = wall_law(one_body +
                                   "metric:\n  type: wall_power_law\n  h0: 2e-4\n  growth: 1.15\n"
                                   "  law: exponential\n  h_max: 3\n  h_wall_max: 0.02\n"
                                   "  curvature_factor: 0.4\n  h_corner: 0.002\n");
  CHECK(e.h0 == 2e-4);
  CHECK(e.growth == 1.15);
  CHECK(e.exponential);
  CHECK(e.delta == 2e-4);  // the given h0
  CHECK(e.h_max == 3);
  CHECK(e.h_wall_max == 0.02);
  CHECK(e.curvature_factor == 0.4);
  CHECK(e.h_corner == 0.002);
  CHECK(wall_law(one_body + "metric: {type: wall_power_law, law: exponential, delta: 0.03}\n").delta == 0.03);
  // h0 = h_max is allowed (a uniform normal size), h0 > h_max is not.
  CHECK(config_error(one_body + "metric: {type: wall_power_law, h0: 0.5, h_max: 0.5}\n") == "no error");
}

TEST_CASE("run config: background keys: the file is required and the mean is a choice") {
  const BackgroundParams b =
      background("metric: {type: background, file: /m/bg.mesh, sol: /m/bg.sol, mean: affine_invariant}\n");
  CHECK(b.file == "/m/bg.mesh");
  CHECK(b.sol == "/m/bg.sol");
  CHECK(b.mean == "affine_invariant");
  const BackgroundParams d = background("metric: {type: background, file: /m/bg.msh}\n");
  CHECK(d.sol.empty());
  CHECK(d.mean == "log_euclidean");
}

TEST_CASE("run config: output formats are the writer registry's names, zooms carry a label and a box") {
  // Every registered writer is accepted alone, all of them together in any order.
  const std::vector<std::string> names = writer_registry<2>().names();
  REQUIRE_FALSE(names.empty());
  std::string all;
  for (const std::string& n : names) {
    CHECK(parse_run_config("output: {formats: [" + n + "]}\n", "t.yaml").output.formats == std::vector<std::string>{n});
    all = n + (all.empty() ? "" : ", ") + all;
  }
  const OutputParams o = parse_run_config("output: {formats: [" + all + "]}\n", "t.yaml").output;
  CHECK(o.formats.size() == names.size());
  for (const std::string& n : names) CHECK(o.wants(n));
  // The default is every format the header lists, each of them a registered writer.
  const OutputParams d = parse_run_config("", "t.yaml").output;
  CHECK(d.formats == std::vector<std::string>{"msh", "vtu", "report", "png"});
  for (const std::string& f : d.formats) CHECK(std::find(names.begin(), names.end(), f) != names.end());
  CHECK(d.zooms.empty());

  const OutputParams z = parse_run_config(
                             "output:\n  zooms:\n    - {label: leading edge, box: [-0.05, 0.1, -0.06, 0.06]}\n"
                             "    - box: [0.9, 1.02, -0.5e-1, 4e-2]\n",
                             "t.yaml")
                             .output;
  REQUIRE(z.zooms.size() == 2);
  CHECK(z.zooms[0].label == "leading edge");
  CHECK(z.zooms[0].box == std::array<double, 4>{-0.05, 0.1, -0.06, 0.06});
  CHECK(z.zooms[1].label.empty());
  CHECK(z.zooms[1].box == std::array<double, 4>{0.9, 1.02, -0.05, 0.04});
}

TEST_CASE("run config: one bad value per key is a ConfigError naming file:line:col and the dotted key") {
  // '^' marks the character the message must point at: the value, the list item or the map.
  struct Case {
    const char* key;
    std::string yaml;
    std::string reason;
  };
  std::string writers;  // the registry's names, as the message lists them
  for (const std::string& n : writer_registry<2>().names()) writers += (writers.empty() ? "" : ", ") + n;
  const std::string g = "geometry: {type: airfoils, bodies: [{file: a.dat}], ";
  const std::string b = "geometry: {type: airfoils, bodies: [{file: a.dat, ";
  const std::string wall = one_body + "metric: {type: wall_power_law, ";
  const Case cases[] = {
      {"name", "name: ^a/b\n", "plain file name"},
      {"order", "order: ^0\n", "outside 1..4"},
      {"geometry.type", "geometry: {type: ^blob}\n", "unknown value 'blob'"},
      {"geometry.r_inner", "geometry: {type: annulus, r_inner: ^0}\n", "must be positive"},
      {"geometry.bodies", "geometry: {type: airfoils, bodies: ^[]}\n", "at least one body"},
      {"geometry.bodies", "geometry: ^{type: airfoils}\n", "at least one body"},
      {"geometry.bodies", "geometry: {type: airfoils, bodies: ^{file: a.dat}}\n", "list of maps"},
      {"geometry.bodies[1]", "geometry: {type: airfoils, bodies: [{file: a.dat}, ^{name: slat}]}\n",
       "file, naca or circle is required"},
      {"geometry.bodies[0].name", b + "name: ^[x]}]}\n", "expected a word"},
      {"geometry.bodies[0].name", b + "name: ^farfield}]}\n", "farfield"},
      {"geometry.bodies[0].corners", b + "corners: [[1, 2], ^[1]]}]}\n", "list of points"},
      {"geometry.bodies[0].corners", b + "corners: ^3}]}\n", "list of points"},
      {"geometry.corner_angle_deg", g + "corner_angle_deg: ^200}\n", "outside [0, 180]"},
      {"geometry.farfield", g + "farfield: ^[1]}\n", "expected a map"},
      {"geometry.farfield.shape", g + "farfield: {shape: ^oval}}\n", "unknown value 'oval' (known: circle, rectangle)"},
      {"geometry.farfield.radius", g + "farfield: {radius: ^0}}\n", "0 is outside (0, 5e11]"},
      {"geometry.farfield.size", g + "farfield: {size: ^[1]}}\n", "two numbers"},
      {"geometry.farfield.size", g + "farfield: {size: ^[30, -1]}}\n", "positive"},
      {"geometry.farfield.center", g + "farfield: {center: ^[1, 2, 3]}}\n", "two numbers"},
      {"metric.type", "metric: {type: ^magic}\n", "unknown 2D metric type 'magic'"},
      {"metric.h", "metric: {type: uniform, h: ^0}\n", "must be positive"},
      {"metric.sizes", "metric: {type: uniform, sizes: ^[0.1, 0.2, 0.3]}\n", "two sizes"},
      {"metric.sizes", "metric: {type: uniform, h: 1, sizes: ^[0.1, 0.2]}\n", "either h or sizes"},
      {"metric.h0", wall + "h0: ^-1}\n", "must be positive"},
      {"metric.h0", wall + "h_max: 0.001, h0: ^0.005}\n", "must not exceed h_max"},
      {"metric.growth", wall + "growth: ^1}\n", "1 is outside (1, 10]"},
      {"metric.growth", wall + "growth: ^11}\n", "outside"},
      {"metric.law", wall + "law: ^cubic}\n", "unknown value 'cubic' (known: linear, exponential)"},
      {"metric.delta", wall + "law: exponential, delta: ^0}\n", "must be positive"},
      {"metric.h_max", wall + "h_max: ^-2}\n", "must be positive"},
      {"metric.h_wall_max", wall + "h_wall_max: ^0}\n", "must be positive"},
      {"metric.curvature_factor", wall + "curvature_factor: ^-0.1}\n", "must be positive"},
      {"metric.h_corner", wall + "h_corner: ^abc}\n", "expected a number, got 'abc'"},
      {"metric", "metric: ^{type: background}\n", "file is required"},
      {"metric.mean", "metric: {type: background, file: a.msh, mean: ^median}\n",
       "unknown value 'median' (known: log_euclidean, affine_invariant)"},
      {"metric.sol", "metric: {type: background, file: a.mesh, sol: ^[a]}\n", "expected a word"},
      {"validity.rel_tol", "validity: {rel_tol: ^2}\n", "outside"},
      {"validity.max_depth", "validity: {max_depth: ^0}\n", "outside 1..20"},
      {"output.formats", "output: {formats: [msh, ^stl]}\n", "unknown value 'stl' (known: " + writers + ")"},
      {"output.formats", "output: {formats: ^msh}\n", "expected a list"},
      {"output.picture_width", "output: {picture_width: ^10}\n", "outside 64..16384"},
      {"output.picture_height", "output: {picture_height: ^1.5}\n", "expected an integer"},
      {"output.histogram_bins", "output: {histogram_bins: ^1}\n", "outside 2..1000"},
      {"output.zooms", "output: {zooms: ^{box: [0, 1, 0, 1]}}\n", "list of maps"},
      {"output.zooms[0].label", "output: {zooms: [{label: ^[a], box: [0, 1, 0, 1]}]}\n", "expected a word"},
      {"output.zooms[1].box", "output: {zooms: [{box: [0, 1, 0, 1]}, {box: ^[0, 1, 1, 0]}]}\n", "min < max"},
      {"output.zooms[0].box", "output: {zooms: [{box: ^[0, 1, 2]}]}\n", "x_min, x_max, y_min, y_max"},
      {"output.zooms[0].box", "output: {zooms: [^{label: a}]}\n", "x_min, x_max, y_min, y_max"},
      {"output.zooms[0].box", "output: {zooms: [{box: [0, ^one, 0, 1]}]}\n", "expected a number"},
  };
  for (const Case& k : cases) {
    const Marked m = unmark(k.yaml, "cases/bad.yaml");
    INFO(m.text);
    const std::string e = config_error(m.text, "cases/bad.yaml");
    INFO(e);
    CHECK(e.rfind(m.position + ": " + k.key + ": ", 0) == 0);
    CHECK(e.find(k.reason) != std::string::npos);
  }
}

TEST_CASE("run config: unknown keys are rejected, in list items and in the chosen plugin's section") {
  struct Case {
    const char* key;
    std::string yaml;
  };
  const Case cases[] = {
      {"colour", "^colour: red\n"},
      {"geometry.bodies[0].colour", "geometry: {type: airfoils, bodies: [{file: a.dat, ^colour: red}]}\n"},
      {"geometry.bodies[1].corner",
       "geometry:\n  type: airfoils\n  bodies:\n    - file: a.dat\n    - file: b.dat\n      ^corner: [[0, 0]]\n"},
      {"geometry.farfield.radious", "geometry: {type: airfoils, bodies: [{file: a.dat}], farfield: {^radious: 3}}\n"},
      // Keys of another plugin type are unknown in the chosen one's section.
      {"geometry.r_inner", "geometry: {type: airfoils, bodies: [{file: a.dat}], ^r_inner: 1}\n"},
      {"geometry.bodies", "geometry: {type: annulus, ^bodies: [{file: a.dat}]}\n"},
      {"metric.h", one_body + "metric: {type: wall_power_law, ^h: 0.1}\n"},
      {"metric.h0", "metric: {type: uniform, ^h0: 0.1}\n"},
      {"metric.file", "metric: {type: uniform, ^file: a.msh}\n"},
      {"output.zooms[0].colour", "output: {zooms: [{box: [0, 1, 0, 1], ^colour: red}]}\n"},
  };
  for (const Case& k : cases) {
    const Marked m = unmark(k.yaml, "u.yaml");
    INFO(m.text);
    const std::string e = config_error(m.text, "u.yaml");
    INFO(e);
    CHECK(e.rfind(m.position + ": unknown key '" + k.key + "'", 0) == 0);
  }
}

TEST_CASE("run config: load_run_config resolves paths relative to the config file's folder") {
  const TempDir d("run_config");
  fs::create_directories(d.path / "cases");
  const fs::path cfg = d.path / "cases" / "two_bodies.yaml";
  std::ofstream(cfg) << "geometry:\n  type: airfoils\n  bodies:\n    - file: ../data/main.dat\n"
                        "    - {file: /abs/flap.dat, name: flap}\n"
                        "metric: {type: background, file: bg/metric.mesh, sol: ./bg/metric.sol}\n";
  const RunConfig c = load_run_config(cfg);
  CHECK(c.file == cfg);
  CHECK(c.name == "two_bodies");
  const AirfoilsParams a = parse_airfoils_params(ConfigNode::load_file(cfg).child("geometry"));
  CHECK(a.bodies[0].file == (d.path / "data" / "main.dat").string());
  CHECK(a.bodies[1].file == "/abs/flap.dat");
  const BackgroundParams b = parse_background_params(ConfigNode::load_file(cfg).child("metric"));
  CHECK(b.file == (d.path / "cases" / "bg" / "metric.mesh").string());
  CHECK(b.sol == (d.path / "cases" / "bg" / "metric.sol").string());

  // Errors name the file as given.
  std::ofstream(d.path / "bad.yaml") << "order: 9\n";
  CHECK_THROWS_WITH_AS(load_run_config(d.path / "bad.yaml"),
                       ((d.path / "bad.yaml").string() + ":1:8: order: 9 is outside 1..4").c_str(), ConfigError);
  CHECK_THROWS_AS(load_run_config(d.path / "missing.yaml"), InputError);
}

TEST_CASE("run config: 3D geometries make a 3D run with its surface section, a 3D uniform metric, no png") {
  const std::string sphere = "geometry: {type: sphere, radius: 2, center: [1, 2, 3]}\n"
                             "metric: {type: uniform, h: 0.1}\n"
                             "surface: {ridge_angle_deg: 40, iterations: 5, curvature_factor: 0.3}\n";
  const RunConfig s = parse_run_config(sphere, "s.yaml");
  CHECK(s.dim == 3);
  CHECK(geometry3(sphere).radius == 2);
  CHECK(geometry3(sphere).center[2] == 3);
  const SurfaceParams sp = surface(sphere);
  CHECK(sp.ridge_angle_deg == 40);
  CHECK(sp.iterations == 5);
  CHECK(sp.curvature_factor == doctest::Approx(0.3));
  CHECK(sp.curvature_h_min == 0);
  CHECK(s.output.formats == std::vector<std::string>{"msh", "vtu", "report", "png"});
  CHECK_FALSE(s.output.has_cut);
  CHECK(s.output.cuts.empty());
  const RunConfig cuts = parse_run_config(sphere + "output: {cuts: [{point: [1, 2, 3], normal: [0, 1, 0], radius: 0.5, label: tip}, "
                                                   "{point: [0, 0, 0], normal: [0, 0, 1]}]}\n", "c.yaml");
  REQUIRE(cuts.output.cuts.size() == 2);
  CHECK(cuts.output.cuts[0].point[2] == 3);
  CHECK(cuts.output.cuts[0].normal[1] == 1);
  CHECK(cuts.output.cuts[0].radius == 0.5);
  CHECK(cuts.output.cuts[0].label == "tip");
  CHECK(cuts.output.cuts[1].radius == 0);

  const std::string wing = "geometry: {type: wing, file: e387.dat, span: 3, root: rounded, tip: symmetry}\n"
                           "metric: {type: uniform, sizes: [0.1, 0.2, 0.3]}\n";
  const RunConfig w = parse_run_config(wing, "w.yaml");
  CHECK(geometry3(wing).root == "rounded");
  CHECK(geometry3(wing).tip == "symmetry");
  CHECK(geometry3(wing).span == 3);
  CHECK(parse_uniform_metric(ConfigNode::load_string(wing, "w.yaml").child("metric"), 3).sizes.size() == 3);

  const Geometry3Params f = geometry3("geometry: {type: surface_file, file: m6.fmt, symmetry_planes: "
                                      "[{normal: [0, 0, 2], offset: 1}], inner_components: error}\n");
  REQUIRE(f.symmetry_planes.size() == 1);
  CHECK(f.symmetry_planes[0].normal[2] == doctest::Approx(1));
  CHECK(f.symmetry_planes[0].offset == doctest::Approx(0.5));  // normalised with the normal
  CHECK(!f.drop_inner_components);
  CHECK(geometry3("geometry: {type: surface_file, file: m6.fmt}\n").drop_inner_components);  // the default
  CHECK(f.check_self_intersections);

  // 2D runs are untouched.
  CHECK(parse_run_config(one_body, "a.yaml").dim == 2);
}

TEST_CASE("run config: 3D keys are checked like the 2D ones") {
  const auto err = [](const std::string& yaml) { return doctest::String(config_error(yaml).c_str()); };
  CHECK(err("geometry: {type: sphere, radius: -1}\n") ==
        doctest::Contains("geometry.radius"));
  CHECK(err("geometry: {type: box, lo: [0, 0, 0], hi: [1, 0, 1]}\n") ==
        doctest::Contains("must exceed lo"));
  CHECK(err("geometry: {type: sphere, center: [0, 0]}\n") == doctest::Contains("three numbers"));
  CHECK(err("geometry: {type: wing}\n") == doctest::Contains("a wing needs its section: file (an airfoil file) or naca"));
  CHECK(err("geometry: {type: wing, file: a.dat, tip: pointed}\n") == doctest::Contains("pointed"));
  CHECK(err("geometry: {type: surface_file}\n") == doctest::Contains("file is required"));
  CHECK(err("geometry: {type: surface_file, file: a.stl, symmetry_planes: [{normal: [0, 0, 0]}]}\n") ==
        doctest::Contains("must not be zero"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: background, file: a.msh}\n") == "no error");
  CHECK(err("geometry: {type: sphere}\nmetric: {type: background}\n") == doctest::Contains("file is required"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: background, file: a.msh, h: 1}\n") ==
        doctest::Contains("metric.h"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: wall_power_law, h0: 1e-5, h_wall_max: 0.1}\n") == "no error");
  CHECK(err("geometry: {type: sphere}\nmetric: {type: wall_power_law, curvature_factor: 0.3}\n") ==
        doctest::Contains("metric.curvature_factor: not a 3D wall_power_law key"));
  CHECK(err("geometry: {type: box}\nmetric: {type: wall_power_law, h_corner: 0.01}\n") ==
        doctest::Contains("metric.h_corner: not a 3D wall_power_law key"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: wall_power_law, growth: 1}\n") ==
        doctest::Contains("metric.growth: 1 is outside (1, 10]"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: uniform, sizes: [1, 2]}\n") ==
        doctest::Contains("three sizes"));
  CHECK(err("geometry: {type: sphere}\nmetric: {type: uniform, angle_deg: 3}\n") ==
        doctest::Contains("angle_deg"));
  CHECK(err("geometry: {type: sphere}\noutput: {cut: {normal: [0, 0, 0]}}\n") ==
        doctest::Contains("output.cut.normal: expected [x, y, z], not all zero"));
  CHECK(err("geometry: {type: sphere}\noutput: {view: [1, 2]}\n") == doctest::Contains("output.view: expected [x, y, z]"));
  CHECK(err("geometry: {type: sphere}\noutput: {cuts: [{point: [0, 0, 0]}]}\n") ==
        doctest::Contains("output.cuts[0]: a cut needs its point and normal"));
  CHECK(err("geometry: {type: sphere}\noutput: {cuts: [{point: [0, 0, 0], normal: [1, 0, 0], radius: -1}]}\n") ==
        doctest::Contains("output.cuts[0].radius: -1 is outside >= 0"));
  CHECK(err("geometry: {type: sphere}\noutput: {cuts: [{point: [0, 0, 0], normal: [1, 0, 0], zoom: 1}]}\n") ==
        doctest::Contains("output.cuts[0].zoom"));
  CHECK(err("output: {cuts: [{point: [0, 0, 0], normal: [1, 0, 0]}]}\n") == doctest::Contains("output.cuts"));  // 2D: unknown
  CHECK(err("geometry: {type: sphere}\noutput: {cut: {point: [0, 0, 0], nromal: [0, 0, 1]}}\n") ==
        doctest::Contains("nromal"));
  CHECK(err("output: {view: [1, 0, 0]}\n") == doctest::Contains("output.view"));  // 2D: unknown
  CHECK(err("geometry: {type: sphere}\nsurface: {ridge_angle: 3}\n") == doctest::Contains("ridge_angle"));
  CHECK(err(one_body + "surface: {iterations: 3}\n") == doctest::Contains("for 3D geometries"));
  CHECK(err("geometry: {type: sphere}\nlayers: {smooth_normals: true}\n") == "no error");
  CHECK(err("geometry: {type: sphere}\nlayers: {isotropic_stop: node}\n") == "no error");
  CHECK(err("geometry: {type: sphere}\nlayers: {isotropic_stop: nodes}\n") == doctest::Contains("layers.isotropic_stop"));
  CHECK(err("geometry: {type: sphere}\nfill: {}\n") == doctest::Contains("starts from the layers' outer front"));
  CHECK(err("geometry: {type: sphere}\nfill: {type: advancing_front}\n") == doctest::Contains("a 3D fill is type tetgen"));
  CHECK(err("geometry: {type: surface_file, file: a.stl, symmetry_planes: [{offset: 1}]}\n") ==
        doctest::Contains("normal is required"));
  CHECK(err("geometry: {type: wing, file: a.dat, corner_angle_deg: 180}\n") ==
        doctest::Contains("geometry.corner_angle_deg: 180 is outside (0, 180)"));
  CHECK(err("geometry: {type: sphere}\noutput: {zooms: [{label: a, box: [1, 0, 0, 1]}]}\n") ==
        doctest::Contains("output.zooms"));
  CHECK(err("geometry: {type: sphere}\nsurface: {max_triangles: 0}\n") == doctest::Contains("surface.max_triangles"));
}

TEST_CASE("run config: extrude makes a 2D section's run 3D, its keys checked, the picture cut at mid-span") {
  const auto err = [](const std::string& yaml) { return doctest::String(config_error(yaml).c_str()); };
  const RunConfig r = parse_run_config(one_body + "extrude: {span: 0.4}\nlayers: {max: 3}\n", "x.yaml");
  CHECK(r.dim == 3);
  REQUIRE(r.extrude);
  CHECK(r.extrude->span == doctest::Approx(0.4));
  CHECK(r.extrude->rows == 2);
  CHECK(r.extrude->hz == 0);  // the section's own size along its wall
  CHECK(r.extrude->probe_z() == doctest::Approx(0.2));
  CHECK(r.output.has_cut);
  CHECK(r.output.cut_point[2] == doctest::Approx(0.2));
  CHECK(r.geometry.run2);  // the section's stages stay 2D
  CHECK(r.metric.run2);
  CHECK(r.surface.run2);
  CHECK(r.layers.run3);  // the layers are the 3D stage
  const RunConfig three = parse_run_config(one_body + "extrude: {span: 1, rows: 3, hz: 0.5}\n", "x.yaml");
  CHECK(three.extrude->probe_z() == doctest::Approx(1.0 / 3));
  CHECK(three.extrude->hz == 0.5);
  CHECK(err(one_body + "extrude: {rows: 2}\n") == doctest::Contains("span is required"));
  CHECK(err(one_body + "extrude: {span: 0}\n") == doctest::Contains("extrude.span"));
  CHECK(err(one_body + "extrude: {span: 1, rows: 0}\n") == doctest::Contains("extrude.rows"));
  CHECK(err(one_body + "extrude: {span: 1, depth: 2}\n") == doctest::Contains("unknown key 'extrude.depth'"));
  CHECK(err("geometry: {type: sphere}\nextrude: {span: 1}\n") == doctest::Contains("2D section of type airfoils"));
  CHECK(err("geometry: {type: annulus}\nextrude: {span: 1}\n") == doctest::Contains("2D section of type airfoils"));
  // 2D-only output keys are unknown in an extruded (3D) run.
  CHECK(err(one_body + "extrude: {span: 1}\noutput: {split_quads: true}\n") ==
        doctest::Contains("unknown key 'output.split_quads'"));
}

TEST_CASE("run config: a circle body instead of a file, its radius required and positive") {
  const auto err = [](const std::string& yaml) { return doctest::String(config_error(yaml).c_str()); };
  const std::string circle = "geometry: {type: airfoils, bodies: [{circle: {center: [1, 2], radius: 0.5}}]}\n";
  CHECK(parse_run_config(circle, "c.yaml").dim == 2);
  const AirfoilsParams a = parse_airfoils_params(ConfigNode::load_string(circle, "c.yaml").child("geometry"));
  REQUIRE(a.bodies.size() == 1);
  CHECK(a.bodies[0].circle);
  CHECK(a.bodies[0].circle_radius == 0.5);
  CHECK(a.bodies[0].circle_center[1] == 2);
  const Geometry2D g = build_airfoils_geometry(a);
  REQUIRE(g.loops.size() == 2);
  CHECK(g.loops[0].loop.corners().empty());
  for (const Eigen::Vector2d& p : g.loops[0].loop.points()) CHECK((p - Eigen::Vector2d(1, 2)).norm() == doctest::Approx(0.5));
  CHECK(err("geometry: {type: airfoils, bodies: [{circle: {center: [0, 0]}}]}\n") ==
        doctest::Contains("radius is required"));
  CHECK(err("geometry: {type: airfoils, bodies: [{circle: {radius: -1}}]}\n") ==
        doctest::Contains("radius"));
  CHECK(err("geometry: {type: airfoils, bodies: [{file: a.dat, circle: {radius: 1}}]}\n") ==
        doctest::Contains("one of file, naca or circle"));
  CHECK(err("geometry: {type: airfoils, bodies: [{name: x}]}\n") == doctest::Contains("file, naca or circle is required"));
}

TEST_CASE("run config: metric.intersect lists metric sections of their own, and the run's metric is their intersection") {
  // The stage: a wall-free pair, isotropic 0.1 intersected with 1 along x and 0.02 along y, then
  // with isotropic 0.05: the smallest size along each direction.
  const RunConfig c = parse_run_config(one_body + "metric:\n  type: uniform\n  h: 0.1\n  intersect:\n"
                                                  "    - {type: uniform, sizes: [1, 0.02]}\n    - {type: uniform, h: 0.05}\n",
                                       "i.yaml");
  REQUIRE(c.metric.run2);
  RunState<2> state(c);
  StageReport rep;
  c.metric.run2(state, rep);
  REQUIRE(state.metric);
  const Metric<2> m = state.metric->evaluate(Eigen::Vector2d(0.3, -2));
  CHECK(m.size_along(Eigen::Vector2d::UnitX()) == doctest::Approx(0.05));
  CHECK(m.size_along(Eigen::Vector2d::UnitY()) == doctest::Approx(0.02));
  // 3D: the same, the extra field's sizes along z.
  const RunConfig c3 = parse_run_config(
      "geometry: {type: sphere}\nmetric: {type: uniform, h: 0.2, intersect: [{type: uniform, sizes: [1, 1, 0.01]}]}\n", "i3.yaml");
  REQUIRE(c3.metric.run3);
  RunState<3> state3(c3);
  c3.metric.run3(state3, rep);
  const Metric<3> m3 = state3.metric->evaluate(Eigen::Vector3d(1, 2, 3));
  CHECK(m3.size_along(Eigen::Vector3d::UnitX()) == doctest::Approx(0.2));
  CHECK(m3.size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.01));
  CHECK_FALSE(state3.surface_sizes);  // no field gave sizes along the wall

  // Errors name the item: its type is required and its keys are its plugin's.
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: [{h: 0.1}]}\n")
            .find("metric.intersect[0]: each metric to intersect needs its type") != std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: [{type: uniform, h0: 0.1}]}\n")
            .find("unknown key 'metric.intersect[0].h0'") != std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: [{type: uniform, intersect: [{type: uniform}]}]}\n")
            .find("unknown key 'metric.intersect[0].intersect'") != std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: [{type: spline}]}\n").find("spline") != std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: []}\n").find("metric.intersect: give a list") !=
        std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: 3}\n").find("expected a list of maps") != std::string::npos);
  CHECK(config_error(one_body + "metric: {type: uniform, intersect: [{type: background}]}\n").find("metric.intersect[0]") !=
        std::string::npos);
}
