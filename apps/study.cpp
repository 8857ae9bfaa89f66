// SPDX-License-Identifier: MIT
// The attenuation study (study.h): generated run configurations, their runs, the pairs' measures
// and the tables, JSON and charts.
#include "apps/study.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "apps/run.h"
#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/geometry2d.h"
#include "modules/io/atomic_file.h"
#include "modules/pipeline/data_root.h"
#include "modules/io/chart.h"
#include "modules/metric/wall_metric.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/run_config.h"

namespace plaf {

namespace {

namespace fs = std::filesystem;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// ---- the study file ---------------------------------------------------------------------------

struct StudyCase {
  std::string name;
  std::string where;  // "file:line:col: cases[i]"
  YAML::Node geometry, metric, layers, extrude, zooms;  // extrude, zooms: null when absent
  bool extruded() const { return extrude.IsMap(); }
  bool sphere = false;
  double circle_radius = 0;
  std::array<double, 2> circle_center = {0, 0};
  double h0 = 0, f_atten = 0, growth = 0;  // the case's own (the base point of its sweeps)
  std::vector<double> h0_factors;          // the study's, or the case's own
};

struct Study {
  std::string name;
  fs::path file;
  int order = 3;
  std::vector<double> f_atten = {0.05, 0.1, 0.2, 0.4, 1.0};
  std::vector<double> h0_factors = {1, 0.1, 0.01, 0.001};
  std::vector<StudyCase> cases;
};

// 12 significant digits: swept values print as the user would write them (0.1 * 5e-5 = 5e-06).
double round12(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return std::strtod(buf, nullptr);
}

// A number from a raw YAML scalar, or `fallback` when absent (the run's own parse checks it).
double raw_number(const YAML::Node& map, const std::string& key, double fallback, const std::string& where) {
  if (!map.IsDefined() || !map.IsMap() || !map[key].IsDefined() || map[key].IsNull()) return fallback;
  try {
    return map[key].as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where + "." + key + ": expected a number, got '" + map[key].Scalar() + "'");
  }
}

// Every value of a sweep list in (lo, hi] and finite.
void check_sweep(const ConfigNode& n, const std::string& key, const std::vector<double>& v, double hi) {
  for (double x : v)
    if (!(x > 0 && x <= hi && std::isfinite(x)))
      throw ConfigError(n.where(key) + ": every value must be positive" + (std::isfinite(hi) ? " and at most " + num(hi) : std::string()) +
                        ", got " + num(x));
  if (v.empty()) throw ConfigError(n.where(key) + ": give at least one value");
}

// Relative path values (`file`: a body's contour, a background metric; `sol`) made absolute
// against the study's folder (dir, absolute): the generated configurations live elsewhere. A data-root path
// (`data:REL`, data_root.h) is found from anywhere and stays as written.
void absolutize_files(YAML::Node node, const fs::path& dir) {
  if (node.IsMap()) {
    for (auto kv : node) {
      if ((kv.first.Scalar() == "file" || kv.first.Scalar() == "sol") && kv.second.IsScalar()) {
        const fs::path p(kv.second.Scalar());
        if (p.is_relative() && kv.second.Scalar().rfind(kDataPrefix, 0) != 0)
          kv.second = (dir / p).lexically_normal().string();
      } else {
        absolutize_files(kv.second, dir);
      }
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) absolutize_files(node[i], dir);
  }
}

// The study of file `path`, read from c (its parsed text).
Study load_study(const ConfigNode& c, const fs::path& path) {
  Study s;
  s.file = path;
  s.name = c.get_string("name", path.stem().string());
  if (s.name.empty() || s.name == "." || s.name == ".." || s.name.find('/') != std::string::npos)
    throw ConfigError(c.where("name") + ": must be a plain file name, got '" + s.name + "'");
  s.order = c.get_int("order", s.order, 1, 4);
  s.f_atten = c.get_double_list("f_atten", s.f_atten);
  check_sweep(c, "f_atten", s.f_atten, 1.0);
  s.h0_factors = c.get_double_list("h0_factors", s.h0_factors);
  check_sweep(c, "h0_factors", s.h0_factors, std::numeric_limits<double>::infinity());
  // Absolute: a study named by a relative path (`configs/x.yaml`) writes its configurations into
  // OUT/configs/, where a path relative to the study's folder would be read from that folder.
  const fs::path dir = fs::absolute(path).parent_path();
  std::set<std::string> names;
  for (const ConfigNode& k : c.child_list("cases")) {
    StudyCase sc;
    sc.where = k.where();
    sc.name = k.get_string("name", "");
    if (sc.name.empty() || sc.name.find_first_of("/ ") != std::string::npos)
      throw ConfigError(k.where("name") + ": every case needs a plain name, got '" + sc.name + "'");
    if (!names.insert(sc.name).second) throw ConfigError(k.where("name") + ": case '" + sc.name + "' is named twice");
    for (const char* key : {"geometry", "metric", "layers"})
      if (!k.has(key)) throw ConfigError(k.where() + ": case '" + sc.name + "' needs a " + key + " section");
    sc.geometry = YAML::Clone(k.raw("geometry"));
    sc.metric = YAML::Clone(k.raw("metric"));
    sc.layers = YAML::Clone(k.raw("layers"));
    for (const YAML::Node* n : {&sc.geometry, &sc.metric, &sc.layers})
      if (!n->IsMap()) throw ConfigError(k.where() + ": case '" + sc.name + "': geometry, metric and layers are maps");
    absolutize_files(sc.geometry, dir);
    absolutize_files(sc.metric, dir);
    if (!sc.geometry["type"].IsDefined() || sc.geometry["type"].Scalar() != "airfoils")
      throw ConfigError(k.where("geometry") + ": a case's section is a 2D geometry of type airfoils");
    if (!sc.metric["type"].IsDefined() || sc.metric["type"].Scalar() != "wall_power_law")
      throw ConfigError(k.where("metric") + ": the study sweeps h0 of a metric of type wall_power_law");
    if (k.has("extrude")) {
      sc.extrude = YAML::Clone(k.raw("extrude"));
      if (!sc.extrude.IsMap()) throw ConfigError(k.where("extrude") + ": expected a map (span, rows, hz)");
    }
    sc.sphere = k.get_bool("sphere", false);
    sc.h0_factors = k.get_double_list("h0_factors", s.h0_factors);
    check_sweep(k, "h0_factors", sc.h0_factors, std::numeric_limits<double>::infinity());
    if (!sc.extruded() && !sc.sphere)
      throw ConfigError(k.where() + ": case '" + sc.name + "' has no 3D partner (give extrude: {span: ...} or sphere: true)");
    if (k.has("output")) {
      const ConfigNode o = k.child("output");
      if (o.has("zooms")) {
        sc.zooms = YAML::Clone(o.raw("zooms"));
        if (!sc.zooms.IsSequence()) throw ConfigError(o.where("zooms") + ": expected a list of {label, box}");
      }
    }
    const WallLawParams defaults;
    const std::string mw = k.where("metric");
    sc.h0 = round12(raw_number(sc.metric, "h0", defaults.h0, mw));
    sc.growth = raw_number(sc.metric, "growth", defaults.growth, mw);
    sc.f_atten = round12(raw_number(sc.layers, "f_atten", 0.2, k.where("layers")));
    if (sc.sphere) {
      // The sphere of the section's circle: one body, a circle; the metric must size both alike.
      const YAML::Node bodies = sc.geometry["bodies"];
      if (!bodies.IsDefined() || !bodies.IsSequence() || bodies.size() != 1 || !bodies[0].IsMap() ||
          !bodies[0]["circle"].IsDefined() || !bodies[0]["circle"].IsMap())
        throw ConfigError(k.where("geometry") + ": the sphere partner needs a section of one circle body "
                          "(bodies: [{circle: {center: [x, y], radius: r}}])");
      const YAML::Node circle = bodies[0]["circle"];
      sc.circle_radius = raw_number(circle, "radius", nan, k.where("geometry") + ".bodies[0].circle");
      const YAML::Node center = circle["center"];
      if (center.IsDefined() && center.IsSequence() && center.size() == 2) {
        YAML::Node xy(YAML::NodeType::Map);
        xy["x"] = center[0];
        xy["y"] = center[1];
        const std::string cw = k.where("geometry") + ".bodies[0].circle.center";
        sc.circle_center = {raw_number(xy, "x", 0, cw), raw_number(xy, "y", 0, cw)};
      }
      if (sc.metric["h_corner"].IsDefined())
        throw ConfigError(mw + ".h_corner: the sphere partner's metric has no corners; leave h_corner out");
      // 2D sizes along the wall: min(h_wall_max, curvature_factor R); 3D: h_wall_max. Equal only
      // when the curvature size is not the smaller one.
      const double cf = raw_number(sc.metric, "curvature_factor", defaults.curvature_factor, mw);
      const double hw = raw_number(sc.metric, "h_wall_max", defaults.h_wall_max, mw);
      if (cf * sc.circle_radius < hw)
        throw ConfigError(mw + ": with a sphere partner the circle's size along the wall must be h_wall_max in both "
                          "(curvature_factor * radius = " + num(cf * sc.circle_radius) + " < h_wall_max = " + num(hw) +
                          ")");
    }
    s.cases.push_back(std::move(sc));
  }
  if (s.cases.empty()) throw ConfigError(c.where("cases") + ": give at least one case");
  c.finish();
  return s;
}

Study load_study(const fs::path& path) { return load_study(ConfigNode::load_file(path), path); }

// ---- the runs -------------------------------------------------------------------------------

struct StudyRun {
  const StudyCase* sc = nullptr;
  std::string partner;  // "section" (2D), "extrusion" or "sphere"
  std::string name;
  double f_atten = 0, h0 = 0;
  bool base = false;                 // the case's own f_atten and h0: every output written
  std::string metric_text, layers_text;  // the shared sections as generated (the pairing check)
  std::string text;                  // the generated configuration
  RunConfig config;
  RunOutcome out;
  bool ran = false;
  std::string error;                 // a mesher error that stopped the run
  double seconds = 0;
  int dim() const { return partner == "section" ? 2 : 3; }
  int code() const { return !ran ? 2 : out.code; }
  std::size_t layers() const { return out.layers.size(); }
  double min_sj() const { return ran ? out.report.scaled_jacobian_min : nan; }
};

std::string emit(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetDoublePrecision(15);
  e << n;
  return e.c_str();
}

std::string point_name(double f, double h0) { return "f" + num(f) + "_h" + num(h0); }

// The configuration of one run of case sc at (f, h0): the case's sections with h0 and f_atten
// set, the partner's geometry (sphere) or extrude key (extrusion).
StudyRun make_run(const Study& st, const StudyCase& sc, const std::string& partner, double f, double h0, bool base,
                  const fs::path& out) {
  StudyRun r;
  r.sc = &sc;
  r.partner = partner;
  r.f_atten = f;
  r.h0 = h0;
  r.base = base;
  r.name = sc.name + "_" + (partner == "section" ? "2d" : partner) + "_" + point_name(f, h0);
  YAML::Node metric = YAML::Clone(sc.metric);
  metric["h0"] = h0;
  YAML::Node layers = YAML::Clone(sc.layers);
  layers["f_atten"] = f;
  // The same rule for high-order heights in both dimensions (their defaults differ, layer_core.h).
  if (!layers["high_order_heights"].IsDefined()) layers["high_order_heights"] = "interpolated";
  // The study measures where the layers stop as well as how they attenuate: a part that fails
  // stops whole in both dimensions (3D's local stops would grow on where 2D stopped, and the
  // pair would no longer compare layer by layer), and its coverage is reported, not enforced.
  if (!layers["local_stops"].IsDefined()) layers["local_stops"] = false;
  if (!layers["min_coverage"].IsDefined()) layers["min_coverage"] = 0.0;
  // The same normals in both (the 3D default relaxes them, layers/plugins.cpp; 2D's does not):
  // 2D's default, so an extrusion's columns stay the section's.
  if (!layers["smooth_normals"].IsDefined()) layers["smooth_normals"] = false;
  // The same isotropic stop in both (the 3D default is node, layers/plugins.cpp): 2D's default.
  if (!layers["isotropic_stop"].IsDefined()) {
    bool linear = false;  // (a bad value is the run's own error, named by its config check)
    if (layers["stop_when_linear"].IsDefined()) YAML::convert<bool>::decode(layers["stop_when_linear"], linear);
    layers["isotropic_stop"] = linear ? "all" : "off";
  }
  r.metric_text = emit(metric);
  r.layers_text = emit(layers);
  YAML::Node n(YAML::NodeType::Map);
  n["name"] = r.name;
  n["order"] = st.order;
  if (partner == "sphere") {
    YAML::Node g(YAML::NodeType::Map);
    g["type"] = "sphere";
    g["center"].push_back(sc.circle_center[0]);
    g["center"].push_back(sc.circle_center[1]);
    g["center"].push_back(0.0);
    g["radius"] = sc.circle_radius;
    n["geometry"] = g;
    // The 3D wall law has no curvature_factor: the check in load_study made it inactive in 2D.
    if (metric["curvature_factor"].IsDefined()) metric.remove("curvature_factor");
  } else {
    n["geometry"] = YAML::Clone(sc.geometry);
  }
  if (partner == "extrusion") n["extrude"] = YAML::Clone(sc.extrude);
  n["metric"] = metric;
  n["layers"] = layers;
  YAML::Node o(YAML::NodeType::Map);
  o["dir"] = (out / "runs").string();
  if (base) {
    for (const char* format : {"msh", "vtu", "report", "png"}) o["formats"].push_back(format);
  } else {
    o["formats"].push_back("report");
  }
  if (sc.zooms.IsSequence()) o["zooms"] = YAML::Clone(sc.zooms);
  n["output"] = o;
  r.text = "# Generated by plaf compare-attenuation from " + st.file.string() + " (case " + sc.name + ")\n" + emit(n) + "\n";
  return r;
}

std::vector<StudyRun> plan_runs(const Study& st, const fs::path& out) {
  std::vector<StudyRun> runs;
  for (const StudyCase& sc : st.cases) {
    std::vector<std::pair<double, double>> points;
    auto add = [&](double f, double h0) {
      for (const auto& p : points)
        if (p.first == f && p.second == h0) return;
      points.emplace_back(f, h0);
    };
    add(sc.f_atten, sc.h0);
    for (double f : st.f_atten) add(round12(f), sc.h0);
    for (double k : sc.h0_factors) add(sc.f_atten, round12(sc.h0 * k));
    for (const auto& [f, h0] : points) {
      const bool base = f == sc.f_atten && h0 == sc.h0;
      runs.push_back(make_run(st, sc, "section", f, h0, base, out));
      if (sc.extruded()) runs.push_back(make_run(st, sc, "extrusion", f, h0, base, out));
      if (sc.sphere) runs.push_back(make_run(st, sc, "sphere", f, h0, base, out));
    }
  }
  // Every configuration is checked before anything runs or is written.
  std::set<std::string> names;
  for (StudyRun& r : runs) {
    if (!names.insert(r.name).second)
      throw ConfigError(r.sc->where + ": case '" + r.sc->name + "': two sweep points print as '" + r.name +
                        "' (give f_atten and h0 values that differ in their first 6 digits)");
    try {
      r.config = parse_run_config(r.text, (out / "configs" / (r.name + ".yaml")).string());
    } catch (const Error& e) {
      throw ConfigError(r.sc->where + ": case '" + r.sc->name + "', its " + (r.dim() == 2 ? "2D" : r.partner) +
                        " run: " + e.what());
    }
    r.config.file = out / "configs" / (r.name + ".yaml");
    r.config.output.dir = out / "runs";
  }
  // Every section's contour files are read and checked too (simple, disjoint loops), once per
  // case, so a bad file stops the study before anything is written.
  for (const StudyCase& sc : st.cases)
    for (const StudyRun& r : runs)
      if (r.sc == &sc && r.partner == "section") {
        try {
          const ConfigNode g = ConfigNode::load_string(r.text, r.config.file.string()).child("geometry");
          build_airfoils_geometry(parse_airfoils_params(g));
        } catch (const Error& e) {
          throw InputError(sc.where + ": case '" + sc.name + "': " + e.what());
        }
        break;
      }
  return runs;
}

// ---- the pairs --------------------------------------------------------------------------------

struct Pair {
  const StudyRun* r2 = nullptr;
  const StudyRun* r3 = nullptr;
  // The layers compared: those both grew before either had to shrink heights (a shrink halves
  // heights around a failing cell, over the loop's neighbouring nodes in 2D and the faces
  // around it in 3D: the two dimensions shrink different neighbourhoods, so from there on the
  // pair measures two different layer stacks).
  std::size_t compared_layers = 0;
  int first_shrink = -1;          // the first layer either run kept shrunk heights in, rebuilt with another f_atten or stopped columns in (-1: none)
  double height_rel_diff = nan;   // largest relative difference of the layer heights (min, mean, max)
  double front_match_rel = nan;   // extrusion, no shrink: outer front at mid-span vs the 2D one, over the wall distance
  double section_match = nan;     // extrusion: mid-span wall nodes vs the section's, over the chord scale
  bool pairing_ok = true;
  std::string pairing_note;
};

double nearest(const Eigen::Vector3d& x, const std::vector<Eigen::Vector3d>& set) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& y : set) best = std::min(best, (x.head<2>() - y.head<2>()).norm());
  return best;
}

