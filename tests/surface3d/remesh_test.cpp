// SPDX-License-Identifier: MIT
#include "surface3d/remesh.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "modules/base/error.h"
#include "modules/metric/metric.h"
#include "modules/geometry/tri_surface.h"
#include "surface3d/analytic.h"
#include "surface3d/curvature_metric.h"
#include "surface3d/features.h"
#include "surface3d/validate.h"
#include "tests/surface3d/feature_checks.h"
#include "tests/surface3d/test_surfaces.h"

namespace plaf {
namespace {

// The unit sphere, projecting radially (test-local: the remesher sees only the interface).
class UnitSphere final : public ReferenceGeometry<3> {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return p.normalized(); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return x.normalized(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return p.normalized(); }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * std::sqrt(3.0); }
};

TriSurface icosahedron() { return surface_from_soup(test::icosahedron_soup()); }

double unit_fraction(const TriSurface& s, const MetricField<3>& metric) {
  std::size_t unit = 0, n = 0;
  for (const auto e : s.mesh.edges()) {
    const auto h = s.mesh.halfedge_handle(e, 0);
    const double l = metric_length(metric, s.mesh.point(s.mesh.from_vertex_handle(h)),
                                   s.mesh.point(s.mesh.to_vertex_handle(h)));
    ++n;
    if (l >= 1 / std::sqrt(2.0) && l <= std::sqrt(2.0)) ++unit;
  }
  return static_cast<double>(unit) / static_cast<double>(n);
}

bool all_outward(const TriSurface& s) {
  for (const auto f : s.mesh.faces()) {
    const auto v = s.face_vertices(f);
    const Eigen::Vector3d a = s.mesh.point(v[0]), b = s.mesh.point(v[1]), c = s.mesh.point(v[2]);
    if ((b - a).cross(c - a).dot(a + b + c) <= 0) return false;
  }
  return true;
}

TEST_CASE("remesh: a sphere to a uniform metric, at least 90 percent unit edges, genus kept") {
  for (const double h : {0.3, 0.1, 0.05}) {
    CAPTURE(h);
    TriSurface s = icosahedron();
    CHECK(s.euler_characteristic() == 2);
    const UniformMetricField<3> metric(Metric<3>::isotropic(h));
    const RemeshReport r = remesh_surface(s, UnitSphere(), metric, RemeshOptions{});
    CHECK(s.euler_characteristic() == 2);
    CHECK(r.unit_fraction >= 0.9);
    CHECK(unit_fraction(s, metric) == doctest::Approx(r.unit_fraction));
    CHECK(r.caps == 0);  // no triangle with an angle over 160 degrees is left on a sphere
    // Faces: the sphere's area over an equilateral unit triangle's, within a factor.
    const double expected = 4 * M_PI / (std::sqrt(3.0) / 4 * h * h);
    CHECK(static_cast<double>(s.mesh.n_faces()) > 0.6 * expected);
    CHECK(static_cast<double>(s.mesh.n_faces()) < 1.6 * expected);
    for (const auto v : s.mesh.vertices()) CHECK(std::abs(s.mesh.point(v).norm() - 1) < 1e-12);
    CHECK(all_outward(s));
    MESSAGE("h = " << h << ": " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction << ", "
                   << r.splits << " splits, " << r.collapses << " collapses, " << r.flips << " flips, " << r.seconds
                   << " s");
  }
}

// The unit sphere whose normal points inward on the cap z > 0.8: every face there is turned
// against it, a fold no operation can mend (what the report must then locate).
class InwardCapSphere final : public ReferenceGeometry<3> {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return p.normalized(); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override {
    return x.normalized().z() > 0.8 ? Eigen::Vector3d(-x.normalized()) : Eigen::Vector3d(x.normalized());
  }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return p.normalized(); }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * std::sqrt(3.0); }
};

