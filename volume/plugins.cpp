// SPDX-License-Identifier: MIT
#include "volume/plugins.h"

#include "modules/base/coordinates.h"
#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/pipeline/budget.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "volume/advancing_front_2d.h"
#include "volume/hybrid_fill3d.h"
#include "volume/optimize_2d.h"

#include <algorithm>
#include <limits>

namespace plaf::volume {

namespace {

// A point for the report: "[x, y, z]" (the text summary writes "(x, y, z)", format.h).
std::string json_point(const Eigen::Vector3d& x) { return json_array({json_number(x[0]), json_number(x[1]), json_number(x[2])}); }

HybridFillParams parse_tetgen(const ConfigNode& section) {
  HybridFillParams p;
  // TetGen's quality bound: 0 (off) or at least 1.1.
  p.tet.max_radius_edge = section.get_zero_or_in_range("max_radius_edge", p.tet.max_radius_edge, 1.1, 100.0);
  p.tet.max_volume = section.get_in_range("max_volume", 0.0, 0.0, std::numeric_limits<double>::max());
  p.optimize.passes = section.get_int("optimize_passes", p.optimize.passes, 0, 50);
  const ConfigNode f = section.child("farfield");
  FarfieldParams3& ff = p.farfield;
  ff.shape = f.get_choice("shape", ff.shape, {"sphere", "box"});
  // Within the readers' coordinate range (modules/base/coordinates.h), so plaf reads back what it writes.
  ff.radius = f.get_in_range("radius", 0.0, 0.0, kMaxCoordinate / 2);
  const std::vector<double> size = f.get_double_list("size", {0, 0, 0});
  if (size.size() != 3 || std::any_of(size.begin(), size.end(), [](double v) { return !(v >= 0 && v <= kMaxCoordinate); }))
    throw ConfigError(f.where("size") + ": three edge lengths in [0, " + num(kMaxCoordinate) +
                      "] (0: 20 x the bodies' diagonal)");
  std::copy(size.begin(), size.end(), ff.size.begin());
  ff.has_center = f.has("center");
  const std::vector<double> c = f.get_double_list("center", {0, 0, 0});
  if (c.size() != 3 || std::any_of(c.begin(), c.end(), [](double v) { return !(std::abs(v) <= kMaxCoordinate / 2); }))
    throw ConfigError(f.where("center") + ": three coordinates within +-" + num(kMaxCoordinate / 2));
  ff.center = Eigen::Vector3d(c[0], c[1], c[2]);
  ff.h = f.get_in_range("h", 0.0, 0.0, std::numeric_limits<double>::max());
  // TetGen keeps the farfield's triangles (-Y), so its tetrahedra there are about as large as
  // regular ones on them: an h whose regular tetrahedron exceeds max_volume cannot meet it.
  if (ff.h > 0 && p.tet.max_volume > 0 && ff.h > largest_edge_within(p.tet.max_volume))
    throw ConfigError(f.where("h") + ": " + num(ff.h) + " is too coarse for fill.max_volume " + num(p.tet.max_volume) +
                      " (a regular tetrahedron on the farfield's triangles would be larger); give h at most " +
                      num(largest_edge_within(p.tet.max_volume)) + " or leave it out");
  return p;
}

}  // namespace

void register_plugins() {
  static const bool once = [] {
    stage_registry<2>(StageKind::Fill)
        .add("advancing_front", [](const ConfigNode& section) -> Stage<2> {
          AdvancingFrontParams p;
          p.max_triangles = static_cast<std::size_t>(section.get_int("max_triangles", 20000000, 1, 2000000000));
          OptimizeParams opt;
          opt.passes = section.get_int("optimize_passes", opt.passes, 0, 50);
          return [p, opt](RunState<2>& s, StageReport& rep) {
            if (!s.layers) throw MesherError("fill: no front to fill from");
            AdvancingFrontResult fill = advancing_front_fill(s.layers->fill_front, *s.metric, p);
            const OptimizeStats o = optimize_fill(fill, s.layers->fill_front.nodes.size(), *s.metric, opt);
            rep.add("optimize_splits", o.splits);
            rep.add("optimize_collapses", o.collapses);
            rep.add("optimize_swaps", o.swaps);
            rep.add("optimize_moves", o.moves);
            rep.add("optimize_quality_min_before", o.quality_min_before);
            rep.add("optimize_quality_min_after", o.quality_min_after);
            rep.add("optimize_unit_fraction_before", o.unit_fraction_before);
            rep.add("optimize_unit_fraction_after", o.unit_fraction_after);
            rep.line("fill: optimised in the metric: " + std::to_string(o.splits) + " splits, " +
                     std::to_string(o.collapses) + " collapses, " + std::to_string(o.swaps) +
                     " swaps, " + std::to_string(o.moves) +
                     " moves; triangle quality min " + num(o.quality_min_before) + " -> " + num(o.quality_min_after) +
                     ", unit edges " + num(100 * o.unit_fraction_before) + " % -> " +
                     num(100 * o.unit_fraction_after) + " %");
            const AdvancingFrontStats& f = fill.stats;
            rep.add("steps", f.steps);
            rep.add("new_points", f.new_points);
            rep.add("merges", f.merges);
            rep.add("delaunay_apexes", f.delaunay_apexes);
            rep.add("max_front", f.max_front);
            rep.line("fill: " + std::to_string(f.steps) + " steps, " + std::to_string(f.new_points) + " new points, " +
                     std::to_string(f.merges) + " merges, " + std::to_string(f.delaunay_apexes) +
                     " Delaunay fallbacks, largest front " + std::to_string(f.max_front) + " edges");
            s.fill = static_cast<FillResult<2>&&>(std::move(fill));
          };
        });
    stage_registry<3>(StageKind::Fill).add("tetgen", [](const ConfigNode& section) -> Stage<3> {
      const HybridFillParams parsed = parse_tetgen(section);
      return [parsed](RunState<3>& s, StageReport& rep) {
        if (!s.layers) throw MesherError("fill: tetgen fills around prism layers; the layer stage grew none");
        HybridFillParams params = parsed;
        params.size_check = [&s](double tets) {  // the size budget (modules/pipeline/budget.h)
          // The whole mesh: the layers grown so far and the fill to come.
          const RunConfig& c = s.config;
          const auto layer_cells = static_cast<double>(s.layers->mesh.num_cells());
          const auto layer_nodes = static_cast<double>(s.layers->mesh.nodes.size());
          const std::string what = "the layers' " + std::to_string(static_cast<long>(layer_cells)) +
                                   " cells and the fill's tetrahedra";
          check_limit(c, "cells", layer_cells + tets, what);
          check_limit(c, "nodes", layer_nodes + tets * c.order * c.order * c.order / 6.0,
                      what + " of order " + std::to_string(c.order));
        };
        params.progress = [&s](double fraction, const std::string& what) { s.progress->step("fill", fraction, what); };
        HybridFill fill = fill_around_layers(*s.layers, *s.metric, params);
        const TetFillStats& st = fill.stats;
        rep.add("farfield.shape", fill.farfield.shape);
        rep.add("farfield.h", fill.farfield.h);
        rep.add("farfield.triangles", fill.farfield_triangles);
        rep.add("symmetry_triangles", fill.plane_triangles);
        rep.add("holes", fill.holes);
        rep.add("curved_front_triangles", fill.curved_front_triangles);
        rep.add("tets", st.tets);
        rep.add("new_points", st.new_points);
        rep.add("min_dihedral_deg", st.min_dihedral_deg);
        rep.add("max_radius_edge", st.max_radius_edge);
        rep.add("switches", st.switches);
        rep.line("fill: " + std::to_string(st.tets) + " tetrahedra, " + std::to_string(st.new_points) +
                 " new points, min dihedral " + std::to_string(st.min_dihedral_deg) + " deg (TetGen -" + st.switches + ")");
        const Optimize3Stats& o = fill.optimize;
        rep.add("optimize.splits", o.splits);
        rep.add("optimize.collapses", o.collapses);
        rep.add("optimize.swaps", o.swaps);
        rep.add("optimize.moves", o.moves);
        rep.add("optimize.repairs", o.repairs);
        for (const auto& [when, f] : {std::pair{"before", &o.before}, std::pair{"after", &o.after}}) {
          const std::string k = std::string("optimize.") + when + ".";
          rep.add(k + "tets", f->tets);
          rep.add(k + "quality_min", f->quality_min);
          rep.add(k + "quality_min_inner", f->quality_min_inner);
          rep.add(k + "unit_fraction", f->unit_fraction);
          rep.add(k + "length_min", f->length_min);
          rep.add(k + "length_max", f->length_max);
          rep.add(k + "length_max_free", f->length_max_free);
          rep.add(k + "min_dihedral_deg", f->min_dihedral_deg);
          rep.add(k + "min_dihedral_inner_deg", f->min_dihedral_inner_deg);
          rep.add(k + "below_5deg", f->below_5deg);
          rep.add(k + "below_10deg", f->below_10deg);
          rep.add(k + "flat", f->flat);
          rep.add(k + "volume_max", f->volume_max);
          rep.add(k + "metric_min_dihedral_deg", f->metric_min_dihedral_deg);
          rep.add(k + "metric_min_dihedral_inner_deg", f->metric_min_dihedral_inner_deg);
          rep.add(k + "metric_below_5deg", f->metric_below_5deg);
          rep.add(k + "metric_below_10deg", f->metric_below_10deg);
          rep.add_json(k + "metric_min_dihedral_at", json_point(f->metric_min_dihedral_at));
          rep.add_json(k + "length_max_at", json_point(f->length_max_at));
          rep.add(k + "stretched.tets", f->stretched.tets);
          rep.add(k + "stretched.metric_p50", f->stretched.metric_p50);
          rep.add(k + "stretched.stretch_p10", f->stretched.stretch_p10);
          rep.add(k + "stretched.stretch_p50", f->stretched.stretch_p50);
          rep.add(k + "stretched.stretch_p90", f->stretched.stretch_p90);
          rep.add(k + "stretched.at_least_10", f->stretched.at_least_10);
          rep.add(k + "stretched.quality_p50", f->stretched.quality_p50);
        }
        for (const auto& [when, f] : {std::pair{"before", &fill.front_ratio_before}, std::pair{"after", &fill.front_ratio_after}}) {
          const std::string k = std::string("front_ratio.") + when + ".";
          rep.add(k + "triangles", f->triangles);
          rep.add(k + "p50", f->p50);
          rep.add(k + "p95", f->p95);
          rep.add(k + "max", f->max);
        }
        if (parsed.tet.max_volume > 0 && o.after.volume_max > parsed.tet.max_volume * (1 + 1e-9))
          rep.fail("fill.max_volume " + num(parsed.tet.max_volume) + " is not met: the largest tetrahedron's volume is " +
                   num(o.after.volume_max) + " (TetGen keeps the fronts' triangles; coarse ones cannot hold small tetrahedra)");
        rep.line("fill: optimised in the metric: " + std::to_string(o.splits) + " splits, " +
                 std::to_string(o.collapses) + " collapses, " + std::to_string(o.swaps) + " swaps, " +
                 std::to_string(o.moves) + " moves, " + std::to_string(o.repairs) + " sliver repairs; tets " +
                 std::to_string(o.before.tets) + " -> " +
                 std::to_string(o.after.tets) + ", unit edges " + num(100 * o.before.unit_fraction) + " % -> " +
                 num(100 * o.after.unit_fraction) + " %, longest " + num(o.before.length_max) + " -> " +
                 num(o.after.length_max) + " at " + point_text(o.after.length_max_at, 6) + " (" + num(o.before.length_max_free) + " -> " + num(o.after.length_max_free) +
                 " with a free end), least quality " + num(o.before.quality_min) + " -> " +
                 num(o.after.quality_min) + " (" + num(o.before.quality_min_inner) + " -> " +
                 num(o.after.quality_min_inner) + " off the fronts), min dihedral " + num(o.before.min_dihedral_deg) + " -> " +
                 num(o.after.min_dihedral_deg) + " deg (" + num(o.before.min_dihedral_inner_deg) + " -> " +
                 num(o.after.min_dihedral_inner_deg) + " off the fronts), under 10 deg " +
                 std::to_string(o.before.below_10deg) + " -> " + std::to_string(o.after.below_10deg) +
                 "; in the metric: min dihedral " + num(o.before.metric_min_dihedral_deg) + " -> " +
                 num(o.after.metric_min_dihedral_deg) + " deg at " + point_text(o.after.metric_min_dihedral_at, 6) + " (" + num(o.before.metric_min_dihedral_inner_deg) + " -> " +
                 num(o.after.metric_min_dihedral_inner_deg) + " off the fronts), under 10 deg " +
                 std::to_string(o.before.metric_below_10deg) + " -> " + std::to_string(o.after.metric_below_10deg) + "; flat " +
                 std::to_string(o.before.flat) + " -> " + std::to_string(o.after.flat) +
                 "; first tetrahedron over last layer's height across the outer front: median " +
                 num(fill.front_ratio_before.p50) + " -> " + num(fill.front_ratio_after.p50) + ", 95 % " +
                 num(fill.front_ratio_before.p95) + " -> " + num(fill.front_ratio_after.p95));
        if (o.after.stretched.tets > 0)
          rep.line("fill: where the metric is stretched 10:1 or more (median " + num(o.after.stretched.metric_p50) +
                   ":1): " + std::to_string(o.before.stretched.tets) + " -> " + std::to_string(o.after.stretched.tets) +
                   " tets, their own stretch median " + num(o.before.stretched.stretch_p50) + " -> " +
                   num(o.after.stretched.stretch_p50) + " (10 % under " + num(o.after.stretched.stretch_p10) + "), " +
                   num(100 * o.after.stretched.at_least_10) + " % of them 10:1 or more, quality median " +
                   num(o.before.stretched.quality_p50) + " -> " + num(o.after.stretched.quality_p50));
        if (fill.curved_front_triangles > 0)
          rep.line("fill: " + std::to_string(fill.curved_front_triangles) +
                   " triangles of the layers' outer front are still curved (no valid closing layer there, "
                   "layers.events): the tetrahedra on them are curved, certified with every cell");
        s.fill = std::move(fill.fill);
      };
    });
    return true;
  }();
  (void)once;
}

}  // namespace plaf::volume
