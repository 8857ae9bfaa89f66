// SPDX-License-Identifier: MIT
// The driver: one pipeline for 2D and 3D (DESIGN.md), numbered steps, each a registered stage
// plugin (modules/pipeline/stages.h) on the run state's core types, timed and reported.
#include "apps/run.h"
#include "apps/exit_codes.h"
#include "apps/stage_clock.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>

#include "layers/plugins.h"
#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/base/format.h"
#include "modules/pipeline/budget.h"
#include "modules/pipeline/data_root.h"
#include "modules/elements/lagrange.h"
#include "modules/io/cgns_io.h"
#include "modules/io/msh_io.h"
#include "modules/io/output_set.h"
#include "modules/mesh/extrude_front.h"
#include "modules/metric/extruded_metric.h"
#include "modules/pipeline/writers.h"
#include "modules/mesh/hybrid2d.h"
#include "modules/mesh/hybrid3d.h"
#include "modules/mesh/bend_fill3d.h"
#include "modules/mesh/untangle3d.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/layer_table.h"
#include "modules/pipeline/run_config.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "surface3d/plugins.h"
#include "volume/plugins.h"

namespace plaf {

namespace {

// A stage's MesherError with the report sections of the stages that ran before it (and its own
// part), for the failed run's report (run_command).
struct StageFailure : MesherError {
  StageFailure(const std::string& what, std::vector<std::pair<std::string, std::string>> done,
               std::vector<std::string> stage_failures)
      : MesherError(what), sections(std::move(done)), failures(std::move(stage_failures)) {}
  std::vector<std::pair<std::string, std::string>> sections;  // QualityReport::extra entries
  std::vector<std::string> failures;                          // the stages' own failure lines
};

// The stage a config chose for `kind`, configured by its plugin. Geometry, metric and surface
// types come from their sections' keys (run_config.h); layers and fill were configured when the
// config was read (their plugins parse their own sections).
// The stage the config chose for `kind`, configured by its plugin when the config was read.
template <int Dim>
const Stage<Dim>& chosen(const RunConfig& c, StageKind kind) {
  const PlannedStage& p = kind == StageKind::Geometry ? c.geometry
                          : kind == StageKind::Metric ? c.metric
                          : kind == StageKind::Surface ? c.surface
                          : kind == StageKind::Layers ? c.layers
                                                      : c.fill;
  if constexpr (Dim == 2)
    return p.run2;
  else
    return p.run3;
}

// Step 5 of the pipeline: the mesh of the run from the stages' products.
void assemble(RunState<2>& s, StageReport& rep) {
  if (s.mesh_done) {  // the annulus: nothing to split (the key as for every 2D run)
    if (s.config.output.split_quads) rep.add("split_quads", 0);
    return;
  }
  if (!s.layers) throw MesherError("assembly: the layer stage gave no result");
  const LayerResult<2>& layers = *s.layers;
  AssemblyOptions o;
  o.order = s.config.order;
  o.uniform_order = s.config.output.uniform_order;
  o.split_quads = s.config.output.split_quads;
  Assembled2D a = assemble_hybrid_2d(*s.front, layers, s.fill ? &*s.fill : nullptr, o);
  s.mesh = std::move(a.mesh);
  if (o.split_quads) rep.add("split_quads", a.split_quads);
}
void assemble(RunState<3>& s, StageReport& rep) {
  if (s.layers) {
    // The layer mesh moves into the run's mesh (the layer table needs only its stats after).
    if (s.fill) {
      // The fill's tetrahedra are appended to the layers' block of order-Q tetrahedra (if any),
      // and the assembly's high-order nodes come after the fill's vertices.
      const int q = s.layers->outer.order;
      std::size_t first_cell = 0;
      for (const CellBlock& b : s.layers->mesh.cells)
        if (b.type == CellType::Tetrahedron && b.order == q) first_cell = b.size();
      s.mesh = assemble_hybrid_3d(std::move(s.layers->mesh), s.layers->outer, *s.fill);
      std::size_t block = s.mesh.cells.size();
      for (std::size_t k = 0; k < s.mesh.cells.size(); ++k)
        if (s.mesh.cells[k].type == CellType::Tetrahedron && s.mesh.cells[k].order == q) block = k;
      // Where the front stayed curved, the fill bends with it (bend_fill3d.h), and the fill's
      // tetrahedra it still inverts are untangled by their own high-order nodes and points
      // (untangle3d.h); the quality stage certifies the result.
      const FillBending bent = bend_fill_3d(s.mesh, block, first_cell);
      rep.add("fill_curved_boundary_triangles", bent.curved_faces);
      rep.add("fill_bent_nodes", bent.nodes_moved);
      rep.add("fill_bent_returned", bent.nodes_returned);
      rep.add("fill_bent_max_shift", bent.max_shift);
      rep.add("fill_bent_invalid_before", bent.invalid_before);
      rep.add("fill_bent_invalid_after", bent.invalid_after);
      if (bent.nodes_moved + bent.nodes_returned > 0)
        rep.line("assembly: the fill bent with the " + std::to_string(bent.curved_faces) +
                 " curved triangles of its boundary: " + std::to_string(bent.nodes_moved) +
                 " of its nodes moved, by at most " + num(bent.max_shift) + " (" +
                 std::to_string(bent.nodes_returned) + " put back where a cell turned invalid); inverted cells " +
                 std::to_string(bent.invalid_before) + " -> " + std::to_string(bent.invalid_after));
      const FillUntangling u = untangle_fill_3d(s.mesh, block, first_cell);
      rep.add("fill_curved_tets", u.curved);
      rep.add("fill_flat_tets", u.flat);
      // invalid_after counts every cell a move could change (layers' cells too), so the difference
      // is clamped.
      const std::size_t untangled = u.invalid_before > u.invalid_after ? u.invalid_before - u.invalid_after : 0;
      rep.add("fill_untangled", untangled);
      rep.add("fill_still_invalid", u.invalid_after);
      rep.add("fill_untangle_certified", u.certified);  // its work, in cells certified
      rep.add("fill_straightened_cells", u.cells_straightened);
      rep.add("fill_straightened_boundary_nodes", u.straightened);
      rep.add("fill_straightened_max_deviation", u.straightened_max);
      if (u.invalid_before > 0)
        rep.line("assembly: " + std::to_string(u.invalid_before - u.flat) + " of the fill's " + std::to_string(u.curved) +
                 " curved tetrahedra" +
                 (u.flat > 0 ? " and " + std::to_string(u.flat) + " flat straight one" + (u.flat > 1 ? "s" : "") +
                                   " (TetGen's slivers)"
                             : std::string()) +
                 " were inverted; " + std::to_string(untangled) + " untangled by moving " +
                 std::to_string(u.nodes_moved) + " high-order nodes and " + std::to_string(u.vertices_moved) +
                 " vertices off the boundary, " + std::to_string(u.invalid_after) + " left");
      if (u.cells_straightened > 0)
        rep.line("assembly: " + std::to_string(u.cells_straightened) +
                 " cells made straight around fill cells no move untangled" +
                 (u.straightened > 0 ? "; WARNING: " + std::to_string(u.straightened) +
                                           " high-order nodes of the boundary straightened with them, the geometry "
                                           "given up there by at most " + num(u.straightened_max)
                                     : std::string()));
      return;
    }
    std::size_t bare = 0;
    s.mesh = assemble_hybrid_3d(std::move(s.layers->mesh), s.layers->outer, &bare);
    rep.add("bare_wall_facets", bare);
    if (bare > 0)
      rep.line("assembly: " + std::to_string(bare) +
               " wall triangles with no layer (their columns stopped before their first; the layers' coverage counts "
               "them), left out of the boundary with their outer triangles");
    return;
  }
  if (!s.mesh_done) throw MesherError("assembly: the surface stage gave no mesh");
}

// The largest offset of a front element's high-order node from its position on the linear
// element (RunOutcome::max_chord_offset).
double max_chord_offset(const CurvedFront<2>& f) {
  double worst = 0;
  const std::size_t q = static_cast<std::size_t>(f.order);
  for (const FrontLoop& l : f.loops) {
    if (l.kind != BoundaryKind::Wall) continue;
    for (std::size_t e = 0; e < l.size(); ++e) {
      const NodeId* el = l.elements.data() + e * (q + 1);
      const Eigen::Vector2d& a = f.nodes[static_cast<std::size_t>(el[0])];
      const Eigen::Vector2d& b = f.nodes[static_cast<std::size_t>(el[1])];
      for (std::size_t k = 1; k < q; ++k) {
        const Eigen::Vector2d lin = a + (static_cast<double>(k) / static_cast<double>(q)) * (b - a);
        worst = std::max(worst, (f.nodes[static_cast<std::size_t>(el[1 + k])] - lin).norm());
      }
    }
  }
  return worst;
}
double max_chord_offset(const CurvedFront<3>& f) {
  double worst = 0;
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, f.order);
  const std::size_t n = static_cast<std::size_t>(tri.size());
  for (std::size_t t = 0; t + n <= f.triangles.size(); t += n) {
    const Eigen::Vector3d& a = f.nodes[static_cast<std::size_t>(f.triangles[t])];
    const Eigen::Vector3d& b = f.nodes[static_cast<std::size_t>(f.triangles[t + 1])];
    const Eigen::Vector3d& c = f.nodes[static_cast<std::size_t>(f.triangles[t + 2])];
    for (std::size_t k = 3; k < n; ++k) {
      const Lattice& l = tri.lattice()[k];
      const Eigen::Vector3d lin = a + (static_cast<double>(l[0]) / f.order) * (b - a) + (static_cast<double>(l[1]) / f.order) * (c - a);
      worst = std::max(worst, (f.nodes[static_cast<std::size_t>(f.triangles[t + k])] - lin).norm());
    }
  }
  return worst;
}

// RunOutcome::wall_edge_mean.
double wall_edge_mean(const CurvedFront<2>& f) {
  double sum = 0;
  std::size_t n = 0;
  const std::size_t q = static_cast<std::size_t>(f.order);
  for (const FrontLoop& l : f.loops)
    if (l.kind == BoundaryKind::Wall)
      for (std::size_t e = 0; e < l.size(); ++e, ++n) {
        const NodeId* el = l.elements.data() + e * (q + 1);
        sum += (f.nodes[static_cast<std::size_t>(el[1])] - f.nodes[static_cast<std::size_t>(el[0])]).norm();
      }
  return n ? sum / static_cast<double>(n) : 0;
}
double wall_edge_mean(const CurvedFront<3>& f) {
  double sum = 0;
  std::size_t n = 0;
  const std::size_t npt = static_cast<std::size_t>((f.order + 1) * (f.order + 2) / 2);
  for (std::size_t t = 0; t + npt <= f.triangles.size(); t += npt)
    for (int k = 0; k < 3; ++k, ++n)
      sum += (f.nodes[static_cast<std::size_t>(f.triangles[t + static_cast<std::size_t>((k + 1) % 3)])] -
              f.nodes[static_cast<std::size_t>(f.triangles[t + static_cast<std::size_t>(k)])])
                 .norm();
  return n ? sum / static_cast<double>(n) : 0;
}

Eigen::Vector3d lift(const Eigen::Vector2d& x) { return Eigen::Vector3d(x[0], x[1], 0); }

// The nodes of a front (2D: its wall loops; 3D: its triangles), each once.
std::vector<Eigen::Vector3d> front_nodes(const CurvedFront<2>& f, const std::vector<Eigen::Vector2d>& nodes) {
  std::vector<Eigen::Vector3d> v;
  for (const FrontLoop& l : f.loops)
    if (l.kind == BoundaryKind::Wall)
      for (NodeId id : l.elements) v.push_back(lift(nodes[static_cast<std::size_t>(id)]));
  return v;
}
std::vector<Eigen::Vector3d> front_nodes(const CurvedFront<3>& f, const std::vector<Eigen::Vector3d>& nodes) {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::uint8_t> seen(nodes.size(), 0);
  for (NodeId id : f.triangles)
    if (!seen[static_cast<std::size_t>(id)]) {
      seen[static_cast<std::size_t>(id)] = 1;
      v.push_back(nodes[static_cast<std::size_t>(id)]);
    }
  return v;
}

// Where a failed run's picture looks (QualityReport::focus): the invalid cell of the smallest
// scaled Jacobian, a few of its sizes around it; else the place a failing stage named
// (StageReport::failure_place: the surface's first folded triangle); else the largest region of
// columns the layers stopped early (stop_regions of LayerCoverage::sites; only when the layer
// stage failed), a box about its size; in all at least 1 % of the wall's extent (its facets'
// nodes; the mesh's without wall facets -- not the farfield's, which would zoom out of the layers).
template <int Dim>
void set_failure_focus(const HybridMesh<Dim>& mesh, const CellQuality& per_cell, const std::vector<StageReport>& reports,
                       const LayerCoverage* coverage, QualityReport& report) {
  using Point = typename HybridMesh<Dim>::Point;
  const double floor = 0.01 * wall_diagonal(mesh);
  // The worst invalid cell.
  std::size_t k = 0, worst_block = 0, worst_cell = 0;
  double worst = std::numeric_limits<double>::infinity();
  bool any = false;
  for (std::size_t b = 0; b < mesh.cells.size(); ++b)
    for (std::size_t i = 0; i < mesh.cells[b].size(); ++i, ++k)
      if (k < per_cell.valid.size() && !per_cell.valid[k]) {
        const double sj = k < per_cell.scaled_jacobian.size() ? per_cell.scaled_jacobian[k] : 0.0;
        if (!any || sj < worst) {
          worst = sj;
          worst_block = b;
          worst_cell = i;
          any = true;
        }
      }
  if (any) {
    const CellBlock& block = mesh.cells[worst_block];
    const NodeId* c = block.cell(worst_cell);
    Point clo = Point::Constant(std::numeric_limits<double>::infinity()), chi = -clo;
    for (int n = 0; n < block.nodes_per_cell(); ++n) {
      clo = clo.cwiseMin(mesh.nodes[static_cast<std::size_t>(c[n])]);
      chi = chi.cwiseMax(mesh.nodes[static_cast<std::size_t>(c[n])]);
    }
    const Point mid = 0.5 * (clo + chi);
    report.focus.assign(mid.data(), mid.data() + Dim);
    report.focus_radius = std::max(4 * (chi - clo).norm(), floor);
    report.focus_label = "worst invalid cell (scaled Jacobian " + num(worst) + ")";
    return;
  }
  for (const StageReport& r : reports) {
    const StageReport::Place& at = r.failure_place();
    if (r.failure().empty() || at.point.size() != static_cast<std::size_t>(Dim)) continue;
    report.focus = at.point;
    report.focus_radius = std::max(at.radius, floor);
    report.focus_label = at.label;
    return;
  }
  if (!coverage || coverage->sites.empty()) return;
  // The largest region of stops (stop_regions, as the layers' report groups them: within 5 % of
  // the wall's diagonal).
  const std::vector<StopRegion> regions = stop_regions(*coverage, 5 * floor);
  const StopRegion& g = regions.front();
  report.focus.assign(g.point.begin(), g.point.begin() + Dim);
  const double extent = Dim == 3 ? std::sqrt(g.measure) : g.measure;
  report.focus_radius = std::max(0.5 * extent, floor);
  report.focus_label = "largest region of columns stopped early (wall " + num(g.measure) + ", layers " +
                       std::to_string(g.first_layer) + "-" + std::to_string(g.last_layer) + ")";
}

// verdict_line: in the progress's Quiet mode, one line on stdout with the verdict (else nothing).
template <int Dim>
RunOutcome run_pipeline(const RunConfig& c, Progress& progress, bool verdict_line) {
  const std::filesystem::path& config_path = c.file;
  const bool quiet = progress.mode() == ProgressMode::Quiet;
  std::ostringstream muted;
  std::ostream& out = quiet ? muted : std::cout;
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings, progress);
  clock.done("config", config_path.string());
  // An extruded run's 2D section: declared before the run's state, whose extruded metric refers
  // to the section's metric, so that it outlives it.
  std::optional<RunState<2>> section;
  RunState<Dim> s(c);
  s.progress = &progress;
  std::vector<StageReport> reports;
  auto step = [&](auto& state, StageKind kind, const std::string& what) {
    reports.emplace_back(stage_kind_name(kind));
    constexpr int D = std::remove_reference_t<decltype(state)>::dim;
    try {
      chosen<D>(c, kind)(state, reports.back());
    } catch (const MesherError& e) {
      // The stages done so far (and this one's part) go into the failed run's report, so that
      // what the messages point to (layers.events, layers.coverage) is there (issue 37, item 7).
      QualityReport done;
      std::vector<std::string> failures;
      for (const StageReport& r : reports) {
        r.append_to(done);
        if (!r.failure().empty()) failures.push_back(r.failure());
      }
      throw StageFailure(e.what(), std::move(done.extra), std::move(failures));
    }
    reports.back().print(out);
    clock.done(stage_kind_name(kind), what);
  };