TEST_CASE("remesh: folds it cannot mend are counted and the first located (its centroid and size)") {
  TriSurface s = icosahedron();
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.3));
  const RemeshReport r = remesh_surface(s, InwardCapSphere(), metric, RemeshOptions{});
  REQUIRE(r.folded_faces > 0);
  CHECK_FALSE(r.first_folded.empty());
  // On the cap (its centroid's projection there), a face of the mesh: its centroid inside the
  // sphere by at most an icosahedron face's (splits and flips there are refused, each would leave
  // a face turned against the reference), its longest edge at most the icosahedron's (1.05).
  CHECK(r.first_folded_centroid.normalized().z() > 0.8);
  CHECK(r.first_folded_centroid.norm() > 0.79);
  CHECK(r.first_folded_centroid.norm() < 1);
  CHECK(r.first_folded_size > 0.1);
  CHECK(r.first_folded_size < 1.06);
  bool found = false;
  for (const auto f : s.mesh.faces()) {
    std::vector<Eigen::Vector3d> x;
    for (const auto v : s.mesh.fv_range(f)) x.push_back(s.mesh.point(v));
    const double longest = std::max({(x[1] - x[0]).norm(), (x[2] - x[1]).norm(), (x[0] - x[2]).norm()});
    found = found || (((x[0] + x[1] + x[2]) / 3 - r.first_folded_centroid).norm() < 1e-12 &&
                      std::abs(longest - r.first_folded_size) < 1e-12);
  }
  CHECK(found);
  std::size_t on_cap = 0;
  for (const auto f : s.mesh.faces()) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto v : s.mesh.fv_range(f)) c += s.mesh.point(v) / 3;
    if (c.normalized().z() > 0.8) ++on_cap;
  }
  CHECK(r.folded_faces == on_cap);
}

TEST_CASE("remesh: an anisotropic metric stretches the triangles") {
  // Sizes 0.05 along z and 0.2 across: the triangles of the sphere's equator band are then about
  // 4 times longer than high; the edges still reach unit metric length.
  TriSurface s = icosahedron();
  Eigen::Matrix3d dirs = Eigen::Matrix3d::Identity();
  const UniformMetricField<3> metric(Metric<3>::from_directions(dirs, Eigen::Vector3d(0.2, 0.2, 0.05)));
  const RemeshReport r = remesh_surface(s, UnitSphere(), metric, RemeshOptions{});
  CHECK(s.euler_characteristic() == 2);
  CHECK(all_outward(s));
  CHECK(r.unit_fraction >= 0.85);
  // Near the equator, edges run 4 times longer around (x, y) than along z on average.
  double around = 0, along = 0;
  for (const auto e : s.mesh.edges()) {
    const auto h = s.mesh.halfedge_handle(e, 0);
    const Eigen::Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(h)), b = s.mesh.point(s.mesh.to_vertex_handle(h));
    if (std::abs(a.z()) > 0.2) continue;
    around += (b - a).head<2>().norm();
    along += std::abs(b.z() - a.z());
  }
  CHECK(around > 2.5 * along);
  MESSAGE("anisotropic: " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction << ", around/along "
                          << around / along);
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

TEST_CASE("remesh: a box keeps its 12 ridges and 8 corners, ridge vertices stay on the edges") {
  AnalyticBody box = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 1, 0.5), 0.5);
  TriSurface& s = box.initial;
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.1));
  const RemeshReport r = remesh_surface(s, *box.reference, metric, RemeshOptions{});
  CHECK(r.unit_fraction >= 0.9);
  CHECK(s.euler_characteristic() == 2);
  test::check_box_features(s);
  // The detector finds the same on the remeshed surface.
  TriSurface probe = s;
  const FeatureReport found = detect_features(probe, FeatureOptions{});
  test::check_box_features(probe);
  CHECK(found.ridges_convex == count_features(s).ridges_convex);
  // Every vertex on the box, every curve vertex on two faces of it (an edge of the box).
  for (const auto v : s.mesh.vertices()) {
    const Eigen::Vector3d p = s.mesh.point(v);
    int on_faces = 0;
    for (int k = 0; k < 3; ++k) {
      const double hi = k == 0 ? 2 : k == 1 ? 1 : 0.5;
      if (std::abs(p[k]) < 1e-12 || std::abs(p[k] - hi) < 1e-12) ++on_faces;
    }
    CHECK(on_faces >= 1);
    if (s.mesh.property(s.vertex_feature, v) == VertexFeature::Curve) CHECK(on_faces == 2);
    if (is_corner(s.mesh.property(s.vertex_feature, v))) CHECK(on_faces == 3);
  }
  MESSAGE("box: " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction);
}

