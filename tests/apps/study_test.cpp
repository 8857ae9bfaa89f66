// SPDX-License-Identifier: MIT
// The attenuation study (apps/study.h) end to end through `plaf compare-attenuation`: its pairs
// are honest (the generated configurations of a pair share metric, layers, order, f_atten and h0;
// an extrusion shares the section; a sphere the circle's radius), its tables are the underlying
// runs' reports, its outputs are written, bad study files fail before anything is written, and
// the shipped study reaches the numbers.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/gmsh_support.h"
#include "tests/test_support.h"
#include "tests/published_data.h"

namespace fs = std::filesystem;
using plaf::test::read_lines;
using plaf::test::read_text;
using plaf::test::run_plaf;
using plaf::test::TempDir;
using plaf::test::write_text;

namespace {

// A CSV file as rows of column name -> text (no quoting: the study's fields hold no commas).
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& p) {
  const std::vector<std::string> lines = read_lines(p);
  std::vector<std::map<std::string, std::string>> rows;
  if (lines.empty()) return rows;
  auto split = [](const std::string& line) {
    std::vector<std::string> v;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) v.push_back(f);
    if (!line.empty() && line.back() == ',') v.push_back("");
    return v;
  };
  const std::vector<std::string> head = split(lines[0]);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> f = split(lines[i]);
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < head.size(); ++k) row[head[k]] = k < f.size() ? f[k] : "";
    rows.push_back(row);
  }
  return rows;
}

double number(const std::string& text) { return text.empty() ? NAN : std::strtod(text.c_str(), nullptr); }

// The value text of "key" at or after `from` in a report (up to the next ',', '}' or ']').
std::string json_value(const std::string& json, const std::string& key, std::size_t from) {
  const std::string quoted = "\"" + key + "\": ";
  const std::size_t at = json.find(quoted, from);
  if (at == std::string::npos) return "";
  const std::size_t b = at + quoted.size();
  return json.substr(b, json.find_first_of(",}]\n", b) - b);
}

// Two numbers equal to the precision the study's CSV writes (10 digits), or both absent.
bool same(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)) + 1e-300;
}

// Linear after layer a no sooner than after layer b, -1 meaning never (within the layers grown).
bool later_or_never(const std::string& a, const std::string& b) {
  const int x = std::stoi(a), y = std::stoi(b);
  return x < 0 || (y >= 0 && x >= y);
}

std::string emit(const YAML::Node& n) {
  YAML::Emitter e;
  e << n;
  return e.c_str();
}

// A small study: a circle with its cylinder and sphere, and the E387 (the paper's coarse case)
// with its wing; order 2, two f_atten, two h0.
std::string small_study() {
  return "name: small\n"
         "order: 2\n"
         "f_atten: [0.2, 1.0]\n"
         "h0_factors: [1, 0.1]\n"
         "cases:\n"
         "  - name: circle\n"
         "    geometry: {type: airfoils, bodies: [{circle: {center: [0, 0], radius: 0.5}}]}\n"
         "    metric: {type: wall_power_law, h0: 0.001, growth: 1.2, h_max: 10.0, h_wall_max: 0.1}\n"
         "    layers: {max: 40, f_atten: 0.2, isotropic_stop: all}\n"
         "    extrude: {span: 0.2}\n"
         "    sphere: true\n"
         "  - name: e387\n"
         "    geometry: {type: airfoils, bodies: [{file: data:airfoils/e387.dat}], corner_angle_deg: 70}\n"
         "    metric: {type: wall_power_law, h0: 0.005, growth: 1.2, h_max: 10.0, h_wall_max: 0.05,\n"
         "             curvature_factor: 0.04, h_corner: 0.01}\n"
         "    layers: {max: 24, f_atten: 0.2, corner_angle_deg: 70}\n"
         "    extrude: {span: 0.2}\n";
}

}  // namespace