  // 1-3. Geometry, metric and surface mesh, each the plugin the config chose; an extruded section
  // runs them in 2D and extrudes their front and metric (modules/mesh/extrude_front.h).
  if constexpr (Dim == 3) {
    if (c.extrude) {
      section.emplace(c);
      section->progress = &progress;
      step(*section, StageKind::Geometry, c.geometry.type);
      step(*section, StageKind::Metric, c.metric.type);
      check_section_budget(*section, c.extrude->rows);
      clock.done("budget", "within limits:");
      step(*section, StageKind::Surface, c.surface.type);
      if (!section->front) throw MesherError("extrude: the section gave no surface front");
      s.front = extrude_front(*section->front, 0, c.extrude->span, c.extrude->rows);
      s.metric = std::make_unique<ExtrudedMetricField>(*section->metric, c.extrude->hz);
      StageReport& e = reports.emplace_back("extrude");
      e.add("span", c.extrude->span);
      e.add("rows", c.extrude->rows);
      if (c.extrude->hz > 0)
        e.add("hz", c.extrude->hz);
      else
        e.add("hz", "section");
      e.add("triangles", s.front->num_triangles());
      e.line("extrude: the section's front between z = 0 and z = " + num(c.extrude->span) + " in " +
             std::to_string(c.extrude->rows) + " rows, " + std::to_string(s.front->num_triangles()) +
             " triangles of order " + std::to_string(c.order));
      e.print(out);
      clock.done("extrude", std::to_string(s.front->num_triangles()) + " triangles");
    }
  }
  if (!section) {
    step(s, StageKind::Geometry, c.geometry.type);
    step(s, StageKind::Metric, c.metric.type);
    if constexpr (Dim == 2) {  // the size budget (modules/pipeline/budget.h)
      check_section_budget(s, 1);
      clock.done("budget", "within limits:");
    }
    step(s, StageKind::Surface, c.surface.type);
  }
  // 4-5. Layers and fill.
  step(s, StageKind::Layers, c.layers.type);
  step(s, StageKind::Fill, c.fill.type);
  RunOutcome outcome;
  if (s.front) {
    outcome.max_chord_offset = max_chord_offset(*s.front);
    outcome.wall_edge_mean = wall_edge_mean(*s.front);
    outcome.wall_nodes = front_nodes(*s.front, s.front->nodes);
  }
  if (s.layers) {
    outcome.linear_after = s.layers->linear_after;
    outcome.outer_nodes = front_nodes(s.layers->outer, s.layers->mesh.nodes);
  }
  // 6. The mesh of the run.
  reports.emplace_back("layers");
  assemble(s, reports.back());
  reports.back().print(out);  // its lines (bare wall triangles, untangled fill cells) in the summary
  const HybridMesh<Dim>& mesh = s.mesh;
  clock.done("mesh", c.geometry.type + ", " + std::to_string(mesh.num_cells()) + " cells, " +
                         std::to_string(mesh.nodes.size()) + " nodes of order " + std::to_string(c.order));

