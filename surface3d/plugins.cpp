// SPDX-License-Identifier: MIT
// The 3D surface stages (plugins.h): geometry, then the surface mesh, each reporting what it did.
#include "surface3d/plugins.h"

#include <algorithm>
#include <iostream>
#include <sstream>

#include "modules/base/error.h"
#include "modules/metric/metric_fields.h"
#include "modules/pipeline/run_state.h"
#include "modules/pipeline/stages.h"
#include "surface3d/analytic.h"
#include "surface3d/curvature_metric.h"
#include "surface3d/features.h"
#include "surface3d/high_order.h"
#include "surface3d/read_surface.h"
#include "surface3d/remesh.h"
#include "surface3d/validate.h"

namespace plaf {

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

// An analytic body, triangulated at 1.5 times the metric's largest size at its centre: one split
// brings its edges to 0.75, inside the unit band (a start at exactly twice the size splits the
// lattice's diagonals to 1/sqrt 2, on the band's edge).
void analytic_body(RunState<3>& s, StageReport& rep) {
  const RunConfig& c = s.config;
  const Surface3Params& g = c.geometry.surface3;
  const double h0 = 1.5 * uniform_metric_3d(c.metric.uniform).max_size();
  AnalyticBody body;
  if (c.geometry.type == "sphere") {
    body = make_sphere(vec(g.center), g.radius, std::min(h0, g.radius));
  } else if (c.geometry.type == "ellipsoid") {
    body = make_ellipsoid(vec(g.center), vec(g.semi_axes), std::min(h0, vec(g.semi_axes).minCoeff()));
  } else if (c.geometry.type == "box") {
    body = make_box(vec(g.lo), vec(g.hi), std::min(h0, (vec(g.hi) - vec(g.lo)).minCoeff() / 2));
  } else {
    WingParams w;
    w.file = g.file;
    w.chord = g.chord;
    w.span = g.span;
    w.root = wing_end(g.root);
    w.tip = wing_end(g.tip);
    w.corner_angle_deg = g.corner_angle_deg;
    body = make_wing(w, std::min(h0, std::min(g.chord, g.span) / 4));
  }
  s.surface = std::move(body.initial);
  s.reference = std::move(body.reference);
  const FeatureReport features = count_features(s.surface);
  rep.set_section("surface");
  rep.add("geometry", c.geometry.type);
  rep.add("input_triangles", s.surface.mesh.n_faces());
  rep.add_json("features.input", feature_json(features));
  rep.line("geometry: " + c.geometry.type + ", initial " + std::to_string(s.surface.mesh.n_faces()) + " triangles");
  rep.line("features (input): " + feature_line(features));
}

// A surface file: read, validated (repairs reported), its features detected; it is its own reference.
void surface_file(RunState<3>& s, StageReport& rep) {
  const Surface3Params& g = s.config.geometry.surface3;
  const TriangleSoup soup = read_surface_file(g.file, ReadSurfaceOptions{g.weld_rel});
  SurfaceCheckOptions so;
  for (const SymmetryPlaneParams& p : g.symmetry_planes) so.symmetry_planes.push_back({vec(p.normal), p.offset});
  so.check_self_intersections = g.check_self_intersections;
  so.drop_inner_components = g.drop_inner_components;
  SurfaceCheckReport k;
  s.surface = validate_surface(soup, so, &k);
  for (const std::string& r : k.repairs) std::cerr << "[plaf] repaired: " << r << '\n';
  const FeatureReport features = detect_features(s.surface, feature_options(s.config.surface));
  s.reference = make_discrete_reference(s.surface);
  std::vector<std::string> repairs;
  for (const std::string& r : k.repairs) repairs.push_back(json_string(r));
  rep.set_section("surface");
  rep.add("geometry", s.config.geometry.type);
  rep.add("input_triangles", k.input_triangles);
  rep.add_json("features.input", feature_json(features));
  rep.add("input.components", k.components);
  rep.add("input.euler_characteristic", k.euler_characteristic);
  rep.add("input.volume", k.volume);
  rep.add("input.boundary_loops", k.boundary_loops);
  rep.add("input.symmetry_edges", k.symmetry_edges);
  rep.add_json("input.repairs", json_array(repairs));
  rep.line("geometry: " + g.file + ": " + std::to_string(k.input_triangles) + " triangles, " +
           std::to_string(k.components) + " components, chi = " + std::to_string(k.euler_characteristic));
  rep.line("features (input): " + feature_line(features));
}

// The surface mesh: curvature-driven sizes (optional), remeshing with features kept, the features
// detected again on the final mesh as a check, order-Q nodes on the reference, every triangle
// certified.
void remesh_and_curve(RunState<3>& s, StageReport& rep) {
  const RunConfig& c = s.config;
  TriSurface& surface = s.surface;
  if (c.surface.curvature_factor > 0) {
    if (surface.mesh.n_vertices() == 0) throw MesherError("surface: no vertices to mesh");
    const double base_min = s.metric->evaluate(surface.mesh.point(*surface.mesh.vertices().begin())).min_size();
    const double h_min = c.surface.curvature_h_min > 0 ? c.surface.curvature_h_min : base_min / 20;
    s.surface_metric =
        std::make_unique<CurvatureMetricField>(*s.metric, *s.reference, c.surface.curvature_factor, h_min);
  }
  const MetricField<3>& field = *s.measure();
  RemeshReport rr;
  if (c.surface.remesh) {
    RemeshOptions ro;
    ro.iterations = c.surface.iterations;
    ro.max_triangles = static_cast<std::size_t>(c.surface.max_triangles);
    rr = remesh_surface(surface, *s.reference, field, ro);
    rep.line("remesh: " + std::to_string(rr.faces_before) + " -> " + std::to_string(rr.faces_after) +
             " triangles, unit fraction " + std::to_string(rr.unit_fraction) + ", " +
             std::to_string(rr.folded_faces) + " folded" +
             (rr.folded_faces ? " (first at " + rr.first_folded + ")" : ""));
  }
  const FeatureReport kept = count_features(surface);
  TriSurface probe = surface;
  const FeatureReport detected = detect_features(probe, feature_options(c.surface));
  rep.line("features (final): " + feature_line(kept));
  rep.line("features (detected on the final mesh): " + feature_line(detected));

  ValidityOptions vo;
  vo.rel_tol = c.validity.rel_tol;
  vo.max_depth = c.validity.max_depth;
  const CurvingReport cr = curve_surface(surface, *s.reference, c.order, vo);
  s.mesh = surface_to_mesh(surface);
  s.mesh_done = true;
  rep.line("high order: " + std::to_string(cr.triangles) + " triangles of order " + std::to_string(c.order) + ", " +
           std::to_string(cr.straightened) + " straightened, " + std::to_string(cr.invalid) + " invalid");
  const double area = surface_area(surface);
  rep.add("order", c.order);
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
  rep.add("remesh.folded_faces", rr.folded_faces);
  rep.add("remesh.refused_splits", rr.refused_splits);
  rep.add("remesh.slivers_removed", rr.slivers_removed);
  rep.add("curving.straightened", cr.straightened);
  rep.add("curving.invalid", cr.invalid);
  rep.add("curving.min_scaled_jacobian", cr.min_scaled_jacobian);
  rep.line("surface: " + std::to_string(surface.mesh.n_faces()) + " triangles, " +
           std::to_string(surface.mesh.n_vertices()) + " vertices, chi " +
           std::to_string(surface.euler_characteristic()) + ", area " + std::to_string(area));
  // A face turned against the surface is the surface's inverted element: the layers would grow
  // from it into the body. The mesh is written for inspection; the run fails.
  if (rr.folded_faces > 0)
    rep.fail("the surface folds: " + std::to_string(rr.folded_faces) +
             " triangles face more than 60 degrees away from the reference surface (first: " + rr.first_folded + ")");
  else if (cr.invalid > 0)
    rep.fail("the surface has " + std::to_string(cr.invalid) + " invalid curved triangles");
}

}  // namespace

void register_surface3d_plugins() {
  static const bool once = [] {
    StageRegistry<3>& geometry = stage_registry<3>(StageKind::Geometry);
    for (const char* body : {"sphere", "ellipsoid", "box", "wing"})
      geometry.add(body, [](const ConfigNode&, const RunConfig&) -> Stage<3> { return analytic_body; });
    geometry.add("surface_file", [](const ConfigNode&, const RunConfig&) -> Stage<3> { return surface_file; });
    stage_registry<3>(StageKind::Surface)
        .add("remesh", [](const ConfigNode&, const RunConfig&) -> Stage<3> { return remesh_and_curve; });
    return true;
  }();
  (void)once;
}

}  // namespace plaf