TEST_CASE("study: a circle, its cylinder and sphere, the E387 and its wing: honest pairs, tables that are the runs' reports") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  TempDir d("study_small");
  const fs::path study = write_text(d / "small.yaml", small_study());
  const fs::path out = d / "out";
  const auto r = run_plaf("compare-attenuation " + study.string() + " --out " + out.string(), d);
  INFO(r.err);
  REQUIRE(r.code == 0);
  for (const char* f : {"small.md", "small.json", "small_runs.csv", "small_layers.csv", "small_pairs.csv",
                        "circle_extrusion_clip.png", "circle_sphere_clip.png", "e387_extrusion_clip.png",
                        "linear_after_f_atten.png", "linear_after_h0.png", "circle_extrusion_side_by_side.png",
                        "circle_sphere_side_by_side.png", "e387_extrusion_side_by_side.png"}) {
    INFO(f);
    CHECK(fs::is_regular_file(out / f));
    CHECK(fs::file_size(out / f) > 0);
  }

  // Runs: per case the points (0.2, h0), (1, h0), (0.2, h0 / 10): 3 x (2D + 2 partners) for the
  // circle and 3 x (2D + 1) for the E387; every one exits 0 with 0 invalid cells.
  const auto runs = read_csv(out / "small_runs.csv");
  REQUIRE(runs.size() == 15);
  std::map<std::string, std::map<std::string, std::string>> by_name;
  for (const auto& row : runs) {
    INFO(row.at("run"));
    CHECK(row.at("exit_code") == "0");
    CHECK(row.at("invalid_cells") == "0");
    by_name[row.at("run")] = row;
  }

  // Honest pairs, from the generated configurations themselves: a 3D run's metric and layers
  // sections are its 2D run's, as are the order, f_atten and h0; an extrusion's geometry is the
  // section; a sphere's radius and centre are the circle's.
  const auto pairs = read_csv(out / "small_pairs.csv");
  REQUIRE(pairs.size() == 9);
  for (const auto& p : pairs) {
    INFO(p.at("run_2d") << " / " << p.at("run_3d"));
    CHECK(p.at("pairing_ok") == "1");
    const YAML::Node a = YAML::LoadFile((out / "configs" / (p.at("run_2d") + ".yaml")).string());
    const YAML::Node b = YAML::LoadFile((out / "configs" / (p.at("run_3d") + ".yaml")).string());
    CHECK(emit(a["metric"]) == emit(b["metric"]));
    CHECK(emit(a["layers"]) == emit(b["layers"]));
    CHECK(a["order"].as<int>() == b["order"].as<int>());
    CHECK(a["metric"]["h0"].as<double>() == number(p.at("h0")));
    CHECK(a["layers"]["f_atten"].as<double>() == number(p.at("f_atten")));
    CHECK(a["layers"]["high_order_heights"].as<std::string>() == "interpolated");
    if (p.at("partner") == "extrusion") {
      CHECK(emit(a["geometry"]) == emit(b["geometry"]));
      CHECK(b["extrude"]["span"].as<double>() == 0.2);
      // The section's wall nodes are the extrusion's at mid-span, exactly.
      CHECK(number(p.at("section_match")) == 0);
      CHECK(p.at("first_shrink") == "-1");
      CHECK(p.at("compared_layers") == p.at("layers_2d"));
      // The cylinder grows the circle's layers and the wing the E387's: heights to 1e-9, the
      // outer fronts at mid-span to 1e-9 of the wall distance, the same linear-after.
      CHECK(number(p.at("height_rel_diff")) <= 1e-9);
      CHECK(number(p.at("front_match_rel")) <= 1e-9);
      CHECK(p.at("linear_after_2d") == p.at("linear_after_3d"));
      CHECK(p.at("layers_2d") == p.at("layers_3d"));
    } else {
      CHECK(b["geometry"]["type"].as<std::string>() == "sphere");
      CHECK(b["geometry"]["radius"].as<double>() == a["geometry"]["bodies"][0]["circle"]["radius"].as<double>());
      // The same radial metric: the heights agree to the sphere's discretisation of its radius;
      // its triangles' interior nodes lie further off their flat triangles than the circle's
      // edges off their chords, so it needs more layers to become linear, never fewer.
      CHECK(number(p.at("height_rel_diff")) <= 1e-3);
      CHECK(number(p.at("s_max_3d")) > number(p.at("s_max_2d")));
      CHECK(later_or_never(p.at("linear_after_3d"), p.at("linear_after_2d")));
    }
  }

  // The per-layer table is each run's report: every row of the study's layer CSV equals its
  // run's report.json table row, and the runs' counts are the reports'.
  const auto layers = read_csv(out / "small_layers.csv");
  std::map<std::string, std::size_t> rows_per_run;
  for (const auto& row : layers) {
    const std::string& name = row.at("run");
    ++rows_per_run[name];
    INFO(name << " layer " << row.at("layer"));
    const std::string report = read_text(by_name.at(name).at("report"));
    REQUIRE_FALSE(report.empty());
    const std::size_t at = report.find("{\"layer\": " + row.at("layer") + ",", report.find("\"table\": ["));
    REQUIRE(at != std::string::npos);
    CHECK(same(number(row.at("max_clipped_over_height")), number(json_value(report, "max_clipped_over_height", at))));
    CHECK(same(number(row.at("min_scaled_jacobian")), number(json_value(report, "min_scaled_jacobian", at))));
    CHECK(same(number(row.at("max_aspect_ratio")), number(json_value(report, "max_aspect_ratio", at))));
    CHECK(same(number(row.at("height_min")), number(json_value(report, "height_min", at))));
    CHECK(same(number(row.at("height_mean")), number(json_value(report, "height_mean", at))));
    CHECK(same(number(row.at("height_max")), number(json_value(report, "height_max", at))));
    CHECK(row.at("curved_cells") == json_value(report, "curved_cells", at));
    CHECK(row.at("cells") == json_value(report, "cells", at));
  }
  for (const auto& [name, row] : by_name) {
    INFO(name);
    const std::string report = read_text(row.at("report"));
    const std::size_t layers_at = report.find("\"layers\": {");
    CHECK(row.at("layers") == json_value(report, "count", layers_at));
    CHECK(row.at("linear_after") == json_value(report, "linear_after", layers_at));
    CHECK(rows_per_run[name] == std::stoul(row.at("layers")));
    CHECK(row.at("invalid_cells") == json_value(report, "invalid", 0));
  }
  // The markdown names every run, and the base runs wrote their meshes and pictures.
  const std::string md = read_text(out / "small.md");
  for (const auto& [name, row] : by_name) CHECK(md.find(name) != std::string::npos);
  CHECK(fs::is_regular_file(out / "runs" / "circle_sphere_f0.2_h0.001.msh"));
  CHECK(fs::is_regular_file(out / "runs" / "e387_extrusion_f0.2_h0.005.png"));
  CHECK_FALSE(fs::exists(out / "runs" / "circle_sphere_f1_h0.001.msh"));  // sweep runs: the report only
  // Gmsh's eye on the base runs' meshes (order 2): -check clean, the 3D ones' Bezier Jacobians
  // positive.
  if (plaf::test::gmsh_on_path()) {
    int checked = 0;
    for (const auto& e : fs::directory_iterator(out / "runs")) {
      if (e.path().extension() != ".msh") continue;
      ++checked;
      INFO(e.path().string());
      TempDir g("study_gmsh_" + std::to_string(checked));
      fs::copy_file(e.path(), g / "mesh.msh");
      CHECK(plaf::test::gmsh_complaints(plaf::test::run_gmsh("mesh.msh -check", g).out).empty());
      if (e.path().stem().string().find("_2d_") == std::string::npos)  // the helper reads 3D cells
        CHECK(plaf::test::gmsh_jacobians("mesh.msh", g).min_j > 0);
    }
    CHECK(checked == 5);  // circle 2D, cylinder, sphere, E387, wing
  } else {
    plaf::test::request_skip("gmsh is not on PATH: Gmsh's checks of the base runs not run");
  }
}