// The points of v (at z, when station) each once, in (x, y) order.
std::vector<Eigen::Vector3d> distinct(const std::vector<Eigen::Vector3d>& v, std::optional<double> station = {},
                                      double tol = 0) {
  std::vector<Eigen::Vector3d> s;
  for (const Eigen::Vector3d& x : v)
    if (!station || std::abs(x.z() - *station) <= tol) s.push_back(x);
  std::sort(s.begin(), s.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 2, b.data(), b.data() + 2);
  });
  s.erase(std::unique(s.begin(), s.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm() == 0; }),
          s.end());
  return s;
}

void fail_pairing(Pair& p, const std::string& why) {
  p.pairing_ok = false;
  p.pairing_note += (p.pairing_note.empty() ? "" : "; ") + why;
}

Pair make_pair_result(const StudyRun& r2, const StudyRun& r3) {
  Pair p;
  p.r2 = &r2;
  p.r3 = &r3;
  // By construction (make_run): the same metric and layers sections, f_atten and h0.
  if (r2.metric_text != r3.metric_text || r2.layers_text != r3.layers_text || r2.f_atten != r3.f_atten ||
      r2.h0 != r3.h0 || r2.config.order != r3.config.order)
    fail_pairing(p, "the generated metric or layers sections, f_atten, h0 or order differ");
  if (!r2.ran || !r3.ran) return p;
  // On the results: the same metric at the wall (the first layer's smallest height, the wall
  // law's normal size there, agrees on both sides).
  if (!r2.out.layers.empty() && !r3.out.layers.empty()) {
    const double a = r2.out.layers[0].stats.min_height(), b = r3.out.layers[0].stats.min_height();
    if (!(std::abs(b - a) <= 1e-6 * a))
      fail_pairing(p, "the first layers' smallest heights differ (" + num(a) + " vs " + num(b) + "): not the same metric");
  }
  if (r3.partner == "sphere") {  // the sphere's wall lies on the circle's radius
    double dev = 0;
    const Eigen::Vector3d c(r3.sc->circle_center[0], r3.sc->circle_center[1], 0);
    for (const Eigen::Vector3d& x : r3.out.wall_nodes) dev = std::max(dev, std::abs((x - c).norm() - r3.sc->circle_radius));
    if (!(dev <= 1e-9 * r3.sc->circle_radius)) fail_pairing(p, "the sphere's wall is off the circle's radius by " + num(dev));
  }
  // Layer heights, layer by layer, over the layers both grew before either kept shrunk heights,
  // used another f_atten (a rebuilt layer, layer_core.cpp) or stopped columns (the proximity
  // rule; a stopped column's neighbours join it with transition triangles in 2D and tetrahedra
  // in 3D): from there on the pair measures two different layer stacks. The stop rules are the
  // same in both, so the first stops must come in the same layer (checked).
  std::size_t n = std::min(r2.layers(), r3.layers());
  auto stops = [](const StudyRun& r, std::size_t k) {
    return k > 0 && k < r.layers() && r.out.layers[k].stats.coverage < r.out.layers[k - 1].stats.coverage * (1 - 1e-12);
  };
  for (std::size_t k = 0; k < std::max(r2.layers(), r3.layers()); ++k) {
    const bool a = k < r2.layers() && r2.out.layers[k].stats.shrunk, b = k < r3.layers() && r3.out.layers[k].stats.shrunk;
    const bool f = k < n && r2.out.layers[k].stats.f_atten != r3.out.layers[k].stats.f_atten;
    const bool s2 = stops(r2, k), s3 = stops(r3, k);
    if (!a && !b && !f && k < n && s2 != s3)
      fail_pairing(p, "layer " + std::to_string(k + 1) + ": columns stopped in the " + (s2 ? "2D" : "3D") +
                          " run only (the same stop rules should stop the same columns)");
    if (a || b || f || s2 || s3) {
      p.first_shrink = static_cast<int>(k) + 1;
      n = std::min(n, k);
      break;
    }
  }
  double worst = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const LayerStats& a = r2.out.layers[k].stats;
    const LayerStats& b = r3.out.layers[k].stats;
    if (a.height_columns == 0 || b.height_columns == 0) continue;
    ++p.compared_layers;
    for (auto [x, y] : {std::pair{a.height_min, b.height_min}, {a.height_mean, b.height_mean}, {a.height_max, b.height_max}})
      worst = x > 0 ? std::max(worst, std::abs(y - x) / x) : nan;  // NaN stays: a zero height is no match
    // The extrusion's mid-span station has the section's columns, one for one.
    if (r3.partner == "extrusion" && a.height_columns != b.height_columns)
      fail_pairing(p, "layer " + std::to_string(k + 1) + " measured " + std::to_string(b.height_columns) +
                          " columns at mid-span, the section " + std::to_string(a.height_columns));
  }
  p.height_rel_diff = p.compared_layers > 0 ? worst : nan;
  if (r3.partner != "extrusion") return p;
  // The mid-span station of the extrusion against the section.
  const double z = r3.config.extrude->probe_z(), tol = 1e-9 * r3.config.extrude->span;
  const std::vector<Eigen::Vector3d> wall2 = distinct(r2.out.wall_nodes), wall3 = distinct(r3.out.wall_nodes, z, tol);
  const std::vector<Eigen::Vector3d> outer2 = distinct(r2.out.outer_nodes), outer3 = distinct(r3.out.outer_nodes, z, tol);
  double scale = 0;
  for (const Eigen::Vector3d& x : wall2) scale = std::max(scale, x.head<2>().norm());
  double sm = 0;
  for (const Eigen::Vector3d& x : wall2) sm = std::max(sm, nearest(x, wall3));
  for (const Eigen::Vector3d& x : wall3) sm = std::max(sm, nearest(x, wall2));
  p.section_match = sm / std::max(scale, 1e-300);
  if (wall2.size() != wall3.size() || !(p.section_match <= 1e-12))
    fail_pairing(p, "the mid-span wall nodes are not the section's (" + std::to_string(wall3.size()) + " vs " +
                        std::to_string(wall2.size()) + " nodes, off by " + num(p.section_match) + ")");
  double fm = 0;
  for (const Eigen::Vector3d& x : outer2) fm = std::max(fm, nearest(x, outer3) / std::max(nearest(x, wall2), 1e-300));
  for (const Eigen::Vector3d& x : outer3) fm = std::max(fm, nearest(x, outer2) / std::max(nearest(x, wall2), 1e-300));
  p.front_match_rel = (outer2.empty() || outer3.empty() || p.first_shrink >= 0) ? nan : fm;
  return p;
}

