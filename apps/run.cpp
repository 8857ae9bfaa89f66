// SPDX-License-Identifier: MIT
// The driver: numbered steps, each a stage call on core data types, timed and reported.
#include "apps/run.h"
#include "apps/stage_clock.h"

#include <chrono>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "layers/grow_layers_2d.h"
#include "modules/mesh/annulus.h"
#include "modules/io/atomic_file.h"
#include "modules/base/error.h"
#include "modules/geometry/geometry2d.h"
#include "modules/mesh/hybrid2d.h"
#include "modules/metric/metric_fields.h"
#include "modules/io/msh_io.h"
#include "modules/io/picture.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/run_config.h"
#include "modules/mesh/curve_mesh.h"
#include "modules/io/writers.h"
#include "volume/advancing_front_2d.h"

namespace plaf {

namespace {

// The mesh of the run and, for spline geometries, the surface front it was built from, the
// layers grown from it and the advancing-front fill.
struct MeshStage {
  HybridMesh<2> mesh;
  std::optional<CurvedFront<2>> front;
  std::optional<layers::LayerResult<2>> layers;
  std::optional<volume::AdvancingFrontStats> fill;
  std::size_t split_quads = 0;
};

layers::LayerParams layer_params(const LayersParams& c) {
  layers::LayerParams p;
  p.max_layers = c.max;
  p.stop_when_linear = c.stop_when_linear;
  p.f_atten = c.f_atten;
  p.corner_angle_deg = c.corner_angle_deg;
  p.fan_angle_deg = c.fan_angle_deg;
  p.integrate_height = c.integrate_height;
  p.smooth_normals = c.smooth_normals;
  p.isotropic_stop = c.isotropic_stop == "node" ? layers::IsotropicStop::Node
                     : c.isotropic_stop == "any"  ? layers::IsotropicStop::Any
                     : c.isotropic_stop == "all"  ? layers::IsotropicStop::All
                                                  : layers::IsotropicStop::Off;
  return p;
}

// Adds a front's loops (order-Q elements) to the mesh's boundary under their tags; at order 1
// (their vertices alone) when `linear`.
void add_boundary_loops(HybridMesh<2>& mesh, const CurvedFront<2>& front, const std::vector<const FrontLoop*>& loops,
                        bool linear) {
  for (const FrontLoop* l : loops) {
    const int tag = mesh.add_tag(l->tag, l->kind);
    CellBlock& b = mesh.boundary_block(CellType::Line, linear ? 1 : front.order, tag);
    for (std::size_t e = 0; e < l->size(); ++e) {
      const NodeId* c = front.element(*l, e);
      if (linear)
        b.connectivity.insert(b.connectivity.end(), c, c + 2);
      else
        b.connectivity.insert(b.connectivity.end(), c, c + front.order + 1);
    }
  }
}

// The fill (Sec. II.C): the linear front is the layers' outer front of every body with layers
// and the surface mesh of the other loops (the farfield, bodies without layers); its triangles
// join the mesh at order Q (uniform_order) or 1.
void fill_domain(const RunConfig& c, const MetricField<2>& metric, const CurvedFront<2>& surface,
                 const layers::LayerResult<2>& lr, MeshStage& stage) {
  HybridMesh<2>& mesh = stage.mesh;
  std::vector<const FrontLoop*> bare;  // loops of the surface mesh that bound the fill directly
  for (const LinearLoop& l : lr.fill_front.loops)
    if (!l.layered) bare.push_back(&surface.loops[static_cast<std::size_t>(l.source_loop)]);
  volume::AdvancingFrontParams params;
  params.max_triangles = static_cast<std::size_t>(c.fill.max_triangles);
  volume::AdvancingFrontResult fill = volume::advancing_front_fill(lr.fill_front, metric, params);
  mesh.nodes = std::move(fill.nodes);
  const bool uniform = c.output.uniform_order || c.order == 1;
  // The bare loops' boundary lines: at order Q they give the triangles their curved edges.
  add_boundary_loops(mesh, surface, bare, !uniform);
  if (uniform) {
    add_triangles_at_order(mesh, fill.triangles, c.order);
  } else {
    CellBlock& t = mesh.block(CellType::Triangle, 1);
    for (const auto& tri : fill.triangles) t.connectivity.insert(t.connectivity.end(), tri.begin(), tri.end());
  }
  stage.fill = fill.stats;
}

MeshStage mesh_geometry(const RunConfig& c, const Geometry2D& geometry, const MetricField<2>& metric) {
  MeshStage stage;
  if (c.geometry.type == "annulus") {
    stage.mesh = mesh_annulus(c.geometry.annulus, c.order, metric);
    return stage;
  }
  CurvedFront<2> front = mesh_curves(geometry, metric, c.order);
  if (!c.layers.enabled) {
    if (c.fill.enabled) {
      const layers::LayerResult<2> none = layers::no_layers(front);
      stage.mesh = none.mesh;
      fill_domain(c, metric, front, none, stage);
    } else {
      stage.mesh = front_mesh(front);
    }
    stage.front = std::move(front);
    return stage;
  }
  layers::LayerParams lp = layer_params(c.layers);
  lp.close_linear = c.fill.enabled;  // the fill starts from a linear front
  layers::LayerResult<2> lr = layers::grow_layers(front, metric, lp);
  if (lr.layers.empty() && c.layers.max > 0)
    throw MesherError("layers: not even the first layer could be grown (" +
                      (lr.events.empty() ? std::string("no wall loop") : lr.events.back()) + ")");
  stage.mesh = lr.mesh;
  if (c.fill.enabled) {
    fill_domain(c, metric, front, lr, stage);
  } else {
    // Layers alone: the outermost front is tagged "layers_outer".
    const int outer = stage.mesh.add_tag("layers_outer", BoundaryKind::Named);
    CellBlock& b = stage.mesh.boundary_block(CellType::Line, c.order, outer);
    for (const FrontLoop& l : lr.outer.loops)
      b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
  }
  if (c.output.split_quads) stage.split_quads = split_quads(stage.mesh);
  compact_nodes(stage.mesh);  // e.g. the farfield's surface nodes are not part of a layers-only mesh
  stage.front = std::move(front);
  stage.layers = std::move(lr);
  return stage;
}

// layers.* report keys and a per-layer table from the certified per-cell quality.
void report_layers(const layers::LayerResult<2>& lr, const HybridMesh<2>& mesh, const CellQuality& pc,
                   QualityReport& report) {
  std::string table = "[";
  std::cout << "  layer  cells  curved  max_clip/h  min_scaled_J  max_aspect\n";
  for (std::size_t k = 0; k < lr.layers.size(); ++k) {
    const layers::LayerStats& st = lr.layers[k];
    std::size_t curved = 0;
    double min_sj = std::numeric_limits<double>::infinity(), max_ar = 0;
    for (std::size_t c = st.first_cell; c < st.first_cell + st.cells; ++c) {
      if (is_curved(mesh, mesh.cells[0], c)) ++curved;
      min_sj = std::min(min_sj, pc.scaled_jacobian[c]);
      max_ar = std::max(max_ar, pc.aspect_ratio[c]);
    }
    table += std::string(k ? ", " : "") + "{\"layer\": " + std::to_string(st.layer) +
             ", \"cells\": " + std::to_string(st.cells) + ", \"curved_cells\": " + std::to_string(curved) +
             ", \"max_clipped_over_height\": " + json_number(st.max_clipped_rel) +
             ", \"linear\": " + (st.linear ? "true" : "false") + ", \"min_scaled_jacobian\": " + json_number(min_sj) +
             ", \"max_aspect_ratio\": " + json_number(max_ar) + ", \"shrinks\": " + std::to_string(st.shrinks) +
             ", \"transition_cells\": " + std::to_string(st.transition_cells) + "}";
    std::cout << std::setw(7) << st.layer << std::setw(7) << st.cells << std::setw(8) << curved << std::setw(12)
              << std::setprecision(3) << st.max_clipped_rel << std::setw(14) << min_sj << std::setw(12) << max_ar
              << '\n';
  }
  table += "]";
  std::string events = "[";
  for (std::size_t k = 0; k < lr.events.size(); ++k) {
    events += std::string(k ? ", " : "") + json_string(lr.events[k]);
    std::cout << "  layers: " << lr.events[k] << '\n';
  }
  events += "]";
  report.extra.push_back({"layers.count", std::to_string(lr.layers.size())});
  report.extra.push_back({"layers.linear_after", std::to_string(lr.linear_after)});
  report.extra.push_back({"layers.table", table});
  report.extra.push_back({"layers.events", events});
  std::cout << "  layers: " << lr.layers.size() << ", front linear after layer " << lr.linear_after << '\n';
}

// fill.* report keys: what the advancing front did.
void report_fill(const volume::AdvancingFrontStats& f, QualityReport& report) {
  report.extra.push_back({"fill.steps", std::to_string(f.steps)});
  report.extra.push_back({"fill.new_points", std::to_string(f.new_points)});
  report.extra.push_back({"fill.merges", std::to_string(f.merges)});
  report.extra.push_back({"fill.delaunay_apexes", std::to_string(f.delaunay_apexes)});
  report.extra.push_back({"fill.max_front", std::to_string(f.max_front)});
  std::cout << "  fill: " << f.steps << " steps, " << f.new_points << " new points, " << f.merges << " merges, "
            << f.delaunay_apexes << " Delaunay fallbacks, largest front " << f.max_front << " edges\n";
}

// Surface statistics as report keys surface.*; a summary line per loop on stdout.
void report_surface(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric,
                    QualityReport& report) {
  const CurveMeshStats s = curve_mesh_stats(front, geometry, metric);
  std::string loops = "[";
  for (std::size_t k = 0; k < s.loops.size(); ++k) {
    const CurveLoopStats& l = s.loops[k];
    loops += std::string(k ? ", " : "") + "{\"tag\": " + json_string(l.tag) +
             ", \"elements\": " + std::to_string(l.elements) + ", \"nodes\": " + std::to_string(l.nodes) +
             ", \"metric_length_min\": " + json_number(l.metric_length_min) +
             ", \"metric_length_max\": " + json_number(l.metric_length_max) + "}";
    std::cout << "  surface loop " << l.tag << ": " << l.elements << " elements, " << l.nodes
              << " nodes, metric length " << l.metric_length_min << " .. " << l.metric_length_max << '\n';
  }
  loops += "]";
  report.extra.push_back({"surface.order", std::to_string(front.order)});
  report.extra.push_back({"surface.loops", loops});
  report.extra.push_back({"surface.metric_length_min", json_number(s.metric_length_min)});
  report.extra.push_back({"surface.metric_length_max", json_number(s.metric_length_max)});
  report.extra.push_back({"surface.unit_fraction", json_number(s.unit_fraction)});
  report.extra.push_back({"surface.short_corner_segments", std::to_string(s.short_segments)});
}

}  // namespace

int run_command(const std::filesystem::path& config_path, const std::optional<std::filesystem::path>& out_dir) {
  // 1. Configuration: everything is validated before anything is written.
  RunConfig c = load_run_config(config_path);
  if (out_dir) c.output.dir = *out_dir;
  if (c.dim == 3) return run_surface3d(c, config_path);
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings);
  clock.done("config", config_path.string());

