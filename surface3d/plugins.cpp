// SPDX-License-Identifier: MIT
// The 3D surface stages (plugins.h): geometry, then the surface mesh, each reporting what it did.
#include "surface3d/plugins.h"

#include "surface3d/fidelity.h"

#include <algorithm>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/metric/metric_fields.h"
#include "modules/metric/metric_integrals.h"
#include "modules/pipeline/budget.h"
#include "modules/pipeline/naca_config.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "surface3d/analytic.h"
#include "surface3d/curvature_metric.h"
#include "surface3d/features.h"
#include "surface3d/graded_metric.h"
#include "surface3d/high_order.h"
#include "surface3d/read_surface.h"
#include "surface3d/remesh.h"
#include "surface3d/smooth_reference.h"
#include "surface3d/validate.h"

namespace plaf {

namespace {

// Three numbers; with `positive`, each > 0.
std::array<double, 3> get_triple(const ConfigNode& n, const std::string& key, std::array<double, 3> fallback,
                                 std::optional<Bounds> positive = std::nullopt) {
  const std::vector<double> v =
      positive ? n.get_double_list(key, {fallback[0], fallback[1], fallback[2]}, 0.0, std::numeric_limits<double>::max(), *positive)
               : n.get_double_list(key, {fallback[0], fallback[1], fallback[2]});
  if (v.size() != 3) throw ConfigError(n.where(key) + ": expected three numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

}  // namespace

Geometry3Params parse_geometry3_params(const ConfigNode& g, const std::string& type) {
  Geometry3Params s;
  if (type == "sphere" || type == "ellipsoid") s.center = get_triple(g, "center", s.center);
  if (type == "sphere") s.radius = g.get_positive("radius", s.radius);
  if (type == "ellipsoid") {
    s.semi_axes = get_triple(g, "semi_axes", s.semi_axes, Bounds::OpenLow);  // positive
  }
  if (type == "box") {
    s.lo = get_triple(g, "lo", s.lo);
    s.hi = get_triple(g, "hi", s.hi);
    for (int k = 0; k < 3; ++k)
      if (!(s.hi[k] > s.lo[k])) throw ConfigError(g.where("hi") + ": every coordinate must exceed lo's");
  }
  if (type == "wing") {
    s.file = g.get_path("file", "");
    s.naca = parse_naca(g);
    if (s.file.empty() == !s.naca)
      throw ConfigError(g.where() + ": a wing needs its section: file (an airfoil file) or naca (a NACA section), one of them");
    s.chord = g.get_positive("chord", s.chord);
    s.span = g.get_positive("span", s.span);
    s.root = g.get_choice("root", s.root, {"flat", "rounded", "symmetry"});
    s.tip = g.get_choice("tip", s.tip, {"flat", "rounded", "symmetry"});
    s.corner_angle_deg = g.get_in_range("corner_angle_deg", s.corner_angle_deg, 0.0, 180.0, Bounds::Open);
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
    const std::string si = g.get_choice("self_intersections", "repair", {"repair", "check", "skip"});
    s.check_self_intersections = si != "skip";
    s.repair_folded_caps = si == "repair";
    s.repair_slivers = g.get_choice("slivers", "repair", {"repair", "keep"}) == "repair";
    s.drop_inner_components = g.get_choice("inner_components", "drop", {"error", "drop"}) == "drop";
    s.smooth_reference = g.get_choice("reference", "facets", {"smooth", "facets"}) == "smooth";
  }
  return s;
}

SurfaceParams parse_surface_params(const ConfigNode& sf) {
  SurfaceParams sp;
  sp.ridge_angle_deg = sf.get_in_range("ridge_angle_deg", sp.ridge_angle_deg, 0.0, 180.0);
  sp.corner_defect_deg = sf.get_in_range("corner_defect_deg", sp.corner_defect_deg, 0.0, 360.0);
  sp.curve_turn_deg = sf.get_in_range("curve_turn_deg", sp.curve_turn_deg, 0.0, 180.0);
  sp.remesh = sf.get_bool("remesh", sp.remesh);
  sp.iterations = sf.get_int("iterations", sp.iterations, 1, 100);
  sp.curvature_factor = sf.get_in_range("curvature_factor", sp.curvature_factor, 0.0, 100.0);
  sp.curvature_h_min = sf.has("curvature_h_min") ? sf.get_positive("curvature_h_min", 1.0) : 0;
  sp.max_triangles = sf.get_int("max_triangles", sp.max_triangles, 1, 2000000000);
  sp.fidelity_tol = sf.get_positive("fidelity_tol", sp.fidelity_tol);
  sp.fidelity_rounds = sf.get_int("fidelity_rounds", sp.fidelity_rounds, 0, 10);
  // The growth of sizes between neighbours (> 1), or 0: off.
  sp.gradation = sf.get_zero_or_in_range("gradation", sp.gradation, 1.0, 100.0, Bounds::OpenLow);
  sp.min_scaled_jacobian = sf.get_in_range("min_scaled_jacobian", sp.min_scaled_jacobian, 0.0, 0.9);
  sp.curvature_h_min_where = sf.where("curvature_h_min");
  return sp;
}

namespace {

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

WingEnd wing_end(const std::string& s) {
  return s == "flat" ? WingEnd::Flat : s == "rounded" ? WingEnd::Rounded : WingEnd::Symmetry;
}

std::string feature_json(const FeatureReport& f) {
  return "{\"ridges_convex\": " + std::to_string(f.ridges_convex) +
         ", \"ridges_concave\": " + std::to_string(f.ridges_concave) +
         ", \"boundary_edges\": " + std::to_string(f.boundary_edges) +
         ", \"corners_convex\": " + std::to_string(f.corners_convex) +
         ", \"corners_concave\": " + std::to_string(f.corners_concave) +
         ", \"corners_saddle\": " + std::to_string(f.corners_saddle) +
         ", \"corners_boundary\": " + std::to_string(f.corners_boundary) + ", \"curves\": " + std::to_string(f.curves) +
         "}";
}

std::string feature_line(const FeatureReport& f) {
  std::ostringstream o;
  o << f.curves << " curves (" << f.ridges_convex << " convex, " << f.ridges_concave << " concave ridge edges, "
    << f.boundary_edges << " boundary edges), corners: " << f.corners_convex << " convex, " << f.corners_concave
    << " concave, " << f.corners_saddle << " saddle, " << f.corners_boundary << " boundary";
  return o.str();
}

FeatureOptions feature_options(const SurfaceParams& sp) {
  FeatureOptions fo;
  fo.ridge_angle_deg = sp.ridge_angle_deg;
  fo.corner_defect_deg = sp.corner_defect_deg;
  fo.curve_turn_deg = sp.curve_turn_deg;
  return fo;
}

// The centre of an analytic body, where the surface stage reads the metric's size.
Eigen::Vector3d body_center(const std::string& type, const Geometry3Params& g) {
  if (type == "box") return 0.5 * (vec(g.lo) + vec(g.hi));
  if (type == "wing") return {0.5 * g.chord, 0, 0.5 * g.span};
  return vec(g.center);
}

// An analytic body (analytic.h) at size h: its exact reference and initial triangulation.
AnalyticBody make_body(const std::string& type, const Geometry3Params& g, double h) {
  // The initial lattice resolves the body's smallest extent (a cube lattice with fewer divisions
  // would not be the body), but never at more than 1/16 (box: 1/32, wing: 1/64) of its largest:
  // a thin box 1 x 1 x 0.001 at half its thickness is a 2000 x 2000 lattice, 16M triangles for a
  // final mesh of 200 nodes (issue 37, item 1). Bodies within those aspect ratios are built as before.
  if (type == "sphere") return make_sphere(vec(g.center), g.radius, std::min(h, g.radius));
  if (type == "ellipsoid") {
    const Eigen::Vector3d a = vec(g.semi_axes);
    return make_ellipsoid(vec(g.center), a, std::min(h, std::max(a.minCoeff(), a.maxCoeff() / 16)));
  }
  if (type == "box") {
    const Eigen::Vector3d e = vec(g.hi) - vec(g.lo);
    return make_box(vec(g.lo), vec(g.hi), std::min(h, std::max(e.minCoeff() / 2, e.maxCoeff() / 32)));
  }
  WingParams w;
  w.file = g.file;
  w.naca = g.naca;
  w.chord = g.chord;
  w.span = g.span;
  w.root = wing_end(g.root);
  w.tip = wing_end(g.tip);
  w.corner_angle_deg = g.corner_angle_deg;
  return make_wing(w, std::min(h, std::max(std::min(g.chord, g.span) / 4, std::max(g.chord, g.span) / 64)));
}

// A surface file's reference: smooth patches on it or its flat facets (plugins.h: reference).
std::unique_ptr<ReferenceGeometry<3>> file_reference(const TriSurface& surface, bool smooth) {
  return smooth ? make_smooth_reference(surface) : make_discrete_reference(surface);
}

// A surface file: read and validated (repairs reported), its features detected; it is its own
// reference.
void surface_file(const Geometry3Params& g, RunState<3>& s, StageReport& rep) {
  const TriangleSoup soup = read_surface_file(g.file, ReadSurfaceOptions{g.weld_rel});
  SurfaceCheckOptions so;
  for (const SymmetryPlaneParams& p : g.symmetry_planes) so.symmetry_planes.push_back({vec(p.normal), p.offset});
  so.check_self_intersections = g.check_self_intersections;
  so.repair_folded_caps = g.repair_folded_caps;
  so.repair_slivers = g.repair_slivers;
  so.drop_inner_components = g.drop_inner_components;
  SurfaceCheckReport k;
  s.surface = validate_surface(soup, so, &k);
  for (const std::string& r : k.repairs) s.progress->note("geometry", "repaired: " + r);
  // Its own reference, with the features of the default options (the surface stage detects them
  // again when its section asks for other angles).
  const FeatureReport features = detect_features(s.surface, feature_options(SurfaceParams{}));
  s.reference = file_reference(s.surface, g.smooth_reference);
  std::vector<std::string> repairs;
  for (const std::string& r : k.repairs) repairs.push_back(json_string(r));
  rep.set_section("surface");
  rep.add("geometry", s.config.geometry.type);
  rep.add("reference", g.smooth_reference ? "smooth" : "facets");
  rep.add("input_triangles", k.input_triangles);
  rep.add("input.components", k.components);
  rep.add("input.euler_characteristic", k.euler_characteristic);
  rep.add("input.volume", k.volume);
  rep.add("input.boundary_loops", k.boundary_loops);
  rep.add("input.symmetry_edges", k.symmetry_edges);
  rep.add("input.slivers", k.slivers_found);
  rep.add("input.slivers_left", k.slivers_left);
  rep.add_json("input.repairs", json_array(repairs));
  rep.line("geometry: " + g.file + ": " + std::to_string(k.input_triangles) + " triangles, " +
           std::to_string(k.components) + " components, chi = " + std::to_string(k.euler_characteristic));
  rep.line("features (input): " + feature_line(features));
}

// The surface section of the report: the final surface, its features, the remeshing and curving.
void report_surface(const TriSurface& surface, int order, const FeatureReport& kept, const FeatureReport& detected,
                    const RemeshReport& rr, const CurvingReport& cr, StageReport& rep) {
  const double area = surface_area(surface);
  rep.add("order", order);
  rep.add("triangles", surface.mesh.n_faces());
  rep.add("vertices", surface.mesh.n_vertices());
  rep.add("euler_characteristic", surface.euler_characteristic());
  rep.add("area", area);
  rep.add_json("features.final", feature_json(kept));
  rep.add_json("features.detected", feature_json(detected));
  rep.add("remesh.rounds", rr.rounds);
  rep.add("remesh.splits", rr.splits);
  rep.add("remesh.collapses", rr.collapses);
  rep.add("remesh.flips", rr.flips);
  rep.add("remesh.unit_fraction", rr.unit_fraction);
  rep.add("remesh.longest_edge", rr.longest);
  rep.add("remesh.long_edges", rr.long_edges);
  rep.add("remesh.folded_faces", rr.folded_faces);
  rep.add("remesh.crossing_pairs_found", rr.crossing_pairs_found);
  rep.add("remesh.untangle_collapses", rr.untangle_collapses);
  rep.add("remesh.refused_splits", rr.refused_splits);
  rep.add("remesh.fan_cuts", rr.fan_cuts);
  rep.add("remesh.slivers_removed", rr.slivers_removed);
  rep.add("remesh.caps", rr.caps);
  rep.add("curving.straightened", cr.straightened);
  rep.add("curving.invalid", cr.invalid);
  rep.add("curving.min_scaled_jacobian", cr.min_scaled_jacobian);
  rep.line("surface: " + std::to_string(surface.mesh.n_faces()) + " triangles, " +
           std::to_string(surface.mesh.n_vertices()) + " vertices, chi " +
           std::to_string(surface.euler_characteristic()) + ", area " + std::to_string(area));
}

// The smallest size the surface mesh asks for: curvature's floor when curvature sizes are on,
// else the metric's smallest size at the surface's first vertex.
double smallest_size(const SurfaceParams& sp, const RunState<3>& s) {
  if (s.surface.mesh.n_vertices() == 0) return 0;
  const double base_min = s.surface_base().evaluate(s.surface.mesh.point(*s.surface.mesh.vertices().begin())).min_size();
  if (sp.curvature_factor <= 0) return base_min;
  return sp.curvature_h_min > 0 ? sp.curvature_h_min : base_min / 20;
}

// The size budget (modules/pipeline/budget.h) of a surface of about `triangles` order-Q triangles.
void check_surface_budget(const RunConfig& c, double triangles) {
  check_limit(c, "surface_elements", triangles, "the surface's triangles");
  check_limit(c, "nodes", triangles * c.order * c.order / 2.0,
              "the surface's order-" + std::to_string(c.order) + " triangles");
  // The layers' budget (layers/plugins.cpp) on the triangles to come, before they are made: a
  // metric.h_max of 0.01 on the sphere hybrid meshed 420k wall triangles for 77 s before the
  // layers refused them (issue 37, item 6).
  if (c.layers.enabled() && c.layers_max > 0) check_layer_budget(c, triangles, c.layers_max, 3, true);
}

// The surface mesh: curvature-driven sizes (optional), remeshing with features kept, the features
// detected again on the final mesh as a check, order-Q nodes on the reference, every triangle
// certified.
void remesh_and_curve(const SurfaceParams& sp, RunState<3>& s, StageReport& rep) {
  const RunConfig& c = s.config;
  // An analytic body starts from a triangulation at 1.5 times the metric's largest size at its
  // centre: one split brings its edges to 0.75, inside the unit band (a start at exactly twice the
  // size splits the lattice's diagonals to 1/sqrt 2, on the band's edge).
  if (s.build_body) {
    // The size budget before the initial triangulation (itself about half the final count): the
    // body built coarse (once at any size, then at an eighth of its diagonal), measured in the
    // sizes; the curvature sizes come on top and are checked below.
    RunState<3> probe(c);
    s.build_body(probe, std::numeric_limits<double>::max());
    const TriangleSoup first = soup_from_surface(probe.surface);
    Eigen::Vector3d lo = first.points.front(), hi = first.points.front();
    for (const Eigen::Vector3d& x : first.points) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    s.build_body(probe, (hi - lo).norm() / 8);
    const TriangleSoup coarse = soup_from_surface(probe.surface);
    check_surface_budget(c, kTrianglesPerMetricArea * metric_surface_area(coarse.points, coarse.triangles, s.surface_base()));
    s.build_body(s, 1.5 * s.surface_base().evaluate(s.body_center).max_size());
    rep.add("input_triangles", s.surface.mesh.n_faces());
    rep.line("initial triangulation: " + std::to_string(s.surface.mesh.n_faces()) + " triangles");
    rep.line("features (input): " + feature_line(count_features(s.surface)));
  } else {
    // A surface file, its features found again with the section's angles and at the mesh's
    // scale: a rounded edge narrower than half the smallest size is one ridge on its crest
    // (features.h; the M6's trailing edge, a cap of radius 3.5e-4 turning 22 degrees per edge).
    FeatureOptions fo = feature_options(sp);
    fo.crest_scale = 0.5 * smallest_size(sp, s);
    fo.min_curve_length = 0.5 * smallest_size(sp, s);
    const FeatureReport features = detect_features(s.surface, fo);
    s.reference = file_reference(s.surface, is_smooth_reference(*s.reference));
    rep.line("features (input, at the mesh's scale): " + feature_line(features) +
             (features.dropped_curves ? ", " + std::to_string(features.dropped_curves) +
                                            " curves shorter than half the smallest size dropped"
                                      : std::string()));
    rep.add("features.dropped_short_curves", features.dropped_curves);
  }
  rep.add_json("features.input", feature_json(count_features(s.surface)));
  TriSurface& surface = s.surface;
  if (surface.mesh.n_vertices() == 0) throw MesherError("surface: no vertices to mesh");
  const double base_min = s.surface_base().evaluate(surface.mesh.point(*surface.mesh.vertices().begin())).min_size();
  if (sp.curvature_h_min > 0 && sp.curvature_h_min >= base_min)
    throw ConfigError(sp.curvature_h_min_where + ": " + std::to_string(sp.curvature_h_min) +
                      " must be smaller than the metric's smallest size " + std::to_string(base_min));
  if (sp.curvature_factor > 0) {
    const double h_min = sp.curvature_h_min > 0 ? sp.curvature_h_min : base_min / 20;
    // Half the fidelity tolerance for the chord error (the rest for the remesher's sizes, which
    // are met within a band, not exactly), over the diagonal the fidelity check divides by.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for (const auto v : surface.mesh.vertices()) {
      const auto p = surface.mesh.point(v);
      const Eigen::Vector3d x(p[0], p[1], p[2]);
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    const ChordCap chord{c.order, 0.5 * sp.fidelity_tol * (hi - lo).norm()};
    s.surface_metric =
        std::make_unique<CurvatureMetricField>(s.surface_base(), *s.reference, sp.curvature_factor, h_min, chord);
  }
  const MetricField<3>& field = *s.measure();  // (with curvature sizes: the raw field, graded below)
  {
    // The size budget (modules/pipeline/budget.h): unit triangles of the metric on the input.
    const TriangleSoup soup = soup_from_surface(surface);
    check_surface_budget(c, kTrianglesPerMetricArea * metric_surface_area(soup.points, soup.triangles, field));
  }
  // The body sampled before the remesher moves anything (fidelity.h); a surface file's facets are
  // the body only for the facets reference (the smooth one curves between the vertices).
  const std::vector<Eigen::Vector3d> body =
      reference_samples(s.surface, *s.reference, !s.build_body && !is_smooth_reference(*s.reference));
  RemeshReport rr;
  RemeshOptions ro;
  ro.iterations = sp.iterations;
  ro.max_triangles = static_cast<std::size_t>(sp.max_triangles);
  // The progress: each pass of the remesher (the first, the graded one, a fidelity refinement's)
  // an equal share of the stage, its rounds within it.
  const int passes = 1 + (s.surface_metric && sp.gradation > 1 ? 1 : 0) + sp.fidelity_rounds;
  int pass = 0;
  ro.on_round = [&s, &pass, passes](int round, int rounds) {
    s.progress->step("surface", (pass + static_cast<double>(round) / rounds) / passes,
                     "remesh round " + std::to_string(round) + " of " + std::to_string(rounds) +
                         (pass > 0 ? " (pass " + std::to_string(pass + 1) + ")" : std::string()),
                     "\"round\": " + std::to_string(round) + ", \"rounds\": " + std::to_string(rounds) +
                         ", \"pass\": " + std::to_string(pass + 1));
  };
  const TriSurface input = sp.remesh ? surface : TriSurface();  // what a remesh starts from
  if (sp.remesh) {
    const bool grade = s.surface_metric && sp.gradation > 1;
    rr = remesh_surface(surface, *s.reference, field, ro);
    if (grade) {
      // Gradation (graded_metric.h): the raw curvature sizes H-corrected on the mesh they gave,
      // then the input remeshed on the graded field, which the run measures from here on (a second
      // pass over the first one's result instead would lose 4 % of the unit edges on the E387 wing).
      // (by vertex index, deleted vertices kept in place: soup_from_surface would renumber them)
      std::vector<Eigen::Vector3d> points(surface.mesh.n_vertices());
      std::vector<std::array<int, 3>> tris;
      for (const auto v : surface.mesh.vertices()) {
        const auto& q = surface.mesh.point(v);
        points[static_cast<std::size_t>(v.idx())] = Eigen::Vector3d(q[0], q[1], q[2]);
      }
      for (const auto f : surface.mesh.faces()) {
        std::array<int, 3> t{};
        int k = 0;
        for (const auto v : surface.mesh.fv_range(f)) t[static_cast<std::size_t>(k++)] = v.idx();
        tris.push_back(t);
      }
      auto graded = std::make_unique<GradedMetricField>(std::move(s.surface_metric), points, tris, sp.gradation);
      std::ostringstream g;
      g << "{\"beta\": " << json_number(sp.gradation) << ", \"support_points\": " << points.size()
        << ", \"corrected_points\": " << graded->corrected_points() << "}";
      rep.add_json("gradation", g.str());
      rep.line("gradation: beta " + std::to_string(sp.gradation) + ", " + std::to_string(graded->corrected_points()) +
               " of " + std::to_string(points.size()) + " sizes made finer; remeshed again");
      s.surface_metric = std::move(graded);
      surface = input;
      ++pass;
      rr = remesh_surface(surface, *s.reference, *s.surface_metric, ro);
    }
  }
  ValidityOptions vo;
  vo.rel_tol = c.validity.rel_tol;
  vo.max_depth = c.validity.max_depth;
  CurvingReport cr = curve_surface(surface, *s.reference, c.order, vo, sp.min_scaled_jacobian);
  // The fidelity loop: where the curved surface leaves its body by more than half the tolerance
  // (a crease under the ridge angle, a curvature the sizing's probe did not see), its sizes are
  // made finer and the input remeshed again, up to fidelity_rounds times while it is still over the
  // tolerance. A spot's factor is sqrt(0.4 tol / distance), in [0.25, 0.8]: the chord error falls
  // as h^2 on a smooth curve at order 1 and as h across a crease, so one round brings a crease's
  // error to 0.4-0.8 of the tolerance; its radius is three of the sizes there. Spots are the far
  // samples, the worst first, each at least a third of its radius from the ones kept before it.
  // A remesh that left faces crossing each other (two sheets or feature curves closer than the
  // size, which the remesher's untangling could not close: a slot 0.03 wide under a size of 0.27
  // on the published Orion capsule) gets a round too: spots of factor 0.5 at the crossing faces,
  // so the sizes there fall toward the gap round by round.
  const double diagonal = samples_diagonal(body), target = 0.5 * sp.fidelity_tol * diagonal;
  FidelityReport fr = measure_fidelity(surface, *s.reference, body, target);
  std::vector<std::string> rounds;
  const auto far_off = [&] { return !(fr.relative <= sp.fidelity_tol) && !fr.far.empty(); };
  for (int round = 1; sp.remesh && round <= sp.fidelity_rounds && rr.folded_faces == 0 && cr.invalid == 0 &&
                      (far_off() || rr.crossing_pairs > 0);
       ++round) {
    const MetricField<3>& now = *s.measure();
    std::vector<FidelityRefinedField::Spot> spots;
    const auto add_spot = [&](const Eigen::Vector3d& x, double factor) {
      const double radius = 3 * now.evaluate(x).max_size();
      if (std::none_of(spots.begin(), spots.end(), [&](const auto& o) { return (o.point - x).norm() < o.radius / 3; }))
        spots.push_back({x, factor, radius});
    };
    if (rr.crossing_pairs > 0)
      for (const Eigen::Vector3d& x : rr.crossing_points) add_spot(x, 0.5);
    const std::size_t crossing_spots = spots.size();
    if (far_off()) {
      std::sort(fr.far.begin(), fr.far.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
      for (const auto& [x, d] : fr.far) add_spot(x, std::clamp(std::sqrt(0.8 * target / d), 0.25, 0.8));
    }
    const double before = fr.relative;
    if (s.surface_metric)
      s.surface_metric = std::make_unique<FidelityRefinedField>(std::move(s.surface_metric), spots);
    else
      s.surface_metric = std::make_unique<FidelityRefinedField>(s.surface_base(), spots);
    surface = input;
    ++pass;
    rr = remesh_surface(surface, *s.reference, *s.surface_metric, ro);
    cr = curve_surface(surface, *s.reference, c.order, vo, sp.min_scaled_jacobian);
    fr = measure_fidelity(surface, *s.reference, body, target);
    std::ostringstream o;
    o << "fidelity refinement " << round << ": " << spots.size() - crossing_spots << " spots over half the tolerance, "
      << crossing_spots << " where faces crossed, " << rr.faces_after << " triangles, Hausdorff distance " << before << " -> " << fr.relative << " of the diagonal";
    rep.line(o.str());
    rounds.push_back("{\"spots\": " + std::to_string(spots.size() - crossing_spots) + ", \"crossing_spots\": " +
                     std::to_string(crossing_spots) + ", \"triangles\": " +
                     std::to_string(rr.faces_after) + ", \"relative_before\": " + json_number(before) +
                     ", \"relative_after\": " + json_number(fr.relative) + "}");
  }
  rep.add_json("fidelity_refinement", json_array(rounds));
  if (sp.remesh)
    rep.line("remesh: " + std::to_string(rr.faces_before) + " -> " + std::to_string(rr.faces_after) +
             " triangles, unit fraction " + std::to_string(rr.unit_fraction) + ", " +
             std::to_string(rr.folded_faces) + " folded" +
             (rr.folded_faces ? " (first at " + rr.first_folded + ")" : ""));
  // Edges the remesher could not split (a thin face on either side would fold): the layers
  // extrude them as they are, into cells as stretched along the wall as the edge is long.
  if (sp.remesh && rr.long_edges > 0)
    rep.line("WARNING: remesh: " + std::to_string(rr.long_edges) + " edges longer than " + num(kLongEdge) +
             " in the metric could not be split (the longest " + num(rr.longest) + ", at " + rr.first_long +
             "): check the input's triangles there (thin faces) or give finer sizes");
  if (sp.remesh && rr.crossing_pairs_found > 0)
    rep.line("remesh: " + std::to_string(rr.crossing_pairs_found) + " pairs of faces crossing each other, " +
             std::to_string(rr.untangle_collapses) + " edges collapsed to untangle them, " +
             std::to_string(rr.crossing_pairs) + " left");
  // A surface that crosses itself is no wall to grow layers from: refused here, where it is made,
  // not as a first layer that cannot be grown.
  if (sp.remesh && rr.crossing_pairs > 0)
    throw MesherError("surface: the remeshed surface crosses itself: " + std::to_string(rr.crossing_pairs) +
                      " pairs of faces (first near " + rr.first_crossing +
                      ") that remeshing could not untangle; two feature curves or sheets there are closer "
                      "than the size: give finer sizes there (metric, surface.curvature_factor) or check "
                      "the input's triangles there");
  const FeatureReport kept = count_features(surface);
  TriSurface probe = surface;
  // The final mesh's features judged on the body (features.h: edges along the reference's feature
  // curves), not on the bend of its small triangles at rounded edges.
  FeatureOptions final_options = feature_options(sp);
  final_options.reference = s.reference.get();
  const FeatureReport detected = detect_features(probe, final_options);
  rep.line("features (final): " + feature_line(kept));
  rep.line("features (detected on the final mesh): " + feature_line(detected));
  s.mesh = surface_to_mesh(surface);
  s.mesh_done = true;
  s.front = surface_front(s.mesh, *s.reference);
  rep.line("high order: " + std::to_string(cr.triangles) + " triangles of order " + std::to_string(c.order) + ", " +
           std::to_string(cr.straightened) + " straightened, " + std::to_string(cr.invalid) + " invalid");
  report_surface(surface, c.order, kept, detected, rr, cr, rep);
  std::ostringstream at, json, line, why;
  at << "(" << fr.worst.x() << ", " << fr.worst.y() << ", " << fr.worst.z() << ")";
  json << "{\"hausdorff\": " << json_number(fr.hausdorff) << ", \"relative\": " << json_number(fr.relative)
       << ", \"tolerance\": " << json_number(sp.fidelity_tol) << ", \"to_reference\": " << json_number(fr.to_reference)
       << ", \"to_mesh\": " << json_number(fr.to_mesh) << ", \"worst\": [" << json_number(fr.worst.x()) << ", "
       << json_number(fr.worst.y()) << ", " << json_number(fr.worst.z()) << "], \"mesh_samples\": " << fr.mesh_samples
       << ", \"reference_samples\": " << fr.reference_samples << "}";
  rep.add_json("fidelity", json.str());
  line << "fidelity: Hausdorff distance " << fr.hausdorff << " (" << fr.relative << " of the diagonal; mesh -> body "
       << fr.to_reference << ", body -> mesh " << fr.to_mesh << ") at " << at.str();
  rep.line(line.str());
  const bool far = !(fr.relative <= sp.fidelity_tol);
  why << "the surface leaves the body: Hausdorff distance " << fr.hausdorff << " is " << fr.relative
      << " of the diagonal, over surface.fidelity_tol " << sp.fidelity_tol << " (worst at " << at.str() << ")";
  const std::string far_why = why.str();
  // A face turned against the surface is the surface's inverted element: the layers would grow
  // from it into the body. The mesh is written for inspection; the run fails.
  if (rr.folded_faces > 0) {
    const Eigen::Vector3d& fc = rr.first_folded_centroid;
    rep.fail("the surface folds: " + std::to_string(rr.folded_faces) +
                 " triangles face more than 60 degrees away from the reference surface (first: " + rr.first_folded + ")",
             {{fc.x(), fc.y(), fc.z()}, 4 * rr.first_folded_size, "first folded triangle"});
  }
  else if (cr.invalid > 0)
    rep.fail("the surface has " + std::to_string(cr.invalid) + " invalid curved triangles");
  else if (far)
    rep.fail(far_why);
}

}  // namespace

void register_surface3d_plugins() {
  static const bool once = [] {
    StageRegistry<3>& geometry = stage_registry<3>(StageKind::Geometry);
    for (const char* name : {"sphere", "ellipsoid", "box", "wing"})
      geometry.add(name, [name](const ConfigNode& section) -> Stage<3> {
        const std::string type = name;  // the registry's name for it: `type:` is read by the run's parse
        const Geometry3Params g = parse_geometry3_params(section, type);
        return [type, g](RunState<3>& s, StageReport& rep) {
          // The exact reference now (the metric may measure distances to it); the triangulation the
          // remesher starts from is made again at the metric's size by the surface stage.
          s.reference = make_body(type, g, std::numeric_limits<double>::infinity()).reference;
          s.body_center = body_center(type, g);
          s.build_body = [type, g](RunState<3>& state, double h) {
            AnalyticBody body = make_body(type, g, h);
            state.surface = std::move(body.initial);
            state.reference = std::move(body.reference);
          };
          rep.set_section("surface");
          rep.add("geometry", type);
          rep.line("geometry: " + type + " (exact reference; triangulated at the metric's size by the surface stage)");
        };
      });
    geometry.add("surface_file", [](const ConfigNode& section) -> Stage<3> {
      const Geometry3Params g = parse_geometry3_params(section, "surface_file");
      return [g](RunState<3>& s, StageReport& rep) { surface_file(g, s, rep); };
    });
    stage_registry<3>(StageKind::Surface).add("remesh", [](const ConfigNode& section) -> Stage<3> {
      const SurfaceParams sp = parse_surface_params(section);
      return [sp](RunState<3>& s, StageReport& rep) { remesh_and_curve(sp, s, rep); };
    });
    return true;
  }();
  (void)once;
}

}  // namespace plaf
