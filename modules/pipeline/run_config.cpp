// SPDX-License-Identifier: MIT
// Strict parsing of the run configuration (keys and defaults documented in run_config.h).
#include "modules/pipeline/run_config.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/pipeline/config.h"
#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/elements/lagrange.h"
#include "modules/io/text_cursor.h"
#include "modules/pipeline/stages.h"
#include "modules/pipeline/writers.h"

namespace plaf {
inline namespace pipeline {

bool OutputParams::wants(const std::string& f) const {
  return std::find(formats.begin(), formats.end(), f) != formats.end();
}

namespace {

// Zoom panels and cut pictures a run draws at most (each is a picture's work: unbounded, a
// config of a million zooms ran for hours; issue 37, item 5).
constexpr std::size_t kMaxPictures = 64;
// The longest run name: every output is NAME + an extension (NAME_boundary.vtu, NAME.cut64.png),
// and a file name holds 255 bytes on the common file systems.
constexpr std::size_t kMaxNameBytes = 200;

// The output section (formats, pictures, histogram bins, and the 2D mesh options).
void parse_output(const ConfigNode& o, RunConfig& r) {
  r.output.dir = o.get_string("dir", r.output.dir.string());
  r.output.formats = o.get_string_list("formats", r.output.formats, writer_registry<2>().names());
  if (r.output.formats.empty()) {
    std::string known;
    for (const std::string& f : writer_registry<2>().names()) known += (known.empty() ? "" : ", ") + f;
    throw ConfigError(o.where("formats") + ": an empty list writes nothing; give at least one of " + known);
  }
  r.output.msh = o.get_choice("msh", r.output.msh, {"auto", "ascii", "binary"});
  r.output.vtu = o.get_choice("vtu", r.output.vtu, {"auto", "ascii", "binary"});
  r.output.histogram_bins = o.get_int("histogram_bins", r.output.histogram_bins, 2, 1000);
  r.output.picture_width = o.get_int("picture_width", r.output.picture_width, 64, 16384);
  r.output.picture_height = o.get_int("picture_height", r.output.picture_height, 64, 16384);
  auto vector3 = [](const ConfigNode& n, const std::string& key, std::array<double, 3> fallback, bool nonzero) {
    const std::vector<double> v = n.get_double_list(key, {fallback[0], fallback[1], fallback[2]});
    if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) ||
        (nonzero && v[0] == 0 && v[1] == 0 && v[2] == 0))
      throw ConfigError(n.where(key) + ": expected [x, y, z]" + (nonzero ? std::string(", not all zero") : std::string()));
    return std::array<double, 3>{v[0], v[1], v[2]};
  };
  if (r.dim == 3) {  // the 3D picture's plane and view (2D runs: unknown keys)
    if (o.has("cut")) {
      const ConfigNode c = o.child("cut");
      r.output.has_cut = true;
      r.output.cut_point = vector3(c, "point", r.output.cut_point, false);
      r.output.cut_normal = vector3(c, "normal", r.output.cut_normal, true);
    }
    const std::vector<ConfigNode> cuts = o.child_list("cuts");
    if (cuts.size() > kMaxPictures)
      throw ConfigError(o.where("cuts") + ": " + std::to_string(cuts.size()) + " cuts; at most " +
                        std::to_string(kMaxPictures) + " (a picture each)");
    for (const ConfigNode& c : cuts) {
      OutputParams::Cut cut;
      if (!c.has("point") || !c.has("normal")) throw ConfigError(c.where() + ": a cut needs its point and normal");
      cut.point = vector3(c, "point", cut.point, false);
      cut.normal = vector3(c, "normal", cut.normal, true);
      cut.radius = c.get_in_range("radius", 0.0, 0.0, std::numeric_limits<double>::max());  // 0: no zoom panel
      cut.label = c.get_string("label", "");
      r.output.cuts.push_back(cut);
    }
    if (!r.output.cuts.empty() && std::find(r.output.formats.begin(), r.output.formats.end(), "png") == r.output.formats.end())
      throw ConfigError(o.where("cuts") + ": the cut pictures are PNG files: add png to output.formats");
    r.output.view = vector3(o, "view", r.output.view, true);
  }
  {
    if (r.dim == 2) {  // the 2D mesh options (3D runs: unknown keys)
      r.output.uniform_order = o.get_bool("uniform_order", r.output.uniform_order);
      r.output.split_quads = o.get_bool("split_quads", r.output.split_quads);
    }
    const std::vector<ConfigNode> zooms = o.child_list("zooms");
    if (zooms.size() > kMaxPictures)
      throw ConfigError(o.where("zooms") + ": " + std::to_string(zooms.size()) + " zooms; at most " +
                        std::to_string(kMaxPictures) + " panels");
    for (const ConfigNode& z : zooms) {
      OutputParams::Zoom zoom;
      zoom.label = z.get_string("label", "");
      const std::vector<double> box = z.get_double_list("box", {});
      if (box.size() != 4 || !(box[1] > box[0]) || !(box[3] > box[2]))
        throw ConfigError(z.where("box") + ": expected [x_min, x_max, y_min, y_max] with min < max");
      zoom.box = {box[0], box[1], box[2], box[3]};
      r.output.zooms.push_back(zoom);
    }
  }

}

RunConfig parse(const ConfigNode& c, const std::string& stem) {
  RunConfig r;
  r.name = c.get_string("name", stem);
  // A plain file name: printable, not hidden, no folder in it, short enough for every extension
  // (issue 37, items 5 and 8: names with a newline or a leading dot were accepted, and a 50 MB
  // one was found too long only after meshing).
  const bool printable = std::none_of(r.name.begin(), r.name.end(), [](char ch) {
    const auto u = static_cast<unsigned char>(ch);
    return u < 0x20 || u == 0x7f || ch == '/' || ch == '\\';
  });
  if (r.name.empty() || !printable || r.name.front() == '.' || r.name.size() > kMaxNameBytes)
    throw ConfigError(c.where("name") + ": must be a plain file name (printable, no / or \\, not starting with '.', at most " +
                      std::to_string(kMaxNameBytes) + " bytes), got " + TextCursor::quote(r.name) +
                      " (" + std::to_string(r.name.size()) + " bytes)");
  r.order = c.get_int("order", r.order, 1, max_order);

  // The geometry's type decides the run's dimension; its plugin parses the section (stages.h).
  const ConfigNode g = c.child("geometry");
  std::vector<std::string> geometry_types = stage_registry<2>(StageKind::Geometry).names();
  for (const std::string& t : stage_registry<3>(StageKind::Geometry).names()) geometry_types.push_back(t);
  const std::string geometry_type = g.get_choice("type", "annulus", geometry_types);
  if (stage_registry<3>(StageKind::Geometry).contains(geometry_type)) r.dim = 3;
  // An extruded section: the section's stages stay 2D, the run is 3D.
  if (c.has("extrude")) {
    const ConfigNode e = c.child("extrude");
    if (r.dim == 3 || geometry_type != "airfoils")
      throw ConfigError(e.where() + ": extrude takes a 2D section of type airfoils, not geometry type '" +
                        geometry_type + "'");
    ExtrudeParams x;
    if (!e.has("span")) throw ConfigError(e.where() + ": span is required");
    x.span = e.get_positive("span", x.span);
    x.rows = e.get_int("rows", x.rows, 1, 1000);
    if (e.has("hz")) x.hz = e.get_positive("hz", 1.0);
    r.extrude = x;
    r.dim = 3;
  }
  const int section_dim = r.extrude ? 2 : r.dim;  // the dimension of geometry, metric and surface

  // The metric's type; its plugin parses the section (stages.h). A 2D type missing from the 3D
  // registry (none today) is named as such.
  const ConfigNode m = c.child("metric");
  const std::string metric_type = m.get_string("type", "uniform");
  if (section_dim == 3 && !stage_registry<3>(StageKind::Metric).contains(metric_type) &&
      stage_registry<2>(StageKind::Metric).contains(metric_type)) {
    std::string types;
    for (const std::string& t : stage_registry<3>(StageKind::Metric).names()) types += (types.empty() ? "" : ", ") + t;
    throw ConfigError(m.where("type") + ": metric type '" + metric_type + "' is 2D only; 3D runs take: " + types);
  }

  // Stage sections: the chosen type's factory parses and checks its own keys (stages.h).
  auto plan = [&](StageKind kind, const std::string& type, const ConfigNode& s, PlannedStage& out) {
    out.type = type;
    out.where = s.where("type");
    out.section = s.where();
    const bool section_stage = kind == StageKind::Geometry || kind == StageKind::Metric || kind == StageKind::Surface;
    if ((section_stage ? section_dim : r.dim) == 2)
      out.run2 = stage_registry<2>(kind).create(out.type, out.where, s);
    else
      out.run3 = stage_registry<3>(kind).create(out.type, out.where, s);
  };
  plan(StageKind::Geometry, geometry_type, g, r.geometry);
  plan(StageKind::Metric, metric_type, m, r.metric);
  // metric.intersect: further fields the run's metric is intersected with (a refinement band
  // given on a background mesh over a wall law, say); each item is a metric section of its own.
  if (m.has("intersect")) {
    const std::vector<ConfigNode> more = m.child_list("intersect");
    if (more.empty()) throw ConfigError(m.where("intersect") + ": give a list of metric sections, e.g. [{type: background, file: band.msh}]");
    std::vector<Stage<2>> more2;
    std::vector<Stage<3>> more3;
    for (const ConfigNode& item : more) {
      if (!item.has("type")) throw ConfigError(item.where() + ": each metric to intersect needs its type");
      PlannedStage planned;
      plan(StageKind::Metric, item.get_string("type", ""), item, planned);
      if (planned.run2) more2.push_back(planned.run2);
      if (planned.run3) more3.push_back(planned.run3);
    }
    if (r.metric.run2) r.metric.run2 = intersect_metric_stages<2>(r.metric.run2, more2);
    if (r.metric.run3) r.metric.run3 = intersect_metric_stages<3>(r.metric.run3, more3);
  }
  // The surface mesh follows from the geometry: curves of the spline loops or the annulus' exact
  // map in 2D (no section), the remesher in 3D (whose section holds its keys and may name it).
  const ConfigNode sf = c.child("surface");
  if (c.has("surface") && section_dim != 3)
    throw ConfigError(sf.where() + ": the surface section is for 3D geometries (sphere, ellipsoid, box, wing, "
                      "surface_file)");
  plan(StageKind::Surface,
       section_dim == 3 ? sf.get_string("type", "remesh") : geometry_type == "annulus" ? "annulus" : "curves", sf,
       r.surface);
  // Layers and fill: type `none` when the section is absent. A type of the other dimension only
  // (the 2D layers and fill on a 3D geometry) says what is missing.
  auto plan_section = [&](StageKind kind, const std::string& default_type, const std::string& needs,
                          PlannedStage& out) {
    const std::string key = stage_kind_name(kind);
    const ConfigNode s = c.child(key);
    const std::string type = c.has(key) ? s.get_string("type", default_type) : "none";
    const int other = r.dim == 2 ? 3 : 2;
    const bool here = r.dim == 2 ? stage_registry<2>(kind).contains(type) : stage_registry<3>(kind).contains(type);
    const bool there = other == 2 ? stage_registry<2>(kind).contains(type) : stage_registry<3>(kind).contains(type);
    if (!here && there) throw ConfigError(s.where() + ": " + needs);
    plan(kind, type, s, out);
    return s;
  };
  const ConfigNode layers_section = plan_section(StageKind::Layers, "extrude", "layers need a spline geometry (type airfoils)", r.layers);
  plan_section(StageKind::Fill, r.dim == 3 ? "tetgen" : "advancing_front",
               r.dim == 3 ? "a 3D fill is type tetgen" : "the fill needs a spline geometry (type airfoils)", r.fill);
  // layers.max: 0 is a surface-only run (the layers' plugin checks the key's range).
  if (layers_section.has("max")) r.layers_max = layers_section.get_int("max", 1, 0, std::numeric_limits<int>::max());
  const bool no_layer = r.layers_max == 0;

  const ConfigNode v = c.child("validity");
  r.validity.rel_tol = v.get_in_range("rel_tol", r.validity.rel_tol, 1e-6, 1.0);
  r.validity.max_depth = v.get_int("max_depth", r.validity.max_depth, 1, 20);

  parse_output(c.child("output"), r);
  {
    const ConfigNode l = c.child("limits");
    r.limits = default_limits(r.dim);
    r.limits.surface_elements = l.get_positive("surface_elements", r.limits.surface_elements);
    r.limits.cells = l.get_positive("cells", r.limits.cells);
    r.limits.nodes = l.get_positive("nodes", r.limits.nodes);
  }
  if (r.extrude && !r.output.has_cut) {  // the picture cuts the extrusion at its measured station
    r.output.has_cut = true;
    r.output.cut_point = {0, 0, r.extrude->probe_z()};
    r.output.cut_normal = {0, 0, 1};
  }

  c.finish();
  // Checked after the keys, so an unknown key is reported first.
  if (r.layers.enabled() && r.dim == 2 && r.geometry.type != "airfoils")
    throw ConfigError(r.layers.section + ": layers need a spline geometry (type airfoils) or a 3D body");
  if (r.fill.enabled() && r.dim == 2 && r.geometry.type != "airfoils")
    throw ConfigError(r.fill.section + ": the fill needs a spline geometry (type airfoils)");
  if (r.fill.enabled() && r.dim == 3 && !r.layers.enabled())
    throw ConfigError(r.fill.section + ": the TetGen fill starts from the layers' outer front; add a layers section");
  // ... nor from none of them (it failed after the surface stage, hinting "fewer layers"; issue 37 item 7).
  if (r.fill.enabled() && no_layer)
    throw ConfigError(layers_section.where("max") + ": 0 grows no layer, and the fill starts from the layers' outer front; "
                      "give at least 1, or leave the fill out");
  return r;
}

}  // namespace

LimitParams default_limits(int dim) {
  if (dim == 2) return {};
  LimitParams l;
  l.surface_elements = 5e5;
  l.cells = 1e7;
  // Peak memory measured per node (whole run, /usr/bin/time): 122 bytes with layers only (the
  // published bullet at Q3, 3.4e6 nodes, 417 MB), 332 with a TetGen fill (onera_m6_hybrid, Q2,
  // 1.4e6 nodes, 476 MB): 5e7 nodes stay under about 17 GB. (3e7 refused the published Orion
  // capsule's layers at Q3, about 4.2e7 nodes, which need about 5 GB.)
  l.nodes = 5e7;
  return l;
}

RunConfig load_run_config(const std::filesystem::path& path) {
  RunConfig r = parse(ConfigNode::load_file(path), path.stem().string());
  r.file = path;
  return r;
}

RunConfig parse_run_config(const std::string& yaml_text, const std::string& name) {
  return parse(ConfigNode::load_string(yaml_text, name), std::filesystem::path(name).stem().string());
}

}  // namespace pipeline
}  // namespace plaf