// The attenuation model's layer counts at the run's largest chord offset s: the issue's
// k = ln(1 + s / h0) / ln g, and with f_atten and the growth (the tops move at most
// f h0 g^(k-1) in layer k, so k layers remove f h0 (g^k - 1) / (g - 1)):
// k = ln(1 + s (g - 1) / (f h0)) / ln g.
double model_k(double s, double h0, double g) { return std::log1p(s / h0) / std::log(g); }
double model_k_f(double s, double h0, double g, double f) { return std::log1p(s * (g - 1) / (f * h0)) / std::log(g); }

// ---- outputs ----------------------------------------------------------------------------------

std::string fmt(double v, int digits = 4) {
  if (!std::isfinite(v)) return "—";
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}
std::string csv_num(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str();
}
std::string linear_text(int k) { return k < 0 ? "not linear" : std::to_string(k); }

void write_text(const fs::path& p, const std::string& text) {
  AtomicFile f(p);
  f.write(text);
  f.commit();
}

std::string runs_csv(const std::vector<StudyRun>& runs) {
  std::ostringstream o;
  o << "case,partner,dim,run,f_atten,h0,growth,exit_code,invalid_cells,layers,linear_after,s_max,model_k,"
       "model_k_f,wall_edge_mean,min_scaled_jacobian,max_aspect_ratio,seconds,report\n";
  for (const StudyRun& r : runs) {
    const double s = r.out.max_chord_offset;
    o << r.sc->name << ',' << r.partner << ',' << r.dim() << ',' << r.name << ',' << csv_num(r.f_atten) << ','
      << csv_num(r.h0) << ',' << csv_num(r.sc->growth) << ',' << r.code() << ','
      << (r.ran ? std::to_string(r.out.report.cells_invalid) : "") << ',' << r.layers() << ','
      << r.out.linear_after << ',' << csv_num(s) << ',' << csv_num(model_k(s, r.h0, r.sc->growth)) << ','
      << csv_num(model_k_f(s, r.h0, r.sc->growth, r.f_atten)) << ',' << csv_num(r.ran ? r.out.wall_edge_mean : nan)
      << ',' << csv_num(r.min_sj()) << ',' << csv_num(r.ran ? r.out.report.aspect_ratio_max : nan) << ',' << csv_num(r.seconds) << ','
      << (r.ran && r.config.output.wants("report") ? (r.out.base.string() + ".report.json") : "") << '\n';
  }
  return o.str();
}