  // 7. Quality: certified validity of every cell, metric conformity, mesh conformity; the
  //    stages' sections and the per-layer table.
  QualityOptions qo;
  qo.validity.rel_tol = c.validity.rel_tol;
  qo.validity.max_depth = c.validity.max_depth;
  qo.histogram_bins = c.output.histogram_bins;
  qo.progress = [&progress](double fraction, const std::string& what) { progress.step("quality", fraction, what); };
  CellQuality per_cell;
  QualityReport report = assess_quality<Dim>(mesh, s.measure(), qo, &per_cell);
  report.name = c.name;
  if (s.layers && !s.layers->layers.empty()) {
    // The table's section goes right after the layer stage's (the report's key order).
    StageReport table("layers");
    outcome.layers = layer_rows<Dim>(*s.layers, mesh, per_cell);
    report_layer_table<Dim>(*s.layers, outcome.layers, table);
    table.print(out);
    const auto layer_stage = std::find_if(reports.begin(), reports.end(), [](const StageReport& r) {
      return r.section() == stage_kind_name(StageKind::Layers);
    });
    reports.insert(layer_stage + 1, std::move(table));
  }
  for (const StageReport& r : reports) r.append_to(report);
  clock.done("quality", std::to_string(report.cells_invalid) + " invalid cells");

