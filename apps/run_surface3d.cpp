// SPDX-License-Identifier: MIT
// The 3D surface run (issue 6; paper Sec. II.E, the initial front of the 3D layers): numbered
// steps, each a surface3d stage call on core types, timed and reported.
#include <algorithm>
#include <chrono>
#include <limits>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "apps/run.h"
#include "apps/stage_clock.h"
#include "modules/io/atomic_file.h"
#include "modules/base/error.h"
#include "modules/io/msh_io.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/run_config.h"
#include "modules/io/vtu_writer.h"
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

std::unique_ptr<MetricField<3>> make_metric_field3(const RunConfig& c) {
  const UniformMetricParams& u = c.metric.uniform;
  if (u.sizes.empty()) return std::make_unique<UniformMetricField<3>>(Metric<3>::isotropic(u.h));
  return std::make_unique<UniformMetricField<3>>(
      Metric<3>::from_directions(Eigen::Matrix3d::Identity(), Eigen::Vector3d(u.sizes[0], u.sizes[1], u.sizes[2])));
}

// The geometry step's product: the surface to remesh and the reference it lives on.
struct SurfaceInput {
  TriSurface surface;
  std::unique_ptr<ReferenceGeometry<3>> reference;
  std::size_t input_triangles = 0;
  std::string what;                   // a progress line
  std::optional<SurfaceCheckReport> check;  // file inputs
  FeatureReport features;             // as detected (files) or built (analytic bodies)
};

SurfaceInput build_input(const RunConfig& c, const MetricField<3>& metric) {
  const Surface3Params& g = c.geometry.surface3;
  SurfaceInput in;
  // Analytic bodies start from a triangulation at 1.5 times the metric's largest size at the
  // centre: one split brings its edges to 0.75, inside the unit band (a start at exactly twice
  // the size splits the lattice's diagonals to 1/sqrt 2, on the band's edge).
  const double h0 = 1.5 * metric.evaluate(vec(g.center)).max_size();
  AnalyticBody body;
  if (c.geometry.type == "sphere") {
    body = make_sphere(vec(g.center), g.radius, std::min(h0, g.radius));
  } else if (c.geometry.type == "ellipsoid") {
    body = make_ellipsoid(vec(g.center), vec(g.semi_axes), std::min(h0, vec(g.semi_axes).minCoeff()));
  } else if (c.geometry.type == "box") {
    body = make_box(vec(g.lo), vec(g.hi), std::min(h0, (vec(g.hi) - vec(g.lo)).minCoeff() / 2));
  } else if (c.geometry.type == "wing") {
    WingParams w;
    w.file = g.file;
    w.chord = g.chord;
    w.span = g.span;
    w.root = wing_end(g.root);
    w.tip = wing_end(g.tip);
    w.corner_angle_deg = g.corner_angle_deg;
    body = make_wing(w, std::min(h0, std::min(g.chord, g.span) / 4));
  } else {
    const TriangleSoup soup = read_surface_file(g.file, ReadSurfaceOptions{g.weld_rel});
    SurfaceCheckOptions so;
    for (const SymmetryPlaneParams& p : g.symmetry_planes) so.symmetry_planes.push_back({vec(p.normal), p.offset});
    so.check_self_intersections = g.check_self_intersections;
    so.drop_inner_components = g.drop_inner_components;
    SurfaceCheckReport rep;
    in.surface = validate_surface(soup, so, &rep);
    in.input_triangles = rep.input_triangles;
    for (const std::string& r : rep.repairs) std::cerr << "[plaf] repaired: " << r << '\n';
    FeatureOptions fo;
    fo.ridge_angle_deg = c.surface.ridge_angle_deg;
    fo.corner_defect_deg = c.surface.corner_defect_deg;
    fo.curve_turn_deg = c.surface.curve_turn_deg;
    in.features = detect_features(in.surface, fo);
    in.reference = make_discrete_reference(in.surface);
    in.check = rep;
    in.what = g.file + ": " + std::to_string(rep.input_triangles) + " triangles, " + std::to_string(rep.components) +
              " components, chi = " + std::to_string(rep.euler_characteristic);
    return in;
  }
  in.surface = std::move(body.initial);
  in.reference = std::move(body.reference);
  in.input_triangles = in.surface.mesh.n_faces();
  in.features = count_features(in.surface);
  in.what = c.geometry.type + ", initial " + std::to_string(in.input_triangles) + " triangles";
  return in;
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

}  // namespace