std::string layers_csv(const std::vector<StudyRun>& runs) {
  std::ostringstream o;
  o << "run,case,partner,dim,f_atten,h0,layer,cells,transition_cells,curved_cells,curved_fraction,"
       "max_clipped_over_height,linear,min_scaled_jacobian,max_aspect_ratio,height_min,height_mean,height_max,"
       "height_columns,layer_f_atten,shrunk\n";
  for (const StudyRun& r : runs)
    for (const LayerRow& row : r.out.layers) {
      const LayerStats& st = row.stats;
      o << r.name << ',' << r.sc->name << ',' << r.partner << ',' << r.dim() << ',' << csv_num(r.f_atten) << ','
        << csv_num(r.h0) << ',' << st.layer << ',' << st.cells << ',' << st.transition_cells << ','
        << (row.measured ? std::to_string(row.curved) : "") << ',' << csv_num(row.curved_fraction()) << ','
        << csv_num(st.max_clipped_rel) << ',' << (st.linear ? 1 : 0) << ',' << csv_num(row.min_scaled_jacobian) << ','
        << csv_num(row.max_aspect_ratio) << ',' << csv_num(st.min_height()) << ',' << csv_num(st.mean_height()) << ','
        << csv_num(st.max_height())
        << ',' << st.height_columns << ',' << csv_num(st.f_atten) << ',' << (st.shrunk ? 1 : 0) << '\n';
    }
  return o.str();
}