TEST_CASE("remesh: an elongated ellipsoid with the curvature metric refines its tips") {
  AnalyticBody e = make_ellipsoid(Eigen::Vector3d::Zero(), Eigen::Vector3d(3, 1, 1), 0.5);
  const UniformMetricField<3> base(Metric<3>::isotropic(0.25));
  const CurvatureMetricField field(base, *e.reference, 0.3, 0.01);
  TriSurface& s = e.initial;
  const RemeshReport r = remesh_surface(s, *e.reference, field, RemeshOptions{});
  CHECK(r.unit_fraction >= 0.85);
  CHECK(s.euler_characteristic() == 2);
  // The tips (radius of curvature b^2 / a = 1/3) ask for 0.1; the waist (radius 1) for 0.25.
  double tip_edges = 0, waist_edges = 0;
  int tips = 0, waists = 0;
  for (const auto ed : s.mesh.edges()) {
    const auto h = s.mesh.halfedge_handle(ed, 0);
    const Eigen::Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(h)), b = s.mesh.point(s.mesh.to_vertex_handle(h));
    if (std::abs(a.x()) > 2.9) {
      tip_edges += (b - a).norm();
      ++tips;
    } else if (std::abs(a.x()) < 0.3) {
      waist_edges += (b - a).norm();
      ++waists;
    }
  }
  REQUIRE(tips > 0);
  REQUIRE(waists > 0);
  CHECK(tip_edges / tips < 0.7 * (waist_edges / waists));
  MESSAGE("ellipsoid: " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction << ", mean edge at tips "
                        << tip_edges / tips << ", at the waist " << waist_edges / waists);
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

TEST_CASE("remesh: a discrete torus keeps its genus (chi = 0) and reaches the metric") {
  // A torus (R = 1, r = 0.3) as a 60 x 20 quad grid split into triangles, outward; the remesher
  // projects onto this faceted input (the discrete reference).
  const int nu = 60, nv = 20;
  TriangleSoup soup;
  soup.source = "torus";
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      soup.points.push_back({(1 + 0.3 * std::cos(v)) * std::cos(u), (1 + 0.3 * std::cos(v)) * std::sin(u), 0.3 * std::sin(v)});
    }
  auto id = [&](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      soup.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      soup.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  SurfaceCheckReport check;
  TriSurface s = validate_surface(soup, SurfaceCheckOptions{}, &check);
  CHECK(check.euler_characteristic == 0);
  CHECK(check.volume == doctest::Approx(2 * M_PI * M_PI * 0.09).epsilon(0.03));
  detect_features(s, FeatureOptions{});
  CHECK(count_features(s).curves == 0);
  const std::unique_ptr<ReferenceGeometry<3>> ref = make_discrete_reference(s);
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.05));
  const RemeshReport r = remesh_surface(s, *ref, metric, RemeshOptions{});
  CHECK(s.euler_characteristic() == 0);
  CHECK(r.unit_fraction >= 0.9);
  CHECK(r.folded_faces == 0);
  // Every vertex on the input surface (its closest point is itself).
  double worst = 0;
  for (const auto v : s.mesh.vertices()) worst = std::max(worst, (ref->project(s.mesh.point(v)) - s.mesh.point(v)).norm());
  CHECK(worst < 1e-12);
  MESSAGE("torus: " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction);
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

TEST_CASE("remesh: tags, features and curves stay consistent on a half wing (symmetry root, flat tip)") {
  WingParams w;
  w.naca = NacaSection{"4412", true, 100};  // cambered, sharp trailing edge
  w.span = 1.0;
  w.root = WingEnd::Symmetry;
  w.tip = WingEnd::Flat;
  w.corner_angle_deg = 70;
  AnalyticBody body = make_wing(w, 0.1);
  TriSurface& s = body.initial;
  const FeatureReport before = count_features(s);
  const UniformMetricField<3> base(Metric<3>::isotropic(0.06));
  const CurvatureMetricField field(base, *body.reference, 0.3, 0.005);
  const RemeshReport r = remesh_surface(s, *body.reference, field, RemeshOptions{});
  CHECK_MESSAGE(r.folded_faces == 0, r.first_folded);
  CHECK(r.unit_fraction >= 0.85);
  CHECK(s.euler_characteristic() == 1);  // a disc: the root is open
  const FeatureReport after = count_features(s);
  CHECK(after.curves == before.curves);
  CHECK(after.corners_convex == before.corners_convex);
  CHECK(after.corners_boundary == before.corners_boundary);
  int symmetry = -1;
  for (std::size_t t = 0; t < s.tags.size(); ++t)
    if (s.tags[t].kind == BoundaryKind::Symmetry) symmetry = static_cast<int>(t);
  REQUIRE(symmetry >= 0);
  std::size_t boundary = 0;
  for (const auto e : s.mesh.edges()) {
    const int tag = s.mesh.property(s.edge_tag, e);
    const EdgeFeature f = s.mesh.property(s.edge_feature, e);
    const int c = s.mesh.property(s.edge_curve, e);
    if (s.mesh.is_boundary(e)) {
      ++boundary;
      CHECK(tag == symmetry);
      CHECK(f == EdgeFeature::Boundary);
      CHECK(c >= 0);
    } else {
      CHECK(tag == -1);
      CHECK(f != EdgeFeature::Boundary);
    }
    CHECK((c >= 0) == (f != EdgeFeature::Smooth));
  }
  CHECK(boundary > 20);
  for (const auto v : s.mesh.vertices())
    if (s.mesh.is_boundary(v)) CHECK(std::abs(s.mesh.point(v).z()) < 1e-12);  // on the root plane
  for (const auto f : s.mesh.faces()) CHECK(s.mesh.property(s.face_tag, f) == 0);
}