  // 2. Geometry: spline loops of the bodies and the farfield (none for the analytic annulus).
  const Geometry2D geometry =
      c.geometry.type == "airfoils" ? build_airfoils_geometry(c.geometry.airfoils) : Geometry2D{};
  clock.done("geometry", c.geometry.type + ", " + std::to_string(geometry.loops.size()) + " loops");

  // 3. Metric field.
  const std::unique_ptr<MetricField<2>> metric = make_metric_field(c, geometry);
  clock.done("metric", c.metric.type);

  // 4. Mesh: the surface mesh of the loops (Sec. II.B), or the analytic annulus.
  const MeshStage stage = mesh_geometry(c, geometry, *metric);
  const HybridMesh<2>& mesh = stage.mesh;
  clock.done("mesh", c.geometry.type + ", " + std::to_string(mesh.num_cells()) + " cells, " +
                         std::to_string(mesh.nodes.size()) + " nodes of order " + std::to_string(c.order));

  // 5. Quality: certified validity of every cell, metric conformity, mesh conformity.
  QualityOptions qo;
  qo.validity.rel_tol = c.validity.rel_tol;
  qo.validity.max_depth = c.validity.max_depth;
  qo.histogram_bins = c.output.histogram_bins;
  CellQuality per_cell;
  QualityReport report = assess_quality<2>(mesh, metric.get(), qo, &per_cell);
  report.name = c.name;
  if (stage.front) report_surface(*stage.front, geometry, *metric, report);
  if (stage.layers) report_layers(*stage.layers, mesh, per_cell, report);
  if (stage.fill) report_fill(*stage.fill, report);
  if (c.output.split_quads) report.extra.push_back({"layers.split_quads", std::to_string(stage.split_quads)});
  clock.done("quality", std::to_string(report.cells_invalid) + " invalid cells");