std::string pairs_csv(const std::vector<Pair>& pairs) {
  std::ostringstream o;
  o << "case,partner,f_atten,h0,run_2d,run_3d,layers_2d,layers_3d,linear_after_2d,linear_after_3d,s_max_2d,s_max_3d,"
       "compared_layers,first_shrink,height_rel_diff,front_match_rel,section_match,pairing_ok\n";
  for (const Pair& p : pairs)
    o << p.r2->sc->name << ',' << p.r3->partner << ',' << csv_num(p.r2->f_atten) << ',' << csv_num(p.r2->h0) << ','
      << p.r2->name << ',' << p.r3->name << ',' << p.r2->layers() << ',' << p.r3->layers() << ','
      << p.r2->out.linear_after << ',' << p.r3->out.linear_after << ',' << csv_num(p.r2->out.max_chord_offset) << ','
      << csv_num(p.r3->out.max_chord_offset) << ',' << p.compared_layers << ',' << p.first_shrink << ','
      << csv_num(p.height_rel_diff) << ',' << csv_num(p.front_match_rel)
      << ',' << csv_num(p.section_match) << ',' << (p.pairing_ok ? 1 : 0) << '\n';
  return o.str();
}

std::string run_json(const StudyRun& r) {
  std::vector<std::string> rows;
  for (const LayerRow& row : r.out.layers) {
    const LayerStats& st = row.stats;
    rows.push_back("{\"layer\": " + std::to_string(st.layer) + ", \"cells\": " + std::to_string(st.cells) +
                   ", \"transition_cells\": " + std::to_string(st.transition_cells) +
                   ", \"curved_fraction\": " + json_number(row.curved_fraction()) +
                   ", \"max_clipped_over_height\": " + json_number(st.max_clipped_rel) +
                   ", \"min_scaled_jacobian\": " + json_number(row.min_scaled_jacobian) +
                   ", \"max_aspect_ratio\": " + json_number(row.max_aspect_ratio) +
                   ", \"height_min\": " + json_number(st.min_height()) +
                   ", \"height_mean\": " + json_number(st.mean_height()) +
                   ", \"height_max\": " + json_number(st.max_height()) +
                   ", \"f_atten\": " + json_number(st.f_atten) + ", \"shrunk\": " + (st.shrunk ? "true" : "false") + "}");
  }
  const double s = r.out.max_chord_offset;
  return "{\"name\": " + json_string(r.name) + ", \"case\": " + json_string(r.sc->name) +
         ", \"partner\": " + json_string(r.partner) + ", \"dim\": " + std::to_string(r.dim()) +
         ", \"f_atten\": " + json_number(r.f_atten) + ", \"h0\": " + json_number(r.h0) +
         ", \"growth\": " + json_number(r.sc->growth) + ", \"base\": " + (r.base ? "true" : "false") +
         ", \"exit_code\": " + std::to_string(r.code()) +
         ", \"error\": " + json_string(r.error) +
         ", \"invalid_cells\": " + (r.ran ? std::to_string(r.out.report.cells_invalid) : "null") +
         ", \"layers\": " + std::to_string(r.layers()) + ", \"linear_after\": " + std::to_string(r.out.linear_after) +
         ", \"s_max\": " + json_number(s) + ", \"model_k\": " + json_number(model_k(s, r.h0, r.sc->growth)) +
         ", \"model_k_f\": " + json_number(model_k_f(s, r.h0, r.sc->growth, r.f_atten)) +
         ", \"wall_edge_mean\": " + json_number(r.ran ? r.out.wall_edge_mean : nan) +
         ", \"min_scaled_jacobian\": " + json_number(r.min_sj()) +
         ", \"max_aspect_ratio\": " + json_number(r.ran ? r.out.report.aspect_ratio_max : nan) +
         ", \"seconds\": " + json_number(r.seconds) +
         ", \"config\": " + json_string(r.config.file.string()) +
         ", \"report\": " + json_string(r.ran && r.config.output.wants("report") ? r.out.base.string() + ".report.json" : "") +
         ", \"table\": " + json_array(rows) + "}";
}