TEST_CASE("remesh: scale invariance, a sphere of radius 1e-6 and 1e6") {
  for (const double scale : {1e-6, 1e6}) {
    CAPTURE(scale);
    AnalyticBody b = make_sphere(Eigen::Vector3d(scale, -scale, 2 * scale), scale, 0.3 * scale);
    const UniformMetricField<3> metric(Metric<3>::isotropic(0.1 * scale));
    const RemeshReport r = remesh_surface(b.initial, *b.reference, metric, RemeshOptions{});
    CHECK(r.unit_fraction >= 0.9);
    CHECK(r.folded_faces == 0);
    CHECK(b.initial.euler_characteristic() == 2);
  }
}

TEST_CASE("remesh: a metric asking for too many triangles is an error, not a hang") {
  AnalyticBody b = make_sphere(Eigen::Vector3d::Zero(), 1, 0.5);
  const UniformMetricField<3> metric(Metric<3>::isotropic(1e-4));
  RemeshOptions o;
  o.max_triangles = 100000;
  CHECK_THROWS_WITH_AS(remesh_surface(b.initial, *b.reference, metric, o), doctest::Contains("surface.max_triangles"),
                       MesherError);
}

}  // namespace
}  // namespace plaf

#include "surface3d/discrete_reference.h"

namespace plaf {
namespace {

TEST_CASE("remesh: faces still crossing at the end are counted and every one located (the surface stage refines there)") {
  // Two unit icospheres whose centres are 1 apart, as one surface: they cross along the circle
  // x = 0, r = sqrt(3)/2, which no collapse can untangle.
  TriangleSoup soup = test::icosphere_soup(4);
  const std::size_t n = soup.points.size();
  TriangleSoup other = soup;
  for (Eigen::Vector3d& p : soup.points) p.x() -= 0.5;
  for (const Eigen::Vector3d& p : other.points) soup.points.push_back(p + Eigen::Vector3d(0.5, 0, 0));
  for (const auto& t : other.triangles)
    soup.triangles.push_back({t[0] + static_cast<int>(n), t[1] + static_cast<int>(n), t[2] + static_cast<int>(n)});
  TriSurface s = surface_from_soup(soup);
  const std::unique_ptr<ReferenceGeometry<3>> ref = make_discrete_reference(s);
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.3));
  RemeshOptions o;
  o.iterations = 2;
  const RemeshReport r = remesh_surface(s, *ref, metric, o);
  REQUIRE(r.crossing_pairs > 0);
  CHECK(r.crossing_points.size() == 2 * r.crossing_pairs);
  CHECK_FALSE(r.first_crossing.empty());
  for (const Eigen::Vector3d& x : r.crossing_points) {
    // On a face that crosses the other sphere: within a face's size of the circle (the untangling
    // collapses leave faces there up to twice the size: measured 0.51 at most).
    const double off_circle = std::hypot(x.x(), std::hypot(x.y(), x.z()) - std::sqrt(3.0) / 2);
    CHECK(off_circle < 0.6);
  }
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

TEST_CASE("remesh: a CAD fan of needles is cut across, its 5-long rays split to the size") {
  // A planar triangle (0,0) - (5,-1) - (5,1) whose middle is a fan from (0,0) to five points
  // 0.0008 apart at x = 5: four needles 5 long (twice the area over the longest edge squared
  // 1.6e-4), whose rays no plain split may halve: the face on either side would keep a half as
  // thin again (0.8e-4), under the degeneracy rule's 1e-4.
  TriangleSoup soup;
  soup.source = "fan";
  soup.points = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(5, -1, 0), Eigen::Vector3d(5, 1, 0)};
  for (int i = 0; i < 5; ++i) soup.points.push_back(Eigen::Vector3d(5, 0.0008 * (i - 2), 0));
  soup.triangles.push_back({0, 1, 3});
  for (int i = 0; i < 4; ++i) soup.triangles.push_back({0, 3 + i, 4 + i});
  soup.triangles.push_back({0, 7, 2});
  TriSurface s = surface_from_soup(soup);
  const std::unique_ptr<ReferenceGeometry<3>> ref = make_discrete_reference(s);
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.5));
  const RemeshReport r = remesh_surface(s, *ref, metric, RemeshOptions{});
  double longest = 0;
  for (const auto e : s.mesh.edges()) longest = std::max(longest, s.mesh.calc_edge_length(e));
  MESSAGE("fan cuts " << r.fan_cuts << ", refused splits " << r.refused_splits << ", longest edge " << longest);
  CHECK(r.fan_cuts > 0);
  CHECK(longest < 1.0);  // (5 without cutting the fan across: measured before the fan cut)
  CHECK(r.folded_faces == 0);
  for (const auto f : s.mesh.faces()) {
    const auto x = s.face_vertices(f);
    CHECK((s.mesh.point(x[1]) - s.mesh.point(x[0])).cross(s.mesh.point(x[2]) - s.mesh.point(x[0])).z() > 0);
  }
}

}  // namespace
}  // namespace plaf

