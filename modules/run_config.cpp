// SPDX-License-Identifier: MIT
// Strict parsing of the run configuration (keys and defaults documented in run_config.h).
#include "modules/run_config.h"

#include <algorithm>

#include "modules/config.h"
#include "modules/error.h"
#include "modules/lagrange.h"
#include "modules/metric_fields.h"
#include "modules/writers.h"

namespace plaf {

bool OutputParams::wants(const std::string& f) const {
  return std::find(formats.begin(), formats.end(), f) != formats.end();
}

namespace {

RunConfig parse(const ConfigNode& c, const std::string& stem) {
  RunConfig r;
  r.name = c.get_string("name", stem);
  if (r.name.empty() || r.name.find('/') != std::string::npos)
    throw ConfigError(c.where("name") + ": must be a plain file name, got '" + r.name + "'");
  r.order = c.get_int("order", r.order, 1, max_order);

  const ConfigNode g = c.child("geometry");
  r.geometry.type = g.get_choice("type", r.geometry.type, {"annulus"});
  r.geometry.where = g.where("type");
  if (r.geometry.type == "annulus") {
    AnnulusParams& a = r.geometry.annulus;
    a.r_inner = g.get_positive("r_inner", a.r_inner);
    a.r_outer = g.get_positive("r_outer", a.r_outer);
    if (a.r_outer <= a.r_inner) throw ConfigError(g.where("r_outer") + ": must be larger than r_inner");
    a.angle_deg = g.get_in_range("angle_deg", a.angle_deg, 1e-6, 360.0);
    a.triangles = g.get_choice("cells", "quad", {"quad", "tri"}) == "tri";
  }

  const ConfigNode m = c.child("metric");
  r.metric.type = m.get_string("type", r.metric.type);
  r.metric.where = m.where("type");
  if (!metric_field_registry().contains(r.metric.type)) make_metric_field(r);  // throws, listing the known types
  if (r.metric.type == "uniform") {
    UniformMetricParams& u = r.metric.uniform;
    u.h = m.get_positive("h", u.h);
    u.sizes = m.get_double_list("sizes", {});
    if (!u.sizes.empty()) {
      if (m.has("h")) throw ConfigError(m.where("sizes") + ": give either h or sizes, not both");
      if (u.sizes.size() != 2) throw ConfigError(m.where("sizes") + ": expected two sizes [h1, h2]");
      for (double s : u.sizes)
        if (!(s > 0)) throw ConfigError(m.where("sizes") + ": sizes must be positive");
    }
    u.angle_deg = m.get_double("angle_deg", u.angle_deg);
  }

  const ConfigNode v = c.child("validity");
  r.validity.rel_tol = v.get_in_range("rel_tol", r.validity.rel_tol, 1e-6, 1.0);
  r.validity.max_depth = v.get_int("max_depth", r.validity.max_depth, 1, 20);

  const ConfigNode o = c.child("output");
  r.output.dir = o.get_string("dir", r.output.dir.string());
  r.output.formats = o.get_string_list("formats", r.output.formats, writer_registry().names());
  r.output.picture_width = o.get_int("picture_width", r.output.picture_width, 64, 16384);
  r.output.picture_height = o.get_int("picture_height", r.output.picture_height, 64, 16384);
  r.output.histogram_bins = o.get_int("histogram_bins", r.output.histogram_bins, 2, 1000);

  c.finish();
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

}  // namespace plaf