std::string pair_json(const Pair& p) {
  return "{\"case\": " + json_string(p.r2->sc->name) + ", \"partner\": " + json_string(p.r3->partner) +
         ", \"f_atten\": " + json_number(p.r2->f_atten) + ", \"h0\": " + json_number(p.r2->h0) +
         ", \"run_2d\": " + json_string(p.r2->name) + ", \"run_3d\": " + json_string(p.r3->name) +
         ", \"layers_2d\": " + std::to_string(p.r2->layers()) + ", \"layers_3d\": " + std::to_string(p.r3->layers()) +
         ", \"linear_after_2d\": " + std::to_string(p.r2->out.linear_after) +
         ", \"linear_after_3d\": " + std::to_string(p.r3->out.linear_after) +
         ", \"compared_layers\": " + std::to_string(p.compared_layers) +
         ", \"first_shrink\": " + std::to_string(p.first_shrink) +
         ", \"height_rel_diff\": " + json_number(p.height_rel_diff) +
         ", \"front_match_rel\": " + json_number(p.front_match_rel) +
         ", \"section_match\": " + json_number(p.section_match) +
         ", \"pairing_ok\": " + (p.pairing_ok ? "true" : "false") + ", \"pairing_note\": " + json_string(p.pairing_note) +
         "}";
}