  // 6. Outputs, each written atomically; the report last, with every stage's time.
  std::filesystem::create_directories(c.output.dir);
  const std::filesystem::path base = c.output.dir / c.name;
  for (const std::string& format : c.output.formats)
    if (format != "report")
      writer_registry().create(format, c.file.string() + ": output.formats", WriteJob{mesh, per_cell, report, c, base});
  clock.done("write", base.string() + ".*");
  report.timings_s = timings;
  if (c.output.wants("report")) writer_registry().create("report", "", WriteJob{mesh, per_cell, report, c, base});

  std::cout << report_summary(report);
  if (!report.ok()) {
    std::cerr << "plaf: error: the mesh of " << config_path.string() << " is NOT valid: " << report.cells_invalid
              << " invalid cells" << (report.first_invalid.empty() ? "" : " (first: " + report.first_invalid + ")")
              << (report.conformity.ok ? "" : ", " + report.conformity.first_problem) << '\n';
    return 2;
  }
  return 0;
}

int check_command(const std::filesystem::path& path, const std::optional<std::filesystem::path>& metric_config,
                  const std::optional<std::filesystem::path>& report_path) {
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings);
  // The metric first: a bad config fails before the (possibly long) read.
  std::optional<RunConfig> c;
  Geometry2D geometry;
  std::unique_ptr<MetricField<2>> metric;
  QualityOptions qo;
  if (metric_config) {
    c = load_run_config(*metric_config);
    if (c->geometry.type == "airfoils") geometry = build_airfoils_geometry(c->geometry.airfoils);
    metric = make_metric_field(*c, geometry);
    qo.histogram_bins = c->output.histogram_bins;
    clock.done("metric", c->metric.type + " from " + metric_config->string());
  }
  const MshMesh m = read_msh41(path);
  clock.done("read", path.string() + ", dimension " + std::to_string(m.dim));
  QualityReport report;
  if (m.dim == 2) {
    report = assess_quality<2>(m.mesh2, metric.get(), qo);
  } else {
    if (metric) throw InputError(path.string() + ": --metric takes a 2D mesh (the run configurations are 2D)");
    report = assess_quality<3>(m.mesh3, nullptr, qo);
  }
  clock.done("quality", std::to_string(report.cells_total) + " cells certified");
  report.name = path.string();
  report.timings_s = timings;
  if (report_path) {
    AtomicFile f(*report_path);
    f.write(report_json(report));
    f.commit();
  }
  std::cout << report_summary(report);
  if (!report.ok()) {
    std::cerr << "plaf: error: " << path.string() << " is NOT valid: " << report.cells_invalid << " invalid cells"
              << (report.conformity.ok ? "" : ", " + report.conformity.first_problem) << '\n';
    return 2;
  }
  return 0;
}

}  // namespace plaf
