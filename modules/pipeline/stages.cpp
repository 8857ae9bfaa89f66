// SPDX-License-Identifier: MIT
// Stage registries and core's own plugins (stages.h).
#include "modules/pipeline/stages.h"

#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/pipeline/writers.h"
#include "modules/mesh/annulus.h"
#include "modules/mesh/curve_mesh.h"
#include "modules/metric/metric_fields.h"
#include "modules/metric/wall_metric_3d.h"
#include "modules/pipeline/run_state.h"

namespace plaf {
inline namespace pipeline {

const char* stage_kind_name(StageKind kind) {
  switch (kind) {
    case StageKind::Geometry: return "geometry";
    case StageKind::Metric: return "metric";
    case StageKind::Surface: return "surface";
    case StageKind::Layers: return "layers";
    case StageKind::Fill: return "fill";
  }
  return "?";
}

template <int Dim>
StageRegistry<Dim>& stage_registry(StageKind kind) {
  static std::vector<StageRegistry<Dim>> registries = [] {
    std::vector<StageRegistry<Dim>> r;
    for (StageKind k : all_stage_kinds) r.emplace_back(std::to_string(Dim) + "D " + stage_kind_name(k) + " type");
    return r;
  }();
  return registries[static_cast<std::size_t>(kind)];
}
template StageRegistry<2>& stage_registry<2>(StageKind);
template StageRegistry<3>& stage_registry<3>(StageKind);

namespace {

// The surface statistics of the 2D loops (curve_mesh.h) as the surface section.
void report_curves(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric,
                   StageReport& rep) {
  const CurveMeshStats s = curve_mesh_stats(front, geometry, metric);
  std::vector<std::string> loops;
  for (const CurveLoopStats& l : s.loops) {
    loops.push_back("{\"tag\": " + json_string(l.tag) + ", \"elements\": " + std::to_string(l.elements) +
                    ", \"nodes\": " + std::to_string(l.nodes) +
                    ", \"metric_length_min\": " + json_number(l.metric_length_min) +
                    ", \"metric_length_max\": " + json_number(l.metric_length_max) + "}");
    std::ostringstream line;
    line << "surface loop " << l.tag << ": " << l.elements << " elements, " << l.nodes << " nodes, metric length "
         << l.metric_length_min << " .. " << l.metric_length_max;
    rep.line(line.str());
  }
  rep.add("order", front.order);
  rep.add_json("loops", json_array(loops));
  rep.add("metric_length_min", s.metric_length_min);
  rep.add("metric_length_max", s.metric_length_max);
  rep.add("unit_fraction", s.unit_fraction);
  rep.add("short_corner_segments", s.short_segments);
}

// A first layer double precision can place on the body: coordinates of size L are spaced about
// 2.2e-16 L apart, so a height under 1e-12 L has no distinct nodes (h0 = 1e-200 stopped a run
// with "node 12 of an order-2 prism has a non-finite coordinate", naming no key; issue 37 item 7).
void check_h0_resolvable(double h0, double scale, const std::string& h0_where) {
  constexpr double kSmallest = 1e-12;
  if (scale > 0 && h0 < kSmallest * scale)
    throw ConfigError(h0_where + ": " + num(h0) + " is below what double precision places on a body of size " + num(scale) +
                      " (at least " + num(kSmallest * scale) + ", 1e-12 of it)");
}

void register_2d() {
  StageRegistry<2>& geometry = stage_registry<2>(StageKind::Geometry);
  geometry.add("annulus", [](const ConfigNode& section) -> Stage<2> {
    const AnnulusParams params = parse_annulus_params(section);
    return [params](RunState<2>& s, StageReport&) { s.annulus = params; };
  });
  geometry.add("airfoils", [](const ConfigNode& section) -> Stage<2> {
    const AirfoilsParams params = parse_airfoils_params(section);
    return [params](RunState<2>& s, StageReport&) { s.geometry = build_airfoils_geometry(params); };
  });
  StageRegistry<2>& metric = stage_registry<2>(StageKind::Metric);
  metric.add("uniform", [](const ConfigNode& section) -> Stage<2> {
    const Metric<2> m = uniform_metric_2d(parse_uniform_metric(section, 2));
    return [m](RunState<2>& s, StageReport&) { s.metric = std::make_unique<UniformMetricField<2>>(m); };
  });
  metric.add("wall_power_law", [](const ConfigNode& section) -> Stage<2> {
    const WallLawParams p = parse_wall_law_params(section, 2);
    const std::string where = section.where("type"), h0_where = section.where("h0");
    return [p, where, h0_where](RunState<2>& s, StageReport&) {
      const double bodies = (s.geometry.body_max - s.geometry.body_min).norm();
      check_h0_resolvable(p.h0, bodies > 0 ? bodies : s.geometry.scale(), h0_where);
      s.metric = make_wall_law_field(p, s.geometry, where);
    };
  });
  metric.add("background", [](const ConfigNode& section) -> Stage<2> {
    const BackgroundParams p = parse_background_params(section);
    const std::string where = section.where("type");
    return [p, where](RunState<2>& s, StageReport&) { s.metric = make_background_field<2>(p, where); };
  });
  StageRegistry<2>& surface = stage_registry<2>(StageKind::Surface);
  surface.add("curves", [](const ConfigNode&) -> Stage<2> {
    return [](RunState<2>& s, StageReport& rep) {
      s.front = mesh_curves(s.geometry, *s.metric, s.config.order);
      report_curves(*s.front, s.geometry, *s.metric, rep);
    };
  });
  surface.add("annulus", [](const ConfigNode&) -> Stage<2> {
    return [](RunState<2>& s, StageReport&) {
      if (!s.annulus) throw MesherError("surface: the annulus mesh needs the annulus geometry");
      s.mesh = mesh_annulus(*s.annulus, s.config.order, *s.metric);
      s.mesh_done = true;
    };
  });
}

void register_3d() {
  StageRegistry<3>& metric = stage_registry<3>(StageKind::Metric);
  metric.add("uniform", [](const ConfigNode& section) -> Stage<3> {
    const Metric<3> m = uniform_metric_3d(parse_uniform_metric(section, 3));
    return [m](RunState<3>& s, StageReport&) { s.metric = std::make_unique<UniformMetricField<3>>(m); };
  });
  // The wall law from the geometry stage's reference; the surface follows its sizes along the wall.
  metric.add("wall_power_law", [](const ConfigNode& section) -> Stage<3> {
    const WallLawParams p = parse_wall_law_params(section, 3);
    const std::string where = section.where("type"), h0_where = section.where("h0");
    return [p, where, h0_where](RunState<3>& s, StageReport&) {
      if (!s.reference)
        throw MesherError(where +
                          ": the wall_power_law metric measures distances to the body, but the geometry stage gave "
                          "no reference geometry");
      check_h0_resolvable(p.h0, s.reference->scale(), h0_where);
      WallPowerLawField3 field(s.reference, p);
      s.surface_sizes = std::make_unique<WallSizesAlongWall3>(field);
      s.metric = std::make_unique<WallPowerLawField3>(std::move(field));
    };
  });
  // The metric at the nodes of a tetrahedral background mesh; the surface follows it as it is.
  metric.add("background", [](const ConfigNode& section) -> Stage<3> {
    const BackgroundParams p = parse_background_params(section);
    const std::string where = section.where("type");
    return [p, where](RunState<3>& s, StageReport&) { s.metric = make_background_field<3>(p, where); };
  });
}

template <int Dim>
void register_none() {
  stage_registry<Dim>(StageKind::Fill).add("none", [](const ConfigNode&) -> Stage<Dim> {
    return [](RunState<Dim>&, StageReport&) {};
  });
  stage_registry<Dim>(StageKind::Layers).add("none", [](const ConfigNode&) -> Stage<Dim> {
    return [](RunState<Dim>& s, StageReport&) {
      // No layers: the fill starts from the surface front itself.
      if constexpr (Dim == 2)
        if (s.front) s.layers = unlayered(*s.front);
    };
  });
}

}  // namespace

void register_core_plugins() {
  static const bool once = [] {
    register_2d();
    register_3d();
    register_none<2>();
    register_none<3>();
    return true;
  }();
  (void)once;
}

template <int Dim>
Stage<Dim> intersect_metric_stages(Stage<Dim> first, std::vector<Stage<Dim>> more) {
  more.insert(more.begin(), std::move(first));
  return [more](RunState<Dim>& s, StageReport& rep) {
    typename IntersectedMetricField<Dim>::Fields fields, along_wall;
    bool own_sizes = false;  // some field gave sizes along the wall (3D)
    for (const Stage<Dim>& stage : more) {
      stage(s, rep);
      if (!s.metric) throw MesherError("metric: a field of the intersection gave no metric");
      std::shared_ptr<const MetricField<Dim>> field(std::move(s.metric));
      fields.push_back(field);
      if constexpr (Dim == 3) {
        own_sizes = own_sizes || s.surface_sizes;
        along_wall.push_back(s.surface_sizes ? std::shared_ptr<const MetricField<3>>(std::move(s.surface_sizes)) : field);
      }
    }
    s.metric = std::make_unique<IntersectedMetricField<Dim>>(std::move(fields));
    if constexpr (Dim == 3)
      if (own_sizes) s.surface_sizes = std::make_unique<IntersectedMetricField<3>>(std::move(along_wall));
  };
}
template Stage<2> intersect_metric_stages(Stage<2>, std::vector<Stage<2>>);
template Stage<3> intersect_metric_stages(Stage<3>, std::vector<Stage<3>>);

std::string plugin_listing() {
  std::string out;
  auto names = [](const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& n : v) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? std::string("-") : s;
  };
  for (StageKind k : all_stage_kinds) {
    out += std::string(stage_kind_name(k)) + ":\n";
    out += "  2D: " + names(stage_registry<2>(k).names()) + "\n";
    out += "  3D: " + names(stage_registry<3>(k).names()) + "\n";
  }
  out += "output formats:\n  2D: " + names(writer_registry<2>().names()) + "\n  3D: " +
         names(writer_registry<3>().names()) + "\n";
  return out;
}

}  // namespace pipeline
}  // namespace plaf
