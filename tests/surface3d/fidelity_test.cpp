// SPDX-License-Identifier: MIT
// The surface's distance to its body (surface3d/fidelity.h): the chord sag of a sphere's
// triangulation measured as the analytic value, a notch (a vertex pushed into the body) caught
// at its place on both sides, the E387 half wing remeshed with the curvature metric keeping its
// root and tip noses (the remesher's curve guards, remesh.cpp), and a rounded edge narrower than
// the mesh (as the M6's trailing edge) cut back unless kept as a crest (features.h).
#include "surface3d/fidelity.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "modules/metric/metric.h"
#include "surface3d/analytic.h"
#include "surface3d/curvature_metric.h"
#include "surface3d/discrete_reference.h"
#include "surface3d/features.h"
#include "surface3d/high_order.h"
#include "surface3d/remesh.h"
#include "tests/surface3d/test_surfaces.h"
#include "tests/published_data.h"

using namespace plaf;

TEST_CASE("fidelity: a sphere's flat triangles sit their chord sag inside it, a pushed-in vertex is found") {
  AnalyticBody body = make_sphere(Eigen::Vector3d(0.3, -0.2, 0.1), 2.0, 0.4);
  TriSurface& s = body.initial;
  const std::vector<Eigen::Vector3d> samples = reference_samples(s, *body.reference, false);
  REQUIRE(!samples.empty());
  for (const Eigen::Vector3d& p : samples) CHECK(((p - Eigen::Vector3d(0.3, -0.2, 0.1)).norm() - 2.0) == doctest::Approx(0).scale(1));
  const FidelityReport clean = measure_fidelity(s, *body.reference, samples);
  // Flat triangles inside a sphere of radius R: the farthest point of a triangle is its
  // circumcentre, R - sqrt(R^2 - r_c^2) deep, r_c its circumradius.
  double sag = 0;
  for (const auto f : s.mesh.faces()) {
    const auto fv = s.face_vertices(f);
    const Eigen::Vector3d a = s.mesh.point(fv[0]), b = s.mesh.point(fv[1]), c = s.mesh.point(fv[2]);
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
    const double rc = la * lb * lc / (2 * (b - a).cross(c - a).norm());
    sag = std::max(sag, 2.0 - std::sqrt(4.0 - rc * rc));
  }
  MESSAGE("sphere R = 2, h = 0.4: Hausdorff " << clean.hausdorff << ", largest circumcentre depth " << sag);
  CHECK(clean.to_reference <= sag * (1 + 1e-9));
  CHECK(clean.to_reference >= 0.5 * sag);  // the 2-sub-lattice of a flat triangle comes near its centre
  CHECK(clean.to_mesh <= sag * (1 + 1e-9));
  CHECK(clean.diagonal == doctest::Approx(4 * std::sqrt(3.0)).epsilon(0.05));
  // A notch: one vertex pushed 0.3 toward the centre.
  const auto v = *s.mesh.vertices().begin();
  const Eigen::Vector3d x = s.mesh.point(v), c(0.3, -0.2, 0.1);
  s.mesh.set_point(v, x - 0.3 * (x - c).normalized());
  const FidelityReport notched = measure_fidelity(s, *body.reference, samples);
  CHECK(notched.to_reference == doctest::Approx(0.3).epsilon(1e-9));  // the vertex itself is a sample
  CHECK((notched.worst_on_mesh - s.mesh.point(v)).norm() < 1e-12);
  CHECK(notched.to_mesh > 0.2);  // the body above the notch (0.3 less its sloped neighbours' lean)
  CHECK((notched.worst_on_reference - x).norm() < 0.2);
  CHECK(notched.relative > 10 * clean.relative);
}

TEST_CASE("fidelity: the samples over a distance are listed, and the refined field shrinks sizes around them") {
  AnalyticBody body = make_sphere(Eigen::Vector3d::Zero(), 2.0, 0.4);
  TriSurface& s = body.initial;
  const std::vector<Eigen::Vector3d> samples = reference_samples(s, *body.reference, false);
  const auto v = *s.mesh.vertices().begin();
  const Eigen::Vector3d x = s.mesh.point(v);
  s.mesh.set_point(v, 0.85 * x);  // a notch 0.3 deep
  const FidelityReport r = measure_fidelity(s, *body.reference, samples, 0.1);
  REQUIRE_FALSE(r.far.empty());
  for (const auto& [p, d] : r.far) {
    CHECK(d > 0.1);
    CHECK((p - x).norm() < 1.0);  // all of them at the notch
  }
  CHECK(std::any_of(r.far.begin(), r.far.end(), [](const auto& f) { return f.second == doctest::Approx(0.3); }));
  CHECK(measure_fidelity(s, *body.reference, samples).far.empty());  // none asked for

  // Two spots: factor 0.5 within a third of radius 0.3 of (0, 0, 2), 0.25 at (2, 0, 0): sizes
  // times the factor, directions kept; ramped back to 1 at the radius; 1 far away.
  const Metric<3> m = Metric<3>::from_directions(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1, 0.2, 0.4));
  const UniformMetricField<3> inner(m);
  const FidelityRefinedField f(inner, {{Eigen::Vector3d(0, 0, 2), 0.5, 0.3}, {Eigen::Vector3d(2, 0, 0), 0.25, 0.3}});
  CHECK(f.num_spots() == 2);
  CHECK(f.factor(Eigen::Vector3d(0, 0, 2.05)) == doctest::Approx(0.5));
  CHECK(f.factor(Eigen::Vector3d(0, 0, 2.2)) == doctest::Approx(0.75));  // halfway along the ramp
  CHECK(f.factor(Eigen::Vector3d(0, 0, 2.31)) == 1.0);
  CHECK(f.factor(Eigen::Vector3d(2, 0.05, 0)) == doctest::Approx(0.25));
  CHECK(f.factor(Eigen::Vector3d(-5, 3, 1)) == 1.0);
  const Metric<3> at = f.evaluate(Eigen::Vector3d(2, 0, 0));
  CHECK(at.size_along(Eigen::Vector3d::UnitX()) == doctest::Approx(0.025));
  CHECK(at.size_along(Eigen::Vector3d::UnitZ()) == doctest::Approx(0.1));
  CHECK(f.evaluate(Eigen::Vector3d(9, 9, 9)).matrix() == m.matrix());
}