  // 8. The verdict: a stage's failure (one line each) or else an invalid, non-conforming mesh
  //    exits 2. Known before writing: a failed run's outputs go to OUTDIR/NAME.failed/ (the report
  //    and the picture, to see why; the mesh only with keep_invalid), never beside a valid run's.
  for (const StageReport& r : reports)
    if (!r.failure().empty()) outcome.failures.push_back(r.failure());
  if (outcome.failures.empty() && !report.ok())
    outcome.failures.push_back(
        "the " + std::string(report.surface ? "surface" : "mesh") + " is NOT valid: " +
        std::to_string(report.cells_invalid) + " invalid " + (report.surface ? "triangles" : "cells") +
        (report.first_invalid.empty() ? "" : " (first: " + report.first_invalid + ")") +
        (report.conformity.ok ? "" : ", " + report.conformity.first_problem));
  const bool failed = !outcome.failures.empty();
  report.exit_code = failed ? 2 : 0;
  report.run_failures = outcome.failures;
  if (failed) {
    const bool layers_failed = std::any_of(reports.begin(), reports.end(), [](const StageReport& r) {
      return r.section() == stage_kind_name(StageKind::Layers) && !r.failure().empty();
    });
    set_failure_focus<Dim>(mesh, per_cell, reports, layers_failed && s.layers ? &s.layers->coverage : nullptr, report);
    if (!report.focus.empty()) {
      std::ostringstream j;
      j << "{\"point\": [";
      for (std::size_t i = 0; i < report.focus.size(); ++i) j << (i ? ", " : "") << json_number(report.focus[i]);
      j << "], \"radius\": " << json_number(report.focus_radius) << ", \"why\": " << json_string(report.focus_label)
        << "}";
      report.extra.emplace_back("failure.focus", j.str());
    }
  }

