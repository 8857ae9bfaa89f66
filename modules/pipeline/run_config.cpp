// SPDX-License-Identifier: MIT
// Strict parsing of the run configuration (keys and defaults documented in run_config.h).
#include "modules/pipeline/run_config.h"

#include <algorithm>
#include <cmath>

#include "modules/pipeline/config.h"
#include "modules/base/error.h"
#include "modules/elements/lagrange.h"
#include "modules/metric/metric_fields.h"
#include "modules/pipeline/stages.h"
#include "modules/io/writers.h"

namespace plaf {
inline namespace pipeline {

bool OutputParams::wants(const std::string& f) const {
  return std::find(formats.begin(), formats.end(), f) != formats.end();
}

namespace {

std::array<double, 2> get_pair(const ConfigNode& n, const std::string& key, std::array<double, 2> fallback) {
  const std::vector<double> v = n.get_double_list(key, {fallback[0], fallback[1]});
  if (v.size() != 2) throw ConfigError(n.where(key) + ": expected two numbers [a, b]");
  return {v[0], v[1]};
}

void parse_airfoils(const ConfigNode& g, AirfoilsParams& a) {
  const std::vector<ConfigNode> bodies = g.child_list("bodies");
  if (bodies.empty()) throw ConfigError(g.where("bodies") + ": give at least one body: [{file: contour.dat}]");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ConfigNode& b = bodies[i];
    BodyParams body;
    body.file = b.get_path("file", "");
    if (body.file.empty()) throw ConfigError(b.where() + ": file is required");
    body.name = b.get_string("name", i == 0 ? "wall" : "wall_" + std::to_string(i + 1));
    // A body tagged "farfield" would merge with the farfield loop's tag (and make it a wall).
    if (body.name.empty() || body.name == "farfield")
      throw ConfigError(b.where("name") + ": '" + body.name +
                        "' cannot tag a body (\"farfield\" is the farfield's tag)");
    body.corners = b.get_point_list("corners");
    a.bodies.push_back(body);
  }
  a.corner_angle_deg = g.get_in_range("corner_angle_deg", a.corner_angle_deg, 0.0, 180.0);
  const ConfigNode f = g.child("farfield");
  FarfieldParams& ff = a.farfield;
  ff.shape = f.get_choice("shape", ff.shape, {"circle", "rectangle"});
  ff.radius = f.get_positive("radius", ff.radius);
  ff.size = get_pair(f, "size", ff.size);
  if (!(ff.size[0] > 0 && ff.size[1] > 0)) throw ConfigError(f.where("size") + ": sizes must be positive");
  ff.has_center = f.has("center");
  ff.center = get_pair(f, "center", ff.center);
}

std::array<double, 3> get_triple(const ConfigNode& n, const std::string& key, std::array<double, 3> fallback) {
  const std::vector<double> v = n.get_double_list(key, {fallback[0], fallback[1], fallback[2]});
  if (v.size() != 3) throw ConfigError(n.where(key) + ": expected three numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

bool is_3d_geometry(const std::string& type) {
  return type == "sphere" || type == "ellipsoid" || type == "box" || type == "wing" || type == "surface_file";
}

void parse_surface3(const ConfigNode& g, const std::string& type, Surface3Params& s) {
  if (type == "sphere" || type == "ellipsoid") s.center = get_triple(g, "center", s.center);
  if (type == "sphere") s.radius = g.get_positive("radius", s.radius);
  if (type == "ellipsoid") {
    s.semi_axes = get_triple(g, "semi_axes", s.semi_axes);
    for (double a : s.semi_axes)
      if (!(a > 0)) throw ConfigError(g.where("semi_axes") + ": semi-axes must be positive");
  }
  if (type == "box") {
    s.lo = get_triple(g, "lo", s.lo);
    s.hi = get_triple(g, "hi", s.hi);
    for (int k = 0; k < 3; ++k)
      if (!(s.hi[k] > s.lo[k])) throw ConfigError(g.where("hi") + ": every coordinate must exceed lo's");
  }
  if (type == "wing") {
    s.file = g.get_path("file", "");
    if (s.file.empty()) throw ConfigError(g.where() + ": file (the airfoil section) is required for a wing");
    s.chord = g.get_positive("chord", s.chord);
    s.span = g.get_positive("span", s.span);
    s.root = g.get_choice("root", s.root, {"flat", "rounded", "symmetry"});
    s.tip = g.get_choice("tip", s.tip, {"flat", "rounded", "symmetry"});
    s.corner_angle_deg = g.get_in_range("corner_angle_deg", s.corner_angle_deg, 0.0, 180.0);
    if (!(s.corner_angle_deg > 0 && s.corner_angle_deg < 180))
      throw ConfigError(g.where("corner_angle_deg") + ": must lie strictly between 0 and 180");
  }
  if (type == "surface_file") {
    s.file = g.get_path("file", "");
    if (s.file.empty()) throw ConfigError(g.where() + ": file is required for a surface_file geometry");
    s.weld_rel = g.get_in_range("weld_rel", s.weld_rel, 0.0, 0.1);
    for (const ConfigNode& p : g.child_list("symmetry_planes")) {
      SymmetryPlaneParams plane;
      if (!p.has("normal")) throw ConfigError(p.where() + ": normal is required ([nx, ny, nz])");
      plane.normal = get_triple(p, "normal", plane.normal);
      const double len = std::sqrt(plane.normal[0] * plane.normal[0] + plane.normal[1] * plane.normal[1] +
                                   plane.normal[2] * plane.normal[2]);
      if (!(len > 0)) throw ConfigError(p.where("normal") + ": the plane normal must not be zero");
      for (double& x : plane.normal) x /= len;
      plane.offset = p.get_double("offset", plane.offset) / len;
      s.symmetry_planes.push_back(plane);
    }
    s.check_self_intersections = g.get_choice("self_intersections", "check", {"check", "skip"}) == "check";
    s.drop_inner_components = g.get_choice("inner_components", "error", {"error", "drop"}) == "drop";
  }
}

// The geometry type; a 3D type reads its surface keys here.
void parse_geometry_type(const ConfigNode& g, RunConfig& r) {
  r.geometry.type = g.get_choice("type", r.geometry.type,
                                  {"annulus", "airfoils", "sphere", "ellipsoid", "box", "wing", "surface_file"});
  r.geometry.where = g.where("type");
  if (is_3d_geometry(r.geometry.type)) {
    r.dim = 3;
    parse_surface3(g, r.geometry.type, r.geometry.surface3);
  }
}

// Where the surface section and its curvature_h_min are: checked against the rest of the run
// once every key is read (check_across_sections).
struct SurfaceWhere {
  std::string section;  // empty: no surface section
  std::string curvature_h_min;
};

SurfaceWhere parse_surface(const ConfigNode& c, SurfaceParams& sp) {
  SurfaceWhere where;
  if (!c.has("surface")) return where;
  const ConfigNode sf = c.child("surface");
  sp.ridge_angle_deg = sf.get_in_range("ridge_angle_deg", sp.ridge_angle_deg, 0.0, 180.0);
  sp.corner_defect_deg = sf.get_in_range("corner_defect_deg", sp.corner_defect_deg, 0.0, 360.0);
  sp.curve_turn_deg = sf.get_in_range("curve_turn_deg", sp.curve_turn_deg, 0.0, 180.0);
  sp.remesh = sf.get_bool("remesh", sp.remesh);
  sp.iterations = sf.get_int("iterations", sp.iterations, 1, 100);
  sp.curvature_factor = sf.get_in_range("curvature_factor", sp.curvature_factor, 0.0, 100.0);
  sp.curvature_h_min = sf.get_positive("curvature_h_min", 1.0);
  if (!sf.has("curvature_h_min")) sp.curvature_h_min = 0;
  sp.max_triangles = sf.get_int("max_triangles", sp.max_triangles, 1, 2000000000);
  where.curvature_h_min = sf.where("curvature_h_min");
  where.section = sf.where();
  return where;
}

// The keys of the 2D geometry types.
void parse_geometry_2d(const ConfigNode& g, GeometryParams& geometry) {
  if (geometry.type == "annulus") {
    AnnulusParams& a = geometry.annulus;
    a.r_inner = g.get_positive("r_inner", a.r_inner);
    a.r_outer = g.get_positive("r_outer", a.r_outer);
    if (a.r_outer <= a.r_inner) throw ConfigError(g.where("r_outer") + ": must be larger than r_inner");
    a.angle_deg = g.get_in_range("angle_deg", a.angle_deg, 1e-6, 360.0);
    a.triangles = g.get_choice("cells", "quad", {"quad", "tri"}) == "tri";
  } else if (geometry.type == "airfoils") {
    parse_airfoils(g, geometry.airfoils);
  }
}

void parse_metric(const ConfigNode& m, RunConfig& r) {
  r.metric.type = m.get_string("type", r.metric.type);
  r.metric.where = m.where("type");
  metric_field_registry().require(r.metric.type, r.metric.where);
  if (r.dim == 3 && r.metric.type != "uniform")
    throw ConfigError(r.metric.where + ": metric type '" + r.metric.type +
                      "' is 2D only; 3D surfaces take a uniform metric (h or sizes [hx, hy, hz])");
  if (r.metric.type == "uniform") {
    UniformMetricParams& u = r.metric.uniform;
    u.h = m.get_positive("h", u.h);
    u.sizes = m.get_double_list("sizes", {});
    if (!u.sizes.empty()) {
      if (m.has("h")) throw ConfigError(m.where("sizes") + ": give either h or sizes, not both");
      if (static_cast<int>(u.sizes.size()) != r.dim)
        throw ConfigError(m.where("sizes") + (r.dim == 2 ? ": expected two sizes [h1, h2]"
                                                         : ": expected three sizes [hx, hy, hz]"));
      for (double s : u.sizes)
        if (!(s > 0)) throw ConfigError(m.where("sizes") + ": sizes must be positive");
    }
    if (r.dim == 2) u.angle_deg = m.get_double("angle_deg", u.angle_deg);  // 3D: sizes along x, y, z
  } else if (r.metric.type == "wall_power_law") {
    WallLawParams& w = r.metric.wall_law;
    w.h0 = m.get_positive("h0", w.h0);
    w.growth = m.get_in_range("growth", w.growth, 1.0, 10.0);
    if (!(w.growth > 1)) throw ConfigError(m.where("growth") + ": must be larger than 1 (layers grow)");
    w.exponential = m.get_choice("law", "linear", {"linear", "exponential"}) == "exponential";
    w.delta = m.get_positive("delta", w.h0);
    w.h_max = m.get_positive("h_max", w.h_max);
    w.h_wall_max = m.get_positive("h_wall_max", w.h_wall_max);
    w.curvature_factor = m.get_positive("curvature_factor", w.curvature_factor);
    w.h_corner = m.get_positive("h_corner", w.h_corner);
    if (w.h0 > w.h_max) throw ConfigError(m.where("h0") + ": must not exceed h_max");
  } else if (r.metric.type == "background") {
    BackgroundParams& b = r.metric.background;
    b.file = m.get_path("file", "");
    if (b.file.empty()) throw ConfigError(m.where() + ": file is required for a background metric");
    b.sol = m.get_path("sol", "");
    b.mean = m.get_choice("mean", b.mean, {"log_euclidean", "affine_invariant"});
  }
}

// Plugin sections: the chosen type's factory parses and checks its own keys (stages.h).
void plan_stages(const ConfigNode& c, RunConfig& r) {
  auto plan = [&](StageKind kind, const std::string& fallback_type, PlannedStage& out) {
    const std::string key = stage_kind_name(kind);
    if (!c.has(key)) return;
    const ConfigNode s = c.child(key);
    out.type = s.get_string("type", fallback_type);
    out.where = s.where("type");
    out.section = s.where();
    if (r.dim == 2)
      out.run2 = stage_registry<2>(kind).create(out.type, out.where, s, r);
    else
      out.run3 = stage_registry<3>(kind).create(out.type, out.where, s, r);
  };
  r.surface_type = r.dim == 3 ? "remesh" : r.geometry.type == "annulus" ? "annulus" : "curves";
  if (c.has("layers") && r.geometry.type != "airfoils")
    throw ConfigError(c.child("layers").where() + ": layers need a spline geometry (type airfoils)");
  plan(StageKind::Layers, "extrude", r.layers);
  plan(StageKind::Fill, "advancing_front", r.fill);
}

void parse_output(const ConfigNode& o, int dim, OutputParams& out) {
  out.dir = o.get_string("dir", out.dir.string());
  if (dim == 3) out.formats = {"msh", "vtu", "report"};
  out.formats = o.get_string_list("formats", out.formats, writer_registry<2>().names());
  if (dim == 3 && out.wants("png"))
    throw ConfigError(o.where("formats") + ": png pictures are 2D only (3D runs write msh, vtu, report)");
  out.histogram_bins = o.get_int("histogram_bins", out.histogram_bins, 2, 1000);
  if (dim == 2) {  // pictures and the 2D mesh options (3D runs: unknown keys)
    out.picture_width = o.get_int("picture_width", out.picture_width, 64, 16384);
    out.picture_height = o.get_int("picture_height", out.picture_height, 64, 16384);
    out.uniform_order = o.get_bool("uniform_order", out.uniform_order);
    out.split_quads = o.get_bool("split_quads", out.split_quads);
    for (const ConfigNode& z : o.child_list("zooms")) {
      OutputParams::Zoom zoom;
      zoom.label = z.get_string("label", "");
      const std::vector<double> box = z.get_double_list("box", {});
      if (box.size() != 4 || !(box[1] > box[0]) || !(box[3] > box[2]))
        throw ConfigError(z.where("box") + ": expected [x_min, x_max, y_min, y_max] with min < max");
      zoom.box = {box[0], box[1], box[2], box[3]};
      out.zooms.push_back(zoom);
    }
  }
}

// What one section cannot check alone, once every key has been read.
void check_across_sections(const RunConfig& r, const SurfaceWhere& surface_where) {
  if (r.dim == 3 && r.surface.curvature_h_min > 0) {
    const UniformMetricParams& u = r.metric.uniform;
    const double smallest = u.sizes.empty() ? u.h : *std::min_element(u.sizes.begin(), u.sizes.end());
    if (r.surface.curvature_h_min >= smallest)
      throw ConfigError(surface_where.curvature_h_min + ": " + std::to_string(r.surface.curvature_h_min) +
                        " must be smaller than the metric's smallest size " + std::to_string(smallest));
  }
  if (!surface_where.section.empty() && r.dim != 3)
    throw ConfigError(surface_where.section +
                      ": the surface section is for 3D geometries (sphere, ellipsoid, box, wing, "
                      "surface_file)");
  if (r.fill.enabled() && r.geometry.type != "airfoils")
    throw ConfigError(r.fill.section + ": the fill needs a spline geometry (type airfoils)");
}

RunConfig parse(const ConfigNode& c, const std::string& stem) {
  RunConfig r;
  // 1. Name and order.
  r.name = c.get_string("name", stem);
  if (r.name.empty() || r.name.find('/') != std::string::npos)
    throw ConfigError(c.where("name") + ": must be a plain file name, got '" + r.name + "'");
  r.order = c.get_int("order", r.order, 1, max_order);
  // 2. The geometry and the surface section (read between the geometry type and the 2D keys,
  //    which keeps the order in which errors are found).
  const ConfigNode g = c.child("geometry");
  parse_geometry_type(g, r);
  const SurfaceWhere surface_where = parse_surface(c, r.surface);
  parse_geometry_2d(g, r.geometry);
  // 3. The metric, 4. the plugin stages, 5. validity, 6. output.
  parse_metric(c.child("metric"), r);
  plan_stages(c, r);
  const ConfigNode v = c.child("validity");
  r.validity.rel_tol = v.get_in_range("rel_tol", r.validity.rel_tol, 1e-6, 1.0);
  r.validity.max_depth = v.get_int("max_depth", r.validity.max_depth, 1, 20);
  parse_output(c.child("output"), r.dim, r.output);
  // 7. No unknown key, then the checks across sections.
  c.finish();
  check_across_sections(r, surface_where);
  return r;
}

}  // namespace

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