TEST_CASE("study: bad study files fail with one line naming the file and key, before anything is written") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  TempDir d("study_bad");
  const std::string good = small_study();
  struct Bad {
    std::string text, expect;
  };
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  const std::vector<Bad> bad = {
      {good + "colour: red\n", "unknown key 'colour'"},
      {replace("f_atten: [0.2, 1.0]", "f_atten: [0.2, 1.5]"), "f_atten"},
      {replace("h0_factors: [1, 0.1]", "h0_factors: [1, -0.1]"), "h0_factors"},
      {replace("    sphere: true\n", ""), ""},  // still valid: the circle keeps its cylinder
      {replace("    extrude: {span: 0.2}\n    sphere: true\n", ""), "no 3D partner"},
      {replace("name: e387\n", "name: circle\n"), "named twice"},
      {replace("bodies: [{circle: {center: [0, 0], radius: 0.5}}]", "bodies: [{file: data:airfoils/e387.dat}]"),
       "one circle body"},
      {replace("h_wall_max: 0.1}", "h_wall_max: 0.1, curvature_factor: 0.1}"), "curvature_factor * radius"},
      {replace("isotropic_stop: all}", "isotropic_stop: all, colour: red}"), "case 'circle'"},
      {replace("type: wall_power_law, h0: 0.001", "type: uniform, h: 0.1"), "wall_power_law"},
      {replace("extrude: {span: 0.2}\n    sphere", "extrude: {span: -1}\n    sphere"), "span"},
      {replace("data:airfoils/e387.dat", "data:airfoils/missing.dat"), "missing.dat"},
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    const fs::path f = write_text(d / ("bad" + std::to_string(i) + ".yaml"), bad[i].text);
    if (bad[i].expect.empty()) continue;  // a control, not run (it would mesh)
    const fs::path out = d / ("out" + std::to_string(i));
    const auto r = run_plaf("compare-attenuation " + f.string() + " --out " + out.string(), d);
    INFO(bad[i].text << "\n" << r.err);
    CHECK(r.code == 1);
    CHECK(r.err.find(bad[i].expect) != std::string::npos);
    CHECK(r.err.find(f.string()) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(out));
  }
  const auto missing = run_plaf("compare-attenuation " + (d / "none.yaml").string(), d);
  CHECK(missing.code == 1);
  CHECK(missing.err.find("none.yaml") != std::string::npos);
  CHECK(run_plaf("compare-attenuation", d).code == 1);
  CHECK(run_plaf("compare-attenuation a.yaml b.yaml", d).code == 1);
}