  // 9. Outputs, each written atomically and all as one set (output_set.h: staged, then moved in
  //    together; a failure or a stop signal leaves none); the report last, with every stage's time.
  OutputSet outputs(failed ? c.output.dir / (c.name + ".failed") : c.output.dir, c.name);
  if (c.output.wants("vtu")) outputs.own("_boundary.vtu");  // not written without a boundary
  outputs.own_numbered(".cut", ".png");                     // output.cuts: as many as this run asks
  const std::filesystem::path base = outputs.staged_base();
  std::vector<std::string> formats = c.output.formats;
  if (failed) {
    if (!c.output.keep_invalid)
      formats.erase(std::remove_if(formats.begin(), formats.end(),
                                   [](const std::string& f) { return f != "report" && f != "png"; }),
                    formats.end());
    for (const char* f : {"report", "png"})
      if (std::find(formats.begin(), formats.end(), f) == formats.end()) formats.push_back(f);
  }
  WriteJob<Dim> job{mesh, per_cell, report, c, base};
  if (s.layers) {
    job.coverage = &s.layers->coverage;
    // The layers grown along the metric, not the closing layer (its f_atten is infinite).
    job.layers = static_cast<int>(std::count_if(s.layers->layers.begin(), s.layers->layers.end(),
                                                [](const LayerStats& st) { return std::isfinite(st.f_atten); }));
  }
  for (const std::string& format : formats)
    if (format != "report")
      writer_registry<Dim>().create(format, c.file.string() + ": output.formats",
                                    job);
  clock.done("write", outputs.final_base().string() + ".*");
  report.timings_s = timings;
  if (std::find(formats.begin(), formats.end(), "report") != formats.end())
    writer_registry<Dim>().create("report", "", job);
  outputs.commit();
  out << report_summary(report);
  for (const std::string& f : outcome.failures) progress.error(config_path.string() + ": " + f);
  if (failed)
    progress.error(config_path.string() + ": the run FAILED; its report and picture are in " +
                   outputs.final_base().parent_path().string() + "/" +
                   (c.output.keep_invalid ? " with the mesh" : " (the mesh too with --keep-invalid)"));
  outcome.code = outcome.failures.empty() ? 0 : 2;
  // The verdict: one line (Quiet: on stdout; Json: the last object on stderr).
  std::ostringstream verdict;
  verdict << c.name << ": " << (failed ? "FAILED" : "valid") << ", " << report.cells_total << " cells, "
          << report.cells_invalid << " invalid, min scaled Jacobian " << num(report.scaled_jacobian_min) << "; "
          << outputs.final_base().string() << ".*";
  if (quiet && verdict_line) std::cout << verdict.str() << '\n';
  progress.verdict(!failed, outcome.code, verdict.str(),
                   "\"cells\": " + std::to_string(report.cells_total) + ", \"invalid_cells\": " +
                       std::to_string(report.cells_invalid) + ", \"min_scaled_jacobian\": " +
                       json_number(report.scaled_jacobian_min) + ", \"output\": " +
                       json_string(outputs.final_base().string()));
  outcome.report = std::move(report);
  outcome.base = outputs.final_base();
  if constexpr (Dim == 2)
    outcome.mesh2 = std::make_shared<const HybridMesh<2>>(std::move(s.mesh));
  else
    outcome.mesh3 = std::make_shared<const HybridMesh<3>>(std::move(s.mesh));
  return outcome;
}

