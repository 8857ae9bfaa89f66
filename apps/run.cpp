// SPDX-License-Identifier: MIT
// The driver: numbered steps, each a stage call on core data types, timed and reported.
#include "apps/run.h"

#include <chrono>
#include <iomanip>
#include <optional>
#include <sstream>
#include <iostream>
#include <string>

#include "modules/annulus.h"
#include "modules/error.h"
#include "modules/geometry2d.h"
#include "modules/metric_fields.h"
#include "modules/msh_io.h"
#include "modules/quality.h"
#include "modules/run_config.h"
#include "modules/surface_mesh.h"
#include "modules/writers.h"

namespace plaf {

namespace {

class StageClock {
 public:
  explicit StageClock(std::vector<std::pair<std::string, double>>& timings) : timings_(timings) {}
  // Records the time since the last call under `stage` and prints a progress line.
  void done(const std::string& stage, const std::string& what) {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    timings_.emplace_back(stage, s);
    std::cerr << "[plaf] " << stage << ": " << what << " (" << s << " s)\n";
  }

 private:
  std::vector<std::pair<std::string, double>>& timings_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// The mesh of the run and, for spline geometries, the surface front it was built from.
struct MeshStage {
  HybridMesh<2> mesh;
  std::optional<CurvedFront<2>> front;
};

MeshStage mesh_geometry(const RunConfig& c, const Geometry2D& geometry, const MetricField<2>& metric) {
  if (c.geometry.type == "annulus") return {mesh_annulus(c.geometry.annulus, c.order, metric), std::nullopt};
  CurvedFront<2> front = mesh_surface(geometry, metric, c.order);
  HybridMesh<2> mesh = front_mesh(front);
  return {std::move(mesh), std::move(front)};
}

std::string json_num(double x) {
  std::ostringstream s;
  s << std::setprecision(10) << x;
  return s.str();
}

// Surface statistics as report keys surface.*; a summary line per loop on stdout.
void report_surface(const CurvedFront<2>& front, const MetricField<2>& metric, QualityReport& report) {
  const SurfaceStats s = surface_stats(front, metric);
  std::string loops = "[";
  for (std::size_t k = 0; k < s.loops.size(); ++k) {
    const SurfaceLoopStats& l = s.loops[k];
    loops += std::string(k ? ", " : "") + "{\"tag\": \"" + l.tag + "\", \"elements\": " + std::to_string(l.elements) +
             ", \"nodes\": " + std::to_string(l.nodes) + ", \"metric_length_min\": " + json_num(l.metric_length_min) +
             ", \"metric_length_max\": " + json_num(l.metric_length_max) + "}";
    std::cout << "  surface loop " << l.tag << ": " << l.elements << " elements, " << l.nodes
              << " nodes, metric length " << l.metric_length_min << " .. " << l.metric_length_max << '\n';
  }
  loops += "]";
  report.extra.push_back({"surface.order", std::to_string(front.order)});
  report.extra.push_back({"surface.loops", loops});
  report.extra.push_back({"surface.metric_length_min", json_num(s.metric_length_min)});
  report.extra.push_back({"surface.metric_length_max", json_num(s.metric_length_max)});
  report.extra.push_back({"surface.unit_fraction", json_num(s.unit_fraction)});
  report.extra.push_back({"surface.short_corner_segments", std::to_string(s.short_segments)});
}

}  // namespace

int run_command(const std::filesystem::path& config_path, const std::optional<std::filesystem::path>& out_dir) {
  // 1. Configuration: everything is validated before anything is written.
  RunConfig c = load_run_config(config_path);
  if (out_dir) c.output.dir = *out_dir;
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
  if (stage.front) report_surface(*stage.front, *metric, report);
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
              << " invalid cells" << (report.conformity.ok ? "" : ", " + report.conformity.first_problem) << '\n';
    return 2;
  }
  return 0;
}

int check_command(const std::filesystem::path& path) {
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings);
  const MshMesh m = read_msh41(path);
  clock.done("read", path.string() + ", dimension " + std::to_string(m.dim));
  QualityReport report;
  if (m.dim == 2)
    report = assess_quality<2>(m.mesh2, nullptr, QualityOptions{});
  else
    report = assess_quality<3>(m.mesh3, nullptr, QualityOptions{});
  clock.done("quality", std::to_string(report.cells_total) + " cells certified");
  report.name = path.string();
  std::cout << report_summary(report);
  if (!report.ok()) {
    std::cerr << "plaf: error: " << path.string() << " is NOT valid: " << report.cells_invalid << " invalid cells"
              << (report.conformity.ok ? "" : ", " + report.conformity.first_problem) << '\n';
    return 2;
  }
  return 0;
}

}  // namespace plaf