std::string markdown(const Study& st, const std::vector<StudyRun>& runs, const std::vector<Pair>& pairs, bool ok,
                     double seconds) {
  std::ostringstream o;
  std::size_t bad = 0;
  for (const StudyRun& r : runs) bad += r.code() != 0;
  o << "# Attenuation study `" << st.name << "`\n\n"
    << runs.size() << " runs (order " << st.order << "), " << bad << " not valid; " << pairs.size()
    << " pairs; " << fmt(seconds, 3) << " s. " << (ok ? "Every run exits 0 with 0 invalid cells and every pairing holds."
                                                      : "**Not every run is valid or paired: see below.**")
    << "\n\nHeights are compared over the layers both runs grew before either shrank one or stopped columns "
       "(shrinks halve heights, and stopped columns join their neighbours, over dimension-specific "
       "neighbourhoods; the first stops must come in the same layer); the front match (extrusions) is the mid-span outer front's "
       "largest distance to the 2D one over the distance to the wall, when neither shrank."
    << "\n\nModel: k = ln(1 + s/h0) / ln g (s: the wall's largest high-order node offset from its chord); "
       "k_f = ln(1 + s (g - 1) / (f h0)) / ln g adds f_atten and the growth.\n\n";
  o << "## Pairs (2D beside 3D)\n\n"
    << "| case | 3D | f_atten | h0 | layers 2D / 3D | linear after 2D / 3D | model k 2D / 3D | model k_f 2D / 3D | "
       "s_max 2D / 3D | height rel. diff (layers compared) | front match | min SJ 2D / 3D | pairing |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Pair& p : pairs) {
    const StudyRun& a = *p.r2;
    const StudyRun& b = *p.r3;
    const double s = a.out.max_chord_offset;
    o << "| " << a.sc->name << " | " << b.partner << " | " << fmt(a.f_atten) << " | " << fmt(a.h0) << " | "
      << a.layers() << " / " << b.layers() << " | " << linear_text(a.out.linear_after) << " / "
      << linear_text(b.out.linear_after) << " | " << fmt(model_k(s, a.h0, a.sc->growth), 3) << " / "
      << fmt(model_k(b.out.max_chord_offset, b.h0, b.sc->growth), 3) << " | "
      << fmt(model_k_f(s, a.h0, a.sc->growth, a.f_atten), 3) << " / "
      << fmt(model_k_f(b.out.max_chord_offset, b.h0, b.sc->growth, b.f_atten), 3) << " | " << fmt(s, 3) << " / "
      << fmt(b.out.max_chord_offset, 3) << " | " << fmt(p.height_rel_diff, 2) << " (" << p.compared_layers
      << (p.first_shrink > 0 ? ", shrunk from " + std::to_string(p.first_shrink) : std::string()) << ") | "
      << fmt(p.front_match_rel, 2)
      << " | " << fmt(a.min_sj(), 3) << " / " << fmt(b.min_sj(), 3) << " | "
      << (p.pairing_ok ? "ok" : "**" + p.pairing_note + "**") << " |\n";
  }
  for (const Pair& p : pairs) {
    if (!p.r2->base) continue;
    const StudyRun& a = *p.r2;
    const StudyRun& b = *p.r3;
    o << "\n## " << a.sc->name << ": 2D section beside its " << b.partner << " (f_atten " << fmt(a.f_atten) << ", h0 "
      << fmt(a.h0) << ")\n\n"
      << "| layer | max clip/h 2D | 3D | curved 2D | 3D | min SJ 2D | 3D | max AR 2D | 3D | height 2D (min..max) | 3D |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    const std::size_t n = std::max(a.layers(), b.layers());
    auto cell = [](const StudyRun& r, std::size_t k, auto f) { return k < r.layers() ? f(r.out.layers[k]) : std::string("—"); };
    for (std::size_t k = 0; k < n; ++k) {
      o << "| " << k + 1;
      for (auto f : {+[](const LayerRow& r) { return fmt(r.stats.max_clipped_rel, 3); },
                     +[](const LayerRow& r) { return fmt(100 * r.curved_fraction(), 3) + " %"; },
                     +[](const LayerRow& r) { return fmt(r.min_scaled_jacobian, 3); },
                     +[](const LayerRow& r) { return fmt(r.max_aspect_ratio, 4); },
                     +[](const LayerRow& r) {
                       return fmt(r.stats.min_height(), 5) + " .. " + fmt(r.stats.max_height(), 5);
                     }})
        o << " | " << cell(a, k, f) << " | " << cell(b, k, f);
      o << " |\n";
    }
  }
  o << "\n## Runs\n\n| run | exit | invalid | layers | linear after | s_max | wall edge mean | min SJ | max AR | time s |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const StudyRun& r : runs)
    o << "| " << r.name << " | " << r.code() << (r.error.empty() ? "" : " (" + r.error + ")") << " | "
      << (r.ran ? std::to_string(r.out.report.cells_invalid) : "—") << " | " << r.layers() << " | "
      << linear_text(r.out.linear_after) << " | " << fmt(r.out.max_chord_offset, 3) << " | "
      << fmt(r.ran ? r.out.wall_edge_mean : nan, 3) << " | " << fmt(r.min_sj(), 3)
      << " | " << fmt(r.ran ? r.out.report.aspect_ratio_max : nan, 4) << " | " << fmt(r.seconds, 3) << " |\n";
  return o.str();
}

// Draws the charts and pictures; each that cannot be drawn (no drawable point, a run without its
// picture, a file error) is left out with a note instead of ending the study.
void write_charts(const Study& st, const std::vector<StudyRun>& runs, const std::vector<Pair>& pairs, const fs::path& out,
                  std::vector<fs::path>& written, std::vector<std::string>& notes) {
  auto draw = [&](const fs::path& p, const std::function<void()>& f) {
    try {
      f();
      written.push_back(p);
    } catch (const Error& e) {
      notes.push_back(p.filename().string() + " not drawn: " + e.what());
    }
  };
  // Per case: max clip / h against layer, 2D solid and 3D dashed, one colour per f_atten at the
  // case's own h0 (one chart per partner).
  for (const StudyCase& sc : st.cases)
    for (const std::string partner : {"extrusion", "sphere"}) {
      std::vector<ChartSeries> series;
      int color = 0;
      for (const Pair& p : pairs) {
        if (p.r2->sc != &sc || p.r3->partner != partner || p.r2->h0 != sc.h0) continue;
        for (const StudyRun* r : {p.r2, p.r3}) {
          ChartSeries s;
          s.label = std::string(r->dim() == 2 ? "2D" : partner) + " f " + num(r->f_atten);
          s.color = color;
          s.dashed = r->dim() == 3;
          for (const LayerRow& row : r->out.layers) {
            s.x.push_back(row.stats.layer);
            s.y.push_back(row.stats.max_clipped_rel);
          }
          series.push_back(s);
        }
        ++color;
      }
      if (series.empty()) continue;
      ChartOptions o;
      o.title = sc.name + ": 2D section (solid) and its " + partner + " (dashed), h0 " + num(sc.h0);
      o.x_label = "layer";
      o.y_label = "max attenuation move still needed / layer height";
      const fs::path p = out / (sc.name + "_" + partner + "_clip.png");
      draw(p, [&] { write_chart_png(series, p, o); });
    }
  // Linear-after against f_atten (at each case's h0) and against h0 (at each case's f_atten).
  for (const bool against_f : {true, false}) {
    std::vector<ChartSeries> series;
    int color = 0;
    for (const StudyCase& sc : st.cases) {
      for (const std::string partner : {"section", "extrusion", "sphere"}) {
        ChartSeries s;
        s.label = sc.name + " " + (partner == "section" ? "2D" : partner);
        s.color = color;
        s.dashed = partner != "section";
        std::vector<std::pair<double, double>> pts;
        for (const StudyRun& r : runs) {
          if (r.sc != &sc || r.partner != partner) continue;
          if (against_f ? r.h0 != sc.h0 : r.f_atten != sc.f_atten) continue;
          pts.emplace_back(against_f ? r.f_atten : r.h0, r.out.linear_after < 0 ? nan : r.out.linear_after);
        }
        std::sort(pts.begin(), pts.end());
        for (const auto& [x, y] : pts) s.x.push_back(x), s.y.push_back(y);
        if (!pts.empty()) {
          series.push_back(s);
          ++color;  // each series its own colour: a 3D partner that equals its section stays visible
        }
      }
    }
    ChartOptions o;
    o.title = against_f ? "Front linear after layer k, against f_atten (each case at its h0)"
                        : "Front linear after layer k, against h0 (each case at its f_atten)";
    o.x_label = against_f ? "f_atten" : "h0 (first layer height)";
    o.y_label = "linear after layer";
    o.log_x = true;
    const fs::path p = out / (against_f ? "linear_after_f_atten.png" : "linear_after_h0.png");
    draw(p, [&] { write_chart_png(series, p, o); });
  }
  // The base runs' pictures side by side: the 2D mesh and the 3D mid-span cut (or sphere cut).
  for (const Pair& p : pairs) {
    if (!p.r2->base || !p.r2->ran || !p.r3->ran) continue;
    const fs::path a = p.r2->out.base.string() + ".png", b = p.r3->out.base.string() + ".png";
    const fs::path to = out / (p.r2->sc->name + "_" + p.r3->partner + "_side_by_side.png");
    draw(to, [&] {
      write_side_by_side_png({a, b},
                             {"2D: " + p.r2->name,
                              "3D: " + p.r3->name + (p.r3->partner == "extrusion" ? " (mid-span cut)" : " (cut z = 0)")},
                             p.r2->sc->name + ": the 2D layers beside the 3D layers", to);
    });
  }
}

}  // namespace