// The keys most likely to mend a mesher failure, by the stage its message names.
std::string mesher_hint(const std::string& what, int dim) {
  auto starts = [&](const char* stage) { return what.rfind(stage, 0) == 0; };
  if (starts("layers"))
    return "; try a thinner first layer or fewer layers (metric.h0, layers.max), or a smaller "
           "layers.corner_angle_deg so that sharp corners get fans";
  if (starts("fill") || starts("advancing front") || starts("tetgen"))
    return dim == 3 ? "; try another farfield (fill.farfield.shape, size, h) or fewer layers (layers.max)"
                    : "; try another farfield (geometry.farfield) or sizes (metric.h_max), or fewer layers (layers.max)";
  if (starts("surface") || starts("remesh") || starts("curving"))
    return "; try other sizes along the wall (metric.h_wall_max, surface.curvature_factor)";
  if (starts("extrude")) return "; check the extrude section (extrude.span, extrude.rows)";
  return "";
}

}  // namespace

void register_all_plugins() {
  register_core_plugins();
  register_surface3d_plugins();
  layers::register_plugins();
  volume::register_plugins();
}

int run_command(const std::filesystem::path& config_path, const std::optional<std::filesystem::path>& out_dir,
                bool keep_invalid, Progress* progress) {
  register_all_plugins();
  std::optional<Progress> text;
  if (!progress) progress = &text.emplace(ProgressMode::Text, std::cerr);
  // Everything is validated before anything is written.
  RunConfig c = load_run_config(config_path);
  if (out_dir) c.output.dir = *out_dir;
  c.output.keep_invalid = keep_invalid;
  prepare_output_dir(c.output.dir, c.name);  // an unwritable folder refused now, not after the meshing
  try {
    return run_config(c, *progress).code;
  } catch (const MesherError& e) {
    // A mesher failure on valid keys (a stage that could not finish: no mesh to write): the run
    // failed, exit 2 as for an invalid mesh, its report (the error and the key most likely to
    // help) in OUTDIR/NAME.failed/ so that a sweep or a script finds why where it looks.
    const std::string hint = mesher_hint(e.what(), c.dim);
    OutputSet outputs(c.output.dir / (c.name + ".failed"), c.name);
    AtomicFile f(outputs.staged_base().string() + ".report.json");
    // The report of a run without a mesh: no cells, the failure, and the sections of the stages
    // that ran (StageFailure; empty when the error came from outside a stage).
    QualityReport report;
    report.name = c.name;
    report.exit_code = exit_code::invalid_mesh;
    report.run_failures = {e.what()};
    const auto* stage = dynamic_cast<const StageFailure*>(&e);
    if (stage) {
      report.run_failures.insert(report.run_failures.end(), stage->failures.begin(), stage->failures.end());
      report.extra = stage->sections;
    }
    report.extra.emplace_back("failure", "{\"error\": " + json_string(e.what()) + ", \"hint\": " +
                                             json_string(hint.empty() ? "" : hint.substr(2)) + ", \"mesh\": false}");
    f.write(report_json(report));
    f.commit();
    outputs.commit();
    progress->error(config_path.string() + ": " + e.what() + hint);
    progress->error(config_path.string() + ": the run FAILED before it had a mesh; its report is in " +
                    outputs.final_base().parent_path().string() + "/");
    const std::string verdict = c.name + ": FAILED before it had a mesh; " + outputs.final_base().string() + ".report.json";
    if (progress->mode() == ProgressMode::Quiet) std::cout << verdict << '\n';
    progress->verdict(false, exit_code::invalid_mesh, verdict,
                      "\"output\": " + json_string(outputs.final_base().string()));
    return exit_code::invalid_mesh;
  } catch (const ConfigError& e) {
    // A key found wrong only once the mesh exists (a farfield that does not enclose the layers):
    // the message names the key; name the config too, unless it already does (ConfigNode::where).
    const std::string what = e.what();
    if (what.rfind(config_path.string(), 0) == 0) throw;
    throw ConfigError(config_path.string() + ": " + what);
  }
}