TEST_CASE("fidelity: the E387 half wing remeshed with the curvature metric keeps its noses") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  WingParams w;
  w.file = plaf::test::published("airfoils/e387.dat");
  w.span = 1.5;
  w.root = WingEnd::Symmetry;
  w.tip = WingEnd::Symmetry;
  w.corner_angle_deg = 70;
  AnalyticBody body = make_wing(w, 0.12);
  const std::vector<Eigen::Vector3d> samples = reference_samples(body.initial, *body.reference, false);
  const UniformMetricField<3> base(Metric<3>::isotropic(0.08));
  const CurvatureMetricField field(base, *body.reference, 0.3, 0.004);
  const RemeshReport r = remesh_surface(body.initial, *body.reference, field, RemeshOptions{});
  CHECK(r.folded_faces == 0);
  const CurvingReport cr = curve_surface(body.initial, *body.reference, 3, ValidityOptions{});
  CHECK(cr.invalid == 0);
  const FidelityReport f = measure_fidelity(body.initial, *body.reference, samples);
  MESSAGE("E387 wing, order 3, h 0.08, curvature 0.3 R >= 0.004: Hausdorff " << f.hausdorff << " (" << f.relative
                                                                     << " of the diagonal) at " << f.worst.transpose());
  // Before the guards measured the curve's sag against the smallest size, the root nose was cut
  // back 0.013 (7e-3 of the diagonal).
  CHECK(f.relative < 1e-3);
}

TEST_CASE("fidelity: a body with no mesh is infinitely far, never within a tolerance") {
  AnalyticBody body = make_sphere(Eigen::Vector3d::Zero(), 1.0, 0.5);
  const std::vector<Eigen::Vector3d> samples = reference_samples(body.initial, *body.reference, false);
  const FidelityReport f = measure_fidelity(TriSurface{}, *body.reference, samples);
  CHECK(std::isinf(f.to_mesh));
  CHECK(std::isinf(f.hausdorff));
  CHECK_FALSE(f.relative <= 1.0);
  CHECK(f.diagonal == doctest::Approx(2 * std::sqrt(3.0)).epsilon(0.05));
}

TEST_CASE("fidelity: a rounded edge narrower than the mesh is cut back unless kept as a crest, and the check says so") {
  // A slab 1 x 0.5 with both long edges rounded (radius 0.002, 8 segments: no ridge at 30
  // degrees), remeshed at 0.04: twenty times the edge's width, as the M6's trailing edge.
  const TriangleSoup soup = test::rounded_slab_soup(0.002, 0.5, 10, 6);
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.04));
  auto run = [&](double crest_scale) {
    TriSurface s = surface_from_soup(soup);
    FeatureOptions o;
    o.crest_scale = crest_scale;
    detect_features(s, o);
    const auto reference = make_discrete_reference(s);
    const std::vector<Eigen::Vector3d> body = reference_samples(s, *reference, true);
    const RemeshReport r = remesh_surface(s, *reference, metric, RemeshOptions{});
    CHECK(r.folded_faces == 0);
    return measure_fidelity(s, *reference, body);
  };
  const FidelityReport kept = run(0.02), cut = run(0);
  MESSAGE("rounded edges kept as crests: " << kept.relative << " of the diagonal; as smooth surface: " << cut.relative
                                            << " at " << cut.worst.transpose());
  // Kept: the mesh follows the edge to within its radius t = 0.002 (a sharp crest between two
  // flat bands stands in for the semicircle); cut: over ten times that, far past the default
  // tolerance (1e-3 of the diagonal) ...
  CHECK(kept.hausdorff <= 0.002);
  CHECK(cut.hausdorff > 10 * kept.hausdorff);
  CHECK(cut.relative > 1e-3);
  // ... on a rounded edge (x = 0 or 1), the body farther from the mesh than the mesh from it.
  CHECK(std::min(std::abs(cut.worst.x()), std::abs(cut.worst.x() - 1)) < 0.01);
  CHECK(cut.to_mesh > cut.to_reference);
}