TEST_CASE("study: named by a relative path, its contour file beside it, written into a folder outside the repository") {
  // The study's `file:` paths are relative to its folder; its generated configurations live in
  // OUT/configs/. Run from the study's folder with a relative study path (as `plaf
  // compare-attenuation configs/attenuation_study.yaml --out /tmp/x` is), once into a folder
  // elsewhere and once into the default out/<name>: each run must find the contour.
  TempDir d("study_relative");
  fs::create_directories(d / "studies");
  {
    std::ostringstream dat;  // a thin ellipse, chord 1, closed
    dat << "ellipse\n";
    for (int i = 0; i <= 64; ++i) {
      const double t = 2 * M_PI * i / 64;
      dat << 0.5 + 0.5 * std::cos(t) << " " << 0.1 * std::sin(t) << "\n";
    }
    write_text(d / "studies/ellipse.dat", dat.str());
  }
  write_text(d / "studies/tiny.yaml",
             "name: tiny\n"
             "order: 2\n"
             "f_atten: [0.2]\n"
             "h0_factors: [1]\n"
             "cases:\n"
             "  - name: ellipse\n"
             "    geometry: {type: airfoils, bodies: [{file: ellipse.dat}]}\n"
             "    metric: {type: wall_power_law, h0: 0.01, growth: 1.3, h_max: 10.0, h_wall_max: 0.1}\n"
             "    layers: {max: 6, f_atten: 0.2}\n"
             "    extrude: {span: 0.2}\n");
  TempDir elsewhere("study_relative_out");
  const fs::path outside = elsewhere / "x";
  struct Case {
    std::string args;
    fs::path out;
  };
  for (const Case& c : {Case{"--out " + outside.string(), outside}, Case{"", d / "out/tiny"}}) {
    const std::string cmd = "cd " + d.path.string() + " && " + PLAF_EXE + " compare-attenuation studies/tiny.yaml " +
                            c.args + " > /dev/null 2> stderr.txt";
    const int status = std::system(cmd.c_str());
    INFO(cmd << "\n" << read_text(d / "stderr.txt"));
    REQUIRE((WIFEXITED(status) && WEXITSTATUS(status) == 0));
    const auto runs = read_csv(c.out / "tiny_runs.csv");
    CHECK(runs.size() == 2);
    for (const auto& row : runs) CHECK(row.at("exit_code") == "0");
    // The generated configurations name the contour by its absolute path.
    const YAML::Node g = YAML::LoadFile((c.out / "configs" / "ellipse_2d_f0.2_h0.01.yaml").string());
    const fs::path contour = g["geometry"]["bodies"][0]["file"].as<std::string>();
    CHECK(contour.is_absolute());
    CHECK(fs::equivalent(contour, d / "studies/ellipse.dat"));
  }
}