void check_study(const std::string& yaml_text, const fs::path& file) {
  load_study(ConfigNode::load_string(yaml_text, file.string()), file);
}

int compare_attenuation_command(const fs::path& study_path, const std::optional<fs::path>& out_dir) {
  register_all_plugins();
  const Study st = load_study(study_path);
  const fs::path out = out_dir ? *out_dir : fs::path("out") / st.name;
  std::vector<StudyRun> runs = plan_runs(st, out);  // every configuration checked first
  try {
    fs::create_directories(out / "configs");
    fs::create_directories(out / "runs");
  } catch (const fs::filesystem_error& e) {
    throw InputError(out.string() + ": cannot create the study's output folder (" + e.code().message() + ")");
  }
  for (const StudyRun& r : runs) write_text(r.config.file, r.text);
  std::cout << "study " << st.name << ": " << st.cases.size() << " cases, " << runs.size() << " runs into "
            << out.string() << "\n";

  const auto t0 = std::chrono::steady_clock::now();
  for (StudyRun& r : runs) {
    const auto start = std::chrono::steady_clock::now();
    try {
      r.out = run_config(r.config, true);
      r.out.mesh2.reset();  // the study keeps every run's numbers, not its mesh
      r.out.mesh3.reset();
      r.ran = true;
    } catch (const Error& e) {  // a mesher failure (or an output that cannot be written): a failed row
      r.error = e.what();
      std::cerr << "plaf: error: " << r.config.file.string() << ": " << e.what() << '\n';
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "  " << std::left << std::setw(44) << r.name << std::right << " exit " << r.code() << ", "
              << std::setw(3) << r.layers() << " layers, linear after " << std::setw(3) << r.out.linear_after
              << ", min SJ " << std::setw(8) << fmt(r.min_sj(), 3) << ", invalid "
              << (r.ran ? std::to_string(r.out.report.cells_invalid) : "—") << " (" << fmt(r.seconds, 3) << " s)\n";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].partner != "section") continue;
    for (std::size_t j = i + 1; j < runs.size() && runs[j].partner != "section"; ++j)
      pairs.push_back(make_pair_result(runs[i], runs[j]));
  }
  bool ok = true;
  for (const StudyRun& r : runs) ok = ok && r.code() == 0;
  for (const Pair& p : pairs) ok = ok && p.pairing_ok;

  // The tables first, then the charts (a chart that cannot be drawn is a note), the JSON last.
  write_text(out / (st.name + "_runs.csv"), runs_csv(runs));
  write_text(out / (st.name + "_layers.csv"), layers_csv(runs));
  write_text(out / (st.name + "_pairs.csv"), pairs_csv(pairs));
  write_text(out / (st.name + ".md"), markdown(st, runs, pairs, ok, seconds));
  std::vector<fs::path> written;
  std::vector<std::string> notes;
  write_charts(st, runs, pairs, out, written, notes);
  for (const std::string& n : notes) std::cerr << "plaf: note: " << n << '\n';
  std::vector<std::string> run_rows, pair_rows, pictures, note_rows;
  for (const StudyRun& r : runs) run_rows.push_back(run_json(r));
  for (const Pair& p : pairs) pair_rows.push_back(pair_json(p));
  for (const fs::path& p : written) pictures.push_back(json_string(p.string()));
  for (const std::string& n : notes) note_rows.push_back(json_string(n));
  const std::string json = "{\"study\": " + json_string(st.name) + ", \"file\": " + json_string(study_path.string()) +
                           ", \"order\": " + std::to_string(st.order) + ", \"ok\": " + (ok ? "true" : "false") +
                           ", \"seconds\": " + json_number(seconds) + ", \"runs\": " + json_array(run_rows) +
                           ", \"pairs\": " + json_array(pair_rows) + ", \"pictures\": " + json_array(pictures) +
                           ", \"notes\": " + json_array(note_rows) + "}\n";
  write_text(out / (st.name + ".json"), json);
  std::cout << "study " << st.name << ": " << runs.size() << " runs in " << fmt(seconds, 3) << " s; "
            << (ok ? "every run valid, every pairing holds" : "NOT every run valid or paired") << "; tables in "
            << (out / (st.name + ".md")).string() << "\n";
  if (!ok) {
    std::cerr << "plaf: error: " << study_path.string() << ": not every run exits 0 with 0 invalid cells or pairs honestly (see "
              << (out / (st.name + ".md")).string() << ")\n";
    return 2;
  }
  return 0;
}

}  // namespace plaf