namespace plaf {
namespace {

// The discrete reference of a surface, its points near (2.5, 0) in z = 0 lifted by a bump of
// height `lift` (a Gaussian 0.1 wide): where the fan's midpoints land, so a cut across the fan
// bends the faces along its outline.
class BumpedReference : public ReferenceGeometry<3> {
 public:
  BumpedReference(std::unique_ptr<ReferenceGeometry<3>> base, double lift) : base_(std::move(base)), lift_(lift) {}
  Vec project(const Vec& p) const override { return bumped(base_->project(p)); }
  Vec normal(const Vec& x) const override { return base_->normal(x); }
  Vec project_to_curve(const Vec& p, int curve) const override { return base_->project_to_curve(p, curve); }
  int num_curves() const override { return base_->num_curves(); }
  double scale() const override { return base_->scale(); }

 private:
  Vec bumped(Vec x) const {
    const double r2 = (x.x() - 2.5) * (x.x() - 2.5) + x.y() * x.y();
    x.z() += lift_ * std::exp(-r2 / (2 * 0.1 * 0.1));
    return x;
  }
  std::unique_ptr<ReferenceGeometry<3>> base_;
  double lift_;
};

// The fan cut's bend rule (Remesher::try_fan_cut, kFanCutMaxBend): the cut moves the faces along
// the fan's outline (its midpoints land on the reference, off the needles' planes); an edge there
// may come out bent by no more than 15 degrees where it was flat.
TEST_CASE("remesh: a fan cut that would bend the faces along the fan's outline by over 15 degrees is refused") {
  // The fan of the test above (apex 0, needles to five points 0.0008 apart at x = 5, end faces to
  // (5, -1) and (5, 1)), with faces beyond its end faces' outer edges (apex - (5, -1), apex -
  // (5, 1)) so that those edges have a bend to keep. The midpoints (2.5, ~0) lie 0.49 from them:
  // lifted by 0.05 the end faces' halves at the apex tilt by 6 degrees, by 0.3 by 31.
  const auto fan = [] {
    TriangleSoup soup;
    soup.source = "fan";
    soup.points = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(5, -1, 0), Eigen::Vector3d(5, 1, 0)};
    for (int i = 0; i < 5; ++i) soup.points.push_back(Eigen::Vector3d(5, 0.0008 * (i - 2), 0));
    soup.points.push_back(Eigen::Vector3d(2.5, -3, 0));  // 8
    soup.points.push_back(Eigen::Vector3d(2.5, 3, 0));   // 9
    soup.points.push_back(Eigen::Vector3d(-2, 0, 0));    // 10
    soup.triangles.push_back({0, 1, 3});
    for (int i = 0; i < 4; ++i) soup.triangles.push_back({0, 3 + i, 4 + i});
    soup.triangles.push_back({0, 7, 2});
    for (const std::array<int, 3>& t : {std::array<int, 3>{0, 8, 1}, {0, 2, 9}, {0, 9, 10}, {0, 10, 8}})
      soup.triangles.push_back(t);
    return surface_from_soup(soup);
  };
  const UniformMetricField<3> metric(Metric<3>::isotropic(0.5));
  RemeshOptions o;
  o.iterations = 1;
  TriSurface flat = fan();
  const BumpedReference low(make_discrete_reference(flat), 0.05);
  const RemeshReport cut = remesh_surface(flat, low, metric, o);
  CHECK(cut.fan_cuts > 0);
  TriSurface bent = fan();
  const BumpedReference high(make_discrete_reference(bent), 0.3);
  const RemeshReport refused = remesh_surface(bent, high, metric, o);
  CHECK(refused.fan_cuts == 0);
}

}  // namespace
}  // namespace plaf