RunOutcome run_config(const RunConfig& c, bool quiet) {
  Progress progress(quiet ? ProgressMode::Quiet : ProgressMode::Text, std::cerr);
  register_all_plugins();
  return c.dim == 3 ? run_pipeline<3>(c, progress, false) : run_pipeline<2>(c, progress, false);
}

RunOutcome run_config(const RunConfig& c, Progress& progress) {
  register_all_plugins();
  return c.dim == 3 ? run_pipeline<3>(c, progress, true) : run_pipeline<2>(c, progress, true);
}

int check_command(const std::filesystem::path& path, const std::optional<std::filesystem::path>& metric_config,
                  const std::optional<std::filesystem::path>& report_path) {
  register_all_plugins();
  std::vector<std::pair<std::string, double>> timings;
  Progress progress(ProgressMode::Text, std::cerr);
  StageClock clock(timings, progress);
  // The metric first: a bad config fails before the (possibly long) read.
  std::optional<RunConfig> c;
  std::unique_ptr<MetricField<2>> metric2;
  std::unique_ptr<MetricField<3>> metric3;
  QualityOptions qo;
  if (metric_config) {
    c = load_run_config(*metric_config);
    // The config's geometry and metric stages, nothing else.
    StageReport ignored;
    if (c->dim == 2) {
      RunState<2> s(*c);
      chosen<2>(*c, StageKind::Geometry)(s, ignored);
      chosen<2>(*c, StageKind::Metric)(s, ignored);
      metric2 = std::move(s.metric);
    } else {
      RunState<3> s(*c);
      chosen<3>(*c, StageKind::Geometry)(s, ignored);
      chosen<3>(*c, StageKind::Metric)(s, ignored);
      metric3 = std::move(s.metric);
    }
    qo.histogram_bins = c->output.histogram_bins;
    clock.done("metric", c->metric.type + " from " + metric_config->string());
  }
  const MshMesh m = read_mesh_file(path);
  clock.done("read", path.string() + ", dimension " + std::to_string(m.dim));
  QualityReport report;
  if (metric_config && m.dim != c->dim)
    throw InputError(path.string() + ": a " + std::to_string(m.dim) + "D mesh measured in the metric of a " +
                     std::to_string(c->dim) + "D configuration (" + metric_config->string() + ")");
  qo.progress = [&progress](double fraction, const std::string& what) { progress.step("quality", fraction, what); };
  if (m.dim == 2)
    report = assess_quality<2>(m.mesh2, metric2.get(), qo);
  else
    report = assess_quality<3>(m.mesh3, metric3.get(), qo);
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

int data_command(const std::vector<std::string>& files) {
  if (files.empty()) {
    for (const DataRoot& r : data_roots())
      std::cout << r.origin << ": "
                << (r.dir ? *r.dir + (std::filesystem::is_directory(*r.dir) ? "" : " (missing)") : std::string("-"))
                << '\n';
    return 0;
  }
  for (const std::string& f : files) {
    const std::string value = f.rfind(kDataPrefix, 0) == 0 ? f : kDataPrefix + f;
    std::cout << resolve_data_path(value, "plaf data " + f) << '\n';
  }
  return 0;
}

int plugins_command() {
  register_all_plugins();
  std::cout << plugin_listing();
  return 0;
}

}  // namespace plaf