int run_surface3d(const RunConfig& c, const std::filesystem::path& config_path) {
  std::vector<std::pair<std::string, double>> timings;
  StageClock clock(timings);
  clock.done("config", config_path.string());

  // 1. Metric field (sizes of the surface triangles).
  const std::unique_ptr<MetricField<3>> metric = make_metric_field3(c);
  clock.done("metric", c.metric.type);

  // 2. Geometry: an analytic body, or a file read, validated (repairs reported) and its features
  //    detected; the reference geometry new nodes are projected onto.
  SurfaceInput in = build_input(c, *metric);
  TriSurface& s = in.surface;
  clock.done("geometry", in.what);
  std::cout << "  features (input): " << feature_line(in.features) << '\n';

  // With curvature_factor, sizes also follow the reference's curvature (curvature_metric.h).
  std::unique_ptr<MetricField<3>> curved_metric;
  if (c.surface.curvature_factor > 0) {
    if (s.mesh.n_vertices() == 0) throw MesherError("surface: no vertices to mesh");
    const double base_min = metric->evaluate(s.mesh.point(*s.mesh.vertices().begin())).min_size();
    const double h_min = c.surface.curvature_h_min > 0 ? c.surface.curvature_h_min : base_min / 20;
    curved_metric = std::make_unique<CurvatureMetricField>(*metric, *in.reference, c.surface.curvature_factor, h_min);
  }
  const MetricField<3>& field = curved_metric ? *curved_metric : *metric;

  // 3. Metric-conforming remeshing, features kept.
  RemeshReport rr;
  if (c.surface.remesh) {
    RemeshOptions ro;
    ro.iterations = c.surface.iterations;
    ro.max_triangles = static_cast<std::size_t>(c.surface.max_triangles);
    rr = remesh_surface(s, *in.reference, field, ro);
    clock.done("remesh", std::to_string(rr.faces_before) + " -> " + std::to_string(rr.faces_after) +
                             " triangles, unit fraction " + std::to_string(rr.unit_fraction) + ", " +
                             std::to_string(rr.folded_faces) + " folded" +
                             (rr.folded_faces ? " (first at " + rr.first_folded + ")" : ""));
  }
  const FeatureReport kept = count_features(s);
  // The features as the detector sees them on the final mesh: the check that remeshing kept them
  // (and, for analytic bodies, that the body's own features are what a file would give).
  TriSurface probe = s;
  FeatureOptions fo;
  fo.ridge_angle_deg = c.surface.ridge_angle_deg;
  fo.corner_defect_deg = c.surface.corner_defect_deg;
  fo.curve_turn_deg = c.surface.curve_turn_deg;
  const FeatureReport detected = detect_features(probe, fo);
  std::cout << "  features (final): " << feature_line(kept) << "\n  features (detected on the final mesh): "
            << feature_line(detected) << '\n';

  // 4. High-order nodes on the reference, every triangle certified.
  ValidityOptions vo;
  vo.rel_tol = c.validity.rel_tol;
  vo.max_depth = c.validity.max_depth;
  const CurvingReport cr = curve_surface(s, *in.reference, c.order, vo);
  const HybridMesh<3> mesh = surface_to_mesh(s);
  clock.done("high_order", std::to_string(cr.triangles) + " triangles of order " + std::to_string(c.order) + ", " +
                               std::to_string(cr.straightened) + " straightened, " + std::to_string(cr.invalid) +
                               " invalid");

  // 5. Quality: certified validity of the surface triangles, metric edge lengths, conformity.
  QualityOptions qo;
  qo.validity = vo;
  qo.histogram_bins = c.output.histogram_bins;
  CellQuality per_cell;
  QualityReport report = assess_quality<3>(mesh, &field, qo, &per_cell);
  report.name = c.name;
  const double area = surface_area(s);
  report.extra.push_back({"surface.order", std::to_string(c.order)});
  report.extra.push_back({"surface.geometry", json_string(c.geometry.type)});
  report.extra.push_back({"surface.input_triangles", std::to_string(in.input_triangles)});
  report.extra.push_back({"surface.triangles", std::to_string(s.mesh.n_faces())});
  report.extra.push_back({"surface.vertices", std::to_string(s.mesh.n_vertices())});
  report.extra.push_back({"surface.euler_characteristic", std::to_string(s.euler_characteristic())});
  report.extra.push_back({"surface.area", json_number(area)});
  report.extra.push_back({"surface.features.input", feature_json(in.features)});
  report.extra.push_back({"surface.features.final", feature_json(kept)});
  report.extra.push_back({"surface.features.detected", feature_json(detected)});
  report.extra.push_back({"surface.remesh.rounds", std::to_string(rr.rounds)});
  report.extra.push_back({"surface.remesh.splits", std::to_string(rr.splits)});
  report.extra.push_back({"surface.remesh.collapses", std::to_string(rr.collapses)});
  report.extra.push_back({"surface.remesh.flips", std::to_string(rr.flips)});
  report.extra.push_back({"surface.remesh.unit_fraction", json_number(rr.unit_fraction)});
  report.extra.push_back({"surface.remesh.folded_faces", std::to_string(rr.folded_faces)});
  report.extra.push_back({"surface.remesh.refused_splits", std::to_string(rr.refused_splits)});
  report.extra.push_back({"surface.remesh.slivers_removed", std::to_string(rr.slivers_removed)});
  report.extra.push_back({"surface.curving.straightened", std::to_string(cr.straightened)});
  report.extra.push_back({"surface.curving.invalid", std::to_string(cr.invalid)});
  report.extra.push_back({"surface.curving.min_scaled_jacobian", json_number(cr.min_scaled_jacobian)});
  if (in.check) {
    const SurfaceCheckReport& k = *in.check;
    std::string repairs = "[";
    for (std::size_t i = 0; i < k.repairs.size(); ++i) repairs += (i ? ", " : "") + json_string(k.repairs[i]);
    repairs += "]";
    report.extra.push_back({"surface.input.components", std::to_string(k.components)});
    report.extra.push_back({"surface.input.euler_characteristic", std::to_string(k.euler_characteristic)});
    report.extra.push_back({"surface.input.volume", json_number(k.volume)});
    report.extra.push_back({"surface.input.boundary_loops", std::to_string(k.boundary_loops)});
    report.extra.push_back({"surface.input.symmetry_edges", std::to_string(k.symmetry_edges)});
    report.extra.push_back({"surface.input.repairs", repairs});
  }
  std::cout << "  surface: " << s.mesh.n_faces() << " triangles, " << s.mesh.n_vertices() << " vertices, chi "
            << s.euler_characteristic() << ", area " << area << '\n';
  clock.done("quality", std::to_string(report.cells_invalid) + " invalid triangles");

  // 6. Outputs, each written atomically; the report last, with every stage's time.
  std::filesystem::create_directories(c.output.dir);
  const std::filesystem::path base = c.output.dir / c.name;
  if (c.output.wants("msh")) write_msh41(mesh, base.string() + ".msh");
  if (c.output.wants("vtu")) {
    // Per triangle: validity, certified scaled Jacobian and aspect ratio, as in 2D (clamped to
    // finite values: VTK 9.1 reads "-inf" as +inf).
    auto finite = [](std::vector<double> v) {
      for (double& x : v) x = std::clamp(x, std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max());
      return v;
    };
    const std::vector<CellField> fields = {
        {"valid", std::vector<double>(per_cell.valid.begin(), per_cell.valid.end())},
        {"scaled_jacobian", finite(per_cell.scaled_jacobian)},
        {"aspect_ratio", finite(per_cell.aspect_ratio)}};
    write_vtu(mesh, base.string() + ".vtu", fields);
  }
  clock.done("write", base.string() + ".*");
  report.timings_s = timings;
  if (c.output.wants("report")) {
    AtomicFile f(base.string() + ".report.json");
    f.write(report_json(report));
    f.commit();
  }
  std::cout << report_summary(report);
  if (rr.folded_faces > 0) {
    // A face turned against the surface is the surface's inverted element: the layers would grow
    // from it into the body. The mesh is written for inspection; the run fails.
    std::cerr << "plaf: error: the surface of " << config_path.string() << " folds: " << rr.folded_faces
              << " triangles face more than 60 degrees away from the reference surface (first: " << rr.first_folded
              << ")\n";
    return 2;
  }
  if (!report.ok() || cr.invalid > 0) {
    std::cerr << "plaf: error: the surface of " << config_path.string() << " is NOT valid: " << report.cells_invalid
              << " invalid triangles" << (report.first_invalid.empty() ? "" : " (first: " + report.first_invalid + ")")
              << (report.conformity.ok ? "" : ", " + report.conformity.first_problem) << '\n';
    return 2;
  }
  return 0;
}

}  // namespace plaf
