// SPDX-License-Identifier: MIT
// The driver: numbered steps, each a stage call on core data types, timed and reported.
#include "apps/run.h"

#include <chrono>
#include <iostream>
#include <string>

#include "modules/annulus.h"
#include "modules/error.h"
#include "modules/metric_fields.h"
#include "modules/msh_io.h"
#include "modules/quality.h"
#include "modules/run_config.h"
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

HybridMesh<2> mesh_geometry(const RunConfig& c, const MetricField<2>& metric) {
  if (c.geometry.type == "annulus") return mesh_annulus(c.geometry.annulus, c.order, metric);
  throw ConfigError(c.geometry.where + ": unknown geometry '" + c.geometry.type + "'");
}

}  // namespace

int run_command(const std::filesystem::path& config_path, const std::optional<std::filesystem::path>& out_dir) {
  // 1. Configuration: everything is validated before anything is written.
  RunConfig c = load_run_config(config_path);
  if (out_dir) c.output.dir = *out_dir;
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings);
  clock.done("config", config_path.string());

  // 2. Metric field.
  const std::unique_ptr<MetricField<2>> metric = make_metric_field(c);
  clock.done("metric", c.metric.type);

  // 3. Mesh.
  const HybridMesh<2> mesh = mesh_geometry(c, *metric);
  clock.done("mesh",
             c.geometry.type + ", " + std::to_string(mesh.num_cells()) + " cells of order " + std::to_string(c.order));

  // 4. Quality: certified validity of every cell, metric conformity, mesh conformity.
  QualityOptions qo;
  qo.validity.rel_tol = c.validity.rel_tol;
  qo.validity.max_depth = c.validity.max_depth;
  qo.histogram_bins = c.output.histogram_bins;
  CellQuality per_cell;
  QualityReport report = assess_quality<2>(mesh, metric.get(), qo, &per_cell);
  report.name = c.name;
  clock.done("quality", std::to_string(report.cells_invalid) + " invalid cells");

  // 5. Outputs, each written atomically; the report last, with every stage's time.
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