TEST_CASE("study: the shipped attenuation study: every run valid, the E387 wing and the cylinder reproduce their sections") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // configs/attenuation_study.yaml in one command (docs/attenuation_study.md's table comes from it).
  const fs::path out = fs::path(PLAF_CONFIG_RUNS).parent_path() / "attenuation_study";
  fs::remove_all(out);
  TempDir d("study_shipped");
  const auto r = run_plaf("compare-attenuation " + std::string(PLAF_CONFIGS) + "/attenuation_study.yaml --out " +
                              out.string(),
                          d);
  INFO(r.err);
  REQUIRE(r.code == 0);
  for (const auto& row : read_csv(out / "attenuation_study_runs.csv")) {
    INFO(row.at("run"));
    CHECK(row.at("exit_code") == "0");
    CHECK(row.at("invalid_cells") == "0");
  }
  int e387 = 0, cylinder = 0, sphere = 0;
  for (const auto& p : read_csv(out / "attenuation_study_pairs.csv")) {
    INFO(p.at("run_2d") << " / " << p.at("run_3d"));
    CHECK(p.at("pairing_ok") == "1");
    const bool paper = p.at("f_atten") == "0.2" && (p.at("case") == "e387_coarse" || p.at("case") == "e387_fine");
    if (paper) {  // the paper's attenuation on the E387 and its wing, every h0
      ++e387;
      // Over every layer before either run shrank one (shrink neighbourhoods are dimension-specific).
      CHECK(std::stoi(p.at("compared_layers")) >= 20);
      CHECK(number(p.at("height_rel_diff")) <= 1e-9);
      CHECK(std::abs(std::stoi(p.at("linear_after_2d")) - std::stoi(p.at("linear_after_3d"))) <= 1);
    }
    if (p.at("case") == "circle" && p.at("partner") == "extrusion") {
      ++cylinder;
      CHECK(p.at("first_shrink") == "-1");
      CHECK(number(p.at("height_rel_diff")) <= 1e-9);
      CHECK(number(p.at("front_match_rel")) <= 1e-9);
      CHECK(p.at("linear_after_2d") == p.at("linear_after_3d"));
      CHECK(p.at("layers_2d") == p.at("layers_3d"));
    }
    if (p.at("partner") == "sphere") {
      ++sphere;
      CHECK(later_or_never(p.at("linear_after_3d"), p.at("linear_after_2d")));
    }
  }
  CHECK(e387 == 8);
  CHECK(cylinder == 8);
  CHECK(sphere == 8);
}
