// SPDX-License-Identifier: MIT
#include "surface3d/analytic.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "modules/io/airfoil_io.h"
#include "modules/base/error.h"
#include "modules/geometry/spline_loop.h"
#include "tests/surface3d/feature_checks.h"
#include "tests/published_data.h"

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using plaf::AnalyticBody;
using plaf::EdgeFeature;
using plaf::TriSurface;
using plaf::VertexFeature;


double signed_volume(const TriSurface& s) {
  double v = 0;
  for (const auto f : s.mesh.faces()) {
    const auto vs = s.face_vertices(f);
    v += s.mesh.point(vs[0]).dot(s.mesh.point(vs[1]).cross(s.mesh.point(vs[2])));
  }
  return v / 6;
}

struct Counts {
  std::map<VertexFeature, int> vertices;
  std::map<EdgeFeature, int> edges;
};
Counts count(const TriSurface& s) {
  Counts c;
  for (const auto v : s.mesh.vertices()) ++c.vertices[s.mesh.property(s.vertex_feature, v)];
  for (const auto e : s.mesh.edges()) ++c.edges[s.mesh.property(s.edge_feature, e)];
  return c;
}

// Checks shared by every body: tags, orientation, vertices on the surface, features consistent
// with the reference's curves, and projections of random points (on the surface by `residual`,
// idempotent, and at least as close as every initial vertex, which all lie on the surface).
void check_body(const AnalyticBody& b, long euler, const std::function<double(const Vector3d&)>& residual,
                unsigned seed, double spread = 0.3) {
  const TriSurface& s = b.initial;
  const plaf::ReferenceGeometry<3>& ref = *b.reference;
  const double L = ref.scale();
  REQUIRE(L > 0);
  REQUIRE(s.tags.size() >= 1);
  CHECK(s.tags[0].name == "wall");
  CHECK(s.tags[0].kind == plaf::BoundaryKind::Wall);
  CHECK(s.euler_characteristic() == euler);
  CHECK(s.num_curves() == ref.num_curves());

  // Faces: tag 0, positive area, normal agreeing with the reference at the centroid's projection.
  int bad_normal = 0;
  Eigen::AlignedBox3d box;
  for (const auto f : s.mesh.faces()) {
    CHECK(s.mesh.property(s.face_tag, f) == 0);
    const auto vs = s.face_vertices(f);
    const Vector3d a = s.mesh.point(vs[0]), p1 = s.mesh.point(vs[1]), p2 = s.mesh.point(vs[2]);
    const Vector3d n = (p1 - a).cross(p2 - a);
    REQUIRE(n.norm() > 1e-14 * L * L);
    const Vector3d c = (a + p1 + p2) / 3;
    if (n.normalized().dot(ref.normal(ref.project(c))) <= 0) ++bad_normal;
  }
  CHECK(bad_normal == 0);

  // Vertices on the surface; curve vertices on their curve.
  double off_surface = 0, off_curve = 0;
  for (const auto v : s.mesh.vertices()) {
    const Vector3d p = s.mesh.point(v);
    box.extend(p);
    off_surface = std::max(off_surface, (ref.project(p) - p).norm());
    for (const auto h : s.mesh.voh_range(v)) {
      const int c = s.mesh.property(s.edge_curve, s.mesh.edge_handle(h));
      if (c >= 0) off_curve = std::max(off_curve, (ref.project_to_curve(p, c) - p).norm());
    }
  }
  CHECK(off_surface < 1e-9 * L);
  CHECK(off_curve < 1e-9 * L);

  // Edges: features and curves agree; open edges only on symmetry planes.
  for (const auto e : s.mesh.edges()) {
    const EdgeFeature f = s.mesh.property(s.edge_feature, e);
    const int c = s.mesh.property(s.edge_curve, e);
    const int tag = s.mesh.property(s.edge_tag, e);
    CHECK((f == EdgeFeature::Smooth) == (c < 0));
    CHECK(c < ref.num_curves());
    if (s.mesh.is_boundary(e)) {
      CHECK(f == EdgeFeature::Boundary);
      REQUIRE(tag >= 0);
      CHECK(s.tags[tag].kind == plaf::BoundaryKind::Symmetry);
    } else {
      CHECK(f != EdgeFeature::Boundary);
      CHECK(tag == -1);
    }
  }
  // Vertices on feature edges are curve vertices or corners; others are smooth.
  for (const auto v : s.mesh.vertices()) {
    int features = 0;
    for (const auto h : s.mesh.voh_range(v))
      if (s.mesh.property(s.edge_feature, s.mesh.edge_handle(h)) != EdgeFeature::Smooth) ++features;
    const VertexFeature vf = s.mesh.property(s.vertex_feature, v);
    if (features == 0) CHECK(vf == VertexFeature::Smooth);
    if (features == 2 && !plaf::is_corner(vf)) CHECK(vf == VertexFeature::Curve);
    if (features != 2 && features != 0) CHECK(plaf::is_corner(vf));
  }

  // Random points around the body.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-spread, 1 + spread);
  const Vector3d lo = box.min(), ext = box.max() - box.min();
  double worst_residual = 0, worst_idem = 0, worst_normal = 0, worst_excess = 0;
  for (int k = 0; k < 150; ++k) {
    const Vector3d p = lo + Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(ext);
    const Vector3d q = ref.project(p);
    worst_residual = std::max(worst_residual, residual(q));
    worst_idem = std::max(worst_idem, (ref.project(q) - q).norm());
    worst_normal = std::max(worst_normal, std::abs(ref.normal(q).norm() - 1));
    double nearest_vertex = 1e300;
    for (const auto v : s.mesh.vertices()) nearest_vertex = std::min(nearest_vertex, (s.mesh.point(v) - p).norm());
    worst_excess = std::max(worst_excess, (q - p).norm() - nearest_vertex);
  }
  CHECK(worst_residual < 1e-9 * L);
  CHECK(worst_idem < 1e-9 * L);
  CHECK(worst_normal < 1e-12);
  CHECK(worst_excess <= 1e-12 * L);
}

}  // namespace

TEST_CASE("analytic sphere: exact projection and an outward closed icosphere") {
  const Vector3d c(1, -2, 0.5);
  const double R = 2;
  const AnalyticBody b = plaf::make_sphere(c, R, 0.4);
  const auto residual = [&](const Vector3d& q) { return std::abs((q - c).norm() - R); };
  check_body(b, 2, residual, 1);
  CHECK(b.reference->num_curves() == 0);
  CHECK(b.initial.num_curves() == 0);
  CHECK(count(b.initial).vertices[VertexFeature::Smooth] == static_cast<int>(b.initial.mesh.n_vertices()));
  const double v = signed_volume(b.initial), exact = 4.0 / 3 * M_PI * R * R * R;
  CHECK(v > 0);
  CHECK(v == doctest::Approx(exact).epsilon(0.03));
  // Roughly uniform: edge lengths within a factor 2 of h.
  double lmin = 1e300, lmax = 0;
  for (const auto e : b.initial.mesh.edges()) {
    const double l = b.initial.mesh.calc_edge_length(e);
    lmin = std::min(lmin, l);
    lmax = std::max(lmax, l);
  }
  CHECK(lmin > 0.2);
  CHECK(lmax < 0.8);
  // Outward normals, also at the centre (any direction, unit).
  for (const Vector3d& p : {Vector3d(4, 0, 0), Vector3d(1, -2, 0.4), c}) {
    const Vector3d q = b.reference->project(p);
    CHECK((q - c).norm() == doctest::Approx(R));
    CHECK(b.reference->normal(q).dot(q - c) > 0);
  }
}

TEST_CASE("analytic ellipsoid: closest point near the centre, on the axes and far away") {
  const Vector3d c(0.5, 0, -1);
  const Vector3d e(3, 2, 1);
  const AnalyticBody b = plaf::make_ellipsoid(c, e, 0.3);
  const auto residual = [&](const Vector3d& q) { return std::abs((q - c).cwiseQuotient(e).norm() - 1); };
  check_body(b, 2, residual, 2);
  const double v = signed_volume(b.initial), exact = 4.0 / 3 * M_PI * e.prod();
  CHECK(v > 0);
  CHECK(v == doctest::Approx(exact).epsilon(0.03));
  // Brute-force distance on a fine (theta, phi) grid: the projection is never farther.
  const auto brute = [&](const Vector3d& p) {
    double best = 1e300;
    for (int i = 0; i <= 600; ++i)
      for (int j = 0; j < 1200; ++j) {
        const double th = M_PI * i / 600, ph = 2 * M_PI * j / 1200;
        const Vector3d x =
            c + e.cwiseProduct(Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
        best = std::min(best, (x - p).norm());
      }
    return best;
  };
  const std::vector<Vector3d> special = {c,
                                         c + Vector3d(1, 0, 0),    // inside, on the long axis
                                         c + Vector3d(0, 0.5, 0),  // inside, on the middle axis
                                         c + Vector3d(0, 0, 0.3),  // inside, on the short axis
                                         c + Vector3d(2, 1, 0),    // inside, in the plane z = 0
                                         c + Vector3d(1e-13, 1e-13, 1e-13),
                                         c + Vector3d(1, 1e-15, 0),  // just off the degenerate plane
                                         c + Vector3d(1, 0, 1e-12),  // tiny short-axis component
                                         c + Vector3d(1, 0.5, -1e-14),
                                         c + Vector3d(10, 0, 0),  // outside, on the axis
                                         c + Vector3d(-5, 4, 3),  // far away
                                         c + Vector3d(2.9999, 0, 0)};
  for (const Vector3d& p : special) {
    CAPTURE(p.transpose());
    const Vector3d q = b.reference->project(p);
    CHECK(residual(q) < 1e-13);
    CHECK((q - p).norm() <= brute(p) + 1e-12);
    // Stationary: p - q is along the normal at q (away from the centre itself).
    if ((p - c).norm() > 1e-6) CHECK((p - q).cross(b.reference->normal(q)).norm() < 1e-12 * (p - q).norm());
    CHECK((b.reference->project(q) - q).norm() < 1e-12);
    CHECK(b.reference->normal(q).dot(q - c) > 0);
  }
  // The centre is at the short semi-axis from the surface.
  CHECK((b.reference->project(c) - c).norm() == doctest::Approx(1.0));
}

TEST_CASE("analytic box: 12 convex ridge curves, 8 convex corners, nearest-face projection") {
  const Vector3d lo(-1, 0, 2), hi(1, 0.5, 3.5);
  const AnalyticBody b = plaf::make_box(lo, hi, 0.25);
  const auto residual = [&](const Vector3d& q) {
    // Inside or on the box, and on one of its faces.
    double out = (q - q.cwiseMax(lo).cwiseMin(hi)).norm();
    double face = 1e300;
    for (int a = 0; a < 3; ++a) face = std::min({face, std::abs(q[a] - lo[a]), std::abs(q[a] - hi[a])});
    return out + face;
  };
  check_body(b, 2, residual, 3);  // (the surface's curves are the reference's)
  CHECK(b.reference->num_curves() == 12);
  plaf::test::check_box_features(b.initial);
  // Edges per curve: the box edge length over its spacing, all convex.
  std::vector<int> per_curve(12, 0);
  for (const auto e : b.initial.mesh.edges()) {
    const int cv = b.initial.mesh.property(b.initial.edge_curve, e);
    if (cv < 0) continue;
    CHECK(b.initial.mesh.property(b.initial.edge_feature, e) == EdgeFeature::ConvexRidge);
    ++per_curve[cv];
  }
  int total = 0;
  for (int n : per_curve) {
    CHECK(n >= 2);
    total += n;
  }
  CHECK(total == 4 * (8 + 2 + 6));
  CHECK(signed_volume(b.initial) == doctest::Approx((hi - lo).prod()).epsilon(1e-12));
  // Inside: the nearest face; outside: the clamp; normals of the face.
  CHECK((b.reference->project(Vector3d(0.9, 0.25, 2.75)) - Vector3d(1, 0.25, 2.75)).norm() < 1e-15);
  CHECK((b.reference->normal(Vector3d(1, 0.25, 2.75)) - Vector3d(1, 0, 0)).norm() < 1e-15);
  CHECK((b.reference->project(Vector3d(0, 0.1, 2.75)) - Vector3d(0, 0, 2.75)).norm() < 1e-15);
  CHECK((b.reference->normal(Vector3d(0, 0, 2.75)) - Vector3d(0, -1, 0)).norm() < 1e-15);
  CHECK((b.reference->project(Vector3d(3, 1, 5)) - hi).norm() < 1e-15);
  // Curves: every curve's projection lies on a box edge (two coordinates at a bound).
  for (int cv = 0; cv < 12; ++cv) {
    const Vector3d q = b.reference->project_to_curve(Vector3d(0.3, 0.2, 2.6), cv);
    int at_bound = 0;
    for (int a = 0; a < 3; ++a) at_bound += (q[a] == lo[a] || q[a] == hi[a]) ? 1 : 0;
    CHECK(at_bound >= 2);
  }
}

namespace {

// Independent description of the section for the wing tests: the spline loop as the body builder
// makes it (same corners), and its upper/lower y at a chord station from a dense polyline.
struct Section {
  plaf::SplineLoop loop;
  std::vector<Vector2d> dense;
  double xmin = 1e300, xmax = -1e300;
  static plaf::SplineLoop make(const plaf::WingParams& w, double chord, double corner_deg) {
    plaf::BodyContour c = w.naca ? plaf::naca_contour(*w.naca) : plaf::read_body_contour(w.file);
    for (auto& p : c.points) p *= chord;
    std::vector<int> corners = plaf::detect_corners(c.points, corner_deg);
    corners.insert(corners.end(), c.corners.begin(), c.corners.end());
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    return plaf::SplineLoop(c.points, corners, c.file);
  }
  Section(const plaf::WingParams& w, double chord, double corner_deg) : loop(make(w, chord, corner_deg)) {
    const int n = 200 * loop.num_points();
    for (int k = 0; k < n; ++k) {
      dense.push_back(loop.point(loop.period() * k / n));
      xmin = std::min(xmin, dense.back().x());
      xmax = std::max(xmax, dense.back().x());
    }
  }
  // (upper, lower) y of the section at x (dense polyline crossings).
  std::pair<double, double> y_at(double x) const {
    double hi = -1e300, lo = 1e300;
    for (std::size_t k = 0; k < dense.size(); ++k) {
      const Vector2d a = dense[k], b = dense[(k + 1) % dense.size()];
      if ((a.x() - x) * (b.x() - x) > 0 || a.x() == b.x()) continue;
      const double y = a.y() + (b.y() - a.y()) * (x - a.x()) / (b.x() - a.x());
      hi = std::max(hi, y);
      lo = std::min(lo, y);
    }
    return {hi, lo};
  }
  bool inside(const Vector2d& p) const {
    const plaf::SplineLoop::Closest c = loop.closest_point(p);
    return (p - c.point).dot(loop.normal(c.t)) < 0;
  }
};

// The UIUC E387 polygon turns 52 and 39 degrees at the two points around its (smooth) leading
// edge: like the 2D configs, its wings use a 70-degree corner threshold.
double corner_angle(const std::string& file) {
  return file == "e387.dat" ? 70.0 : 30.0;
}

// A wing's section: "naca NNNN sharp|blunt" is generated (modules/io/naca_section.h), a file name
// is a published contour in the data root (the test case checks it is there).
void set_section(plaf::WingParams& p, const std::string& section) {
  if (section.rfind("naca ", 0) == 0) {
    p.naca = plaf::NacaSection{section.substr(5, section.find(' ', 5) - 5), section.find("sharp") != std::string::npos, 100};
  } else {
    p.file = plaf::test::published("airfoils/" + section);
  }
}

struct WingCase {
  std::string file;
  plaf::WingEnd root, tip;
  long euler;
  int curves;
  int corners;  // corner vertices of any kind
};

void check_wing(const WingCase& w, double chord, double span, double h) {
  CAPTURE(w.file);
  CAPTURE(static_cast<int>(w.root));
  CAPTURE(static_cast<int>(w.tip));
  plaf::WingParams p;
  set_section(p, w.file);
  p.chord = chord;
  p.span = span;
  p.root = w.root;
  p.tip = w.tip;
  p.corner_angle_deg = corner_angle(w.file);
  const AnalyticBody b = plaf::make_wing(p, h);
  const Section sec(p, chord, p.corner_angle_deg);
  const double tol = 1e-9 * b.reference->scale();
  // On the surface: the side (on the contour, 0 <= z <= span), a flat end (inside the contour),
  // or a rounded end (on the half circle through the upper and lower points at its x).
  const auto residual = [&](const Vector3d& q) {
    const double side = sec.loop.closest_point(q.head<2>()).distance;
    double best = 1e300;
    if (q.z() >= -tol && q.z() <= span + tol) best = side;
    const std::array<plaf::WingEnd, 2> ends = {w.root, w.tip};
    for (int e = 0; e < 2; ++e) {
      const double z = e == 0 ? 0.0 : span;
      if (ends[e] == plaf::WingEnd::Flat && sec.inside(q.head<2>())) best = std::min(best, std::abs(q.z() - z));
      if (ends[e] == plaf::WingEnd::Rounded && (e == 0 ? q.z() < 0 : q.z() > span) && q.x() >= sec.xmin &&
          q.x() <= sec.xmax) {
        const auto [yu, yl] = sec.y_at(q.x());
        const double yc = 0.5 * (yu + yl), r = 0.5 * (yu - yl);
        // The dense polyline's y is accurate to ~1e-6 chord only (near the leading edge): its
        // residual is scaled so that the common 1e-9 tolerance means 1e-5 here.
        best = std::min(best, std::abs(std::hypot(q.y() - yc, q.z() - z) - r) * 1e-4);
      }
    }
    return best;
  };
  check_body(b, w.euler, residual, 7, 0.15);
  CHECK(b.reference->num_curves() == w.curves);
  const Counts c = count(b.initial);
  int corners = 0;
  for (const auto& [vf, n] : c.vertices)
    if (plaf::is_corner(vf)) corners += n;
  CHECK(corners == w.corners);
  CHECK(c.edges.count(EdgeFeature::ConcaveRidge) == 0);
  // Every open edge is on a symmetry end plane.
  for (const auto e : b.initial.mesh.edges())
    if (b.initial.mesh.is_boundary(e)) {
      const auto hh = b.initial.mesh.halfedge_handle(e, 0);
      const double z0 = b.initial.mesh.point(b.initial.mesh.from_vertex_handle(hh)).z();
      const double z1 = b.initial.mesh.point(b.initial.mesh.to_vertex_handle(hh)).z();
      CHECK(z0 == z1);
      CHECK((z0 == 0.0 ? w.root : w.tip) == plaf::WingEnd::Symmetry);
      CHECK((z0 == 0.0 || z0 == span));
    }
  // Volume of a closed wing: about the section area times the span (plus the rounded caps).
  if (w.euler == 2) {
    const double area = std::abs(sec.loop.signed_area()) * span;
    const double v = signed_volume(b.initial);
    CHECK(v > 0.95 * area);
    CHECK(v < 1.1 * area + (w.root == plaf::WingEnd::Rounded || w.tip == plaf::WingEnd::Rounded ? 0.02 : 0.0));
  }
}

}  // namespace

TEST_CASE("analytic wing: E387 (sharp trailing edge) with each end type") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  // Sharp TE: one spanwise ridge; each flat or symmetry end adds one contour curve.
  check_wing({"e387.dat", plaf::WingEnd::Symmetry, plaf::WingEnd::Flat, 1, 3, 2}, 1.0, 1.5, 0.1);
  check_wing({"e387.dat", plaf::WingEnd::Flat, plaf::WingEnd::Rounded, 2, 2, 2}, 1.0, 1.0, 0.1);
  check_wing({"e387.dat", plaf::WingEnd::Symmetry, plaf::WingEnd::Symmetry, 0, 3, 2}, 2.0, 1.0, 0.2);
  check_wing({"e387.dat", plaf::WingEnd::Rounded, plaf::WingEnd::Rounded, 2, 1, 2}, 1.0, 0.8, 0.08);
}

TEST_CASE("analytic wing: a generated NACA 4412 (sharp trailing edge) with each end type, as the E387") {
  check_wing({"naca 4412 sharp", plaf::WingEnd::Symmetry, plaf::WingEnd::Flat, 1, 3, 2}, 1.0, 1.5, 0.1);
  check_wing({"naca 4412 sharp", plaf::WingEnd::Flat, plaf::WingEnd::Rounded, 2, 2, 2}, 1.0, 1.0, 0.1);
  check_wing({"naca 4412 sharp", plaf::WingEnd::Symmetry, plaf::WingEnd::Symmetry, 0, 3, 2}, 2.0, 1.0, 0.2);
  check_wing({"naca 4412 sharp", plaf::WingEnd::Rounded, plaf::WingEnd::Rounded, 2, 1, 2}, 1.0, 0.8, 0.08);
}

TEST_CASE("analytic wing: a generated NACA 0012 (blunt trailing edge) with each end type") {
  // Blunt TE: two spanwise ridges and a flat base; flat/symmetry ends add two contour curves,
  // rounded ends join both ridges through the base's half circle.
  check_wing({"naca 0012 blunt", plaf::WingEnd::Flat, plaf::WingEnd::Flat, 2, 6, 4}, 1.0, 1.0, 0.1);
  check_wing({"naca 0012 blunt", plaf::WingEnd::Symmetry, plaf::WingEnd::Rounded, 1, 3, 2}, 1.0, 1.0, 0.1);
  check_wing({"naca 0012 blunt", plaf::WingEnd::Rounded, plaf::WingEnd::Rounded, 2, 1, 0}, 1.0, 1.0, 0.1);
  check_wing({"naca 0012 blunt", plaf::WingEnd::Symmetry, plaf::WingEnd::Symmetry, 0, 6, 4}, 1.0, 1.0, 0.1);
}

TEST_CASE("analytic wing: corner vertices by end type and projections onto curves") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  plaf::WingParams p;
  p.file = plaf::test::published("airfoils/e387.dat");
  p.root = plaf::WingEnd::Symmetry;
  p.tip = plaf::WingEnd::Flat;
  p.corner_angle_deg = 70;
  const AnalyticBody b = plaf::make_wing(p, 0.1);
  const Counts c = count(b.initial);
  CHECK(c.vertices.at(VertexFeature::BoundaryCorner) == 1);  // TE ridge meets the symmetry loop
  CHECK(c.vertices.at(VertexFeature::ConvexCorner) == 1);    // TE ridge meets the flat tip ridge
  // The TE ridge projection keeps x, y of the TE and clamps z to the span.
  const TriSurface& s = b.initial;
  for (const auto e : s.mesh.edges()) {
    const int cv = s.mesh.property(s.edge_curve, e);
    if (cv < 0) continue;
    const auto h = s.mesh.halfedge_handle(e, 0);
    const Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(h)),
                   m = 0.5 * (a + s.mesh.point(s.mesh.to_vertex_handle(h)));
    // The midpoint of a curve edge projects near it, onto the curve (idempotent).
    const Vector3d q = b.reference->project_to_curve(m, cv);
    CHECK((q - m).norm() < 0.1);
    CHECK((b.reference->project_to_curve(q, cv) - q).norm() < 1e-12);
    CHECK((b.reference->project(q) - q).norm() < 1e-12);
  }
  // A point beyond the tip above the section projects onto the flat cap.
  const Vector3d q = b.reference->project(Vector3d(0.5, 0.02, 1.3));
  CHECK((q - Vector3d(0.5, 0.02, 1.0)).norm() < 1e-15);
  CHECK((b.reference->normal(q) - Vector3d(0, 0, 1)).norm() < 1e-15);
}

TEST_CASE("analytic bodies: bad parameters give a clear error") {
  CHECK_THROWS_AS(plaf::make_sphere(Vector3d::Zero(), 0.0, 0.1), plaf::ConfigError);
  CHECK_THROWS_AS(plaf::make_sphere(Vector3d::Zero(), -1.0, 0.1), plaf::ConfigError);
  CHECK_THROWS_AS(plaf::make_sphere(Vector3d::Zero(), 1.0, 0.0), plaf::ConfigError);
  CHECK_THROWS_AS(plaf::make_sphere(Vector3d::Zero(), 1.0, 1e-6), plaf::ConfigError);
  CHECK_THROWS_AS(plaf::make_ellipsoid(Vector3d::Zero(), Vector3d(1, 0, 1), 0.1), plaf::ConfigError);
  CHECK_THROWS_AS(plaf::make_box(Vector3d::Zero(), Vector3d(1, 0, 1), 0.1), plaf::ConfigError);
  CHECK_THROWS_WITH_AS(plaf::make_box(Vector3d::Ones(), Vector3d::Zero(), 0.1), doctest::Contains("lo < hi"),
                       plaf::ConfigError);
  plaf::WingParams p;
  p.naca = plaf::NacaSection{"4412", true, 100};
  p.span = 0;
  CHECK_THROWS_WITH_AS(plaf::make_wing(p, 0.1), doctest::Contains("span"), plaf::ConfigError);
  p.span = 1;
  p.chord = -1;
  CHECK_THROWS_WITH_AS(plaf::make_wing(p, 0.1), doctest::Contains("chord"), plaf::ConfigError);
  p.chord = 1;
  p.corner_angle_deg = 0;
  CHECK_THROWS_AS(plaf::make_wing(p, 0.1), plaf::ConfigError);
  p.corner_angle_deg = 30;
  CHECK_NOTHROW(plaf::make_wing(p, 0.1));
  p.naca.reset();
  p.file = std::string(PLAF_REPO_DATA) + "/airfoils/no_such_airfoil.dat";
  CHECK_THROWS_AS(plaf::make_wing(p, 0.1), plaf::InputError);
}

TEST_CASE("analytic wing: a rounded end cannot follow the E387's leading-edge corners at 30 degrees") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  plaf::WingParams p;
  p.file = plaf::test::published("airfoils/e387.dat");
  // At 30 degrees the E387 leading-edge points are corners: a rounded end cannot follow them.
  p.corner_angle_deg = 30;
  p.tip = plaf::WingEnd::Rounded;
  CHECK_THROWS_WITH_AS(plaf::make_wing(p, 0.1), doctest::Contains("e387.dat:34"), plaf::InputError);
  p.corner_angle_deg = 0;
  CHECK_THROWS_AS(plaf::make_wing(p, 0.1), plaf::ConfigError);
  p.corner_angle_deg = 70;
  CHECK_NOTHROW(plaf::make_wing(p, 0.1));
}
// A wing with a rounded tip on the section (set_section): the cap is a half body of revolution,
// tangent-continuous with the side.
static void check_rounded_tip(const std::string& file) {
  {
    CAPTURE(file);
    plaf::WingParams p;
    set_section(p, file);
    p.corner_angle_deg = corner_angle(file);
    p.chord = 2;
    p.span = 3;
    p.root = plaf::WingEnd::Symmetry;
    p.tip = plaf::WingEnd::Rounded;
    const AnalyticBody b = plaf::make_wing(p, 0.2);
    const plaf::ReferenceGeometry<3>& ref = *b.reference;
    const Section sec(p, p.chord, p.corner_angle_deg);
    // Points above the tip land on the cap: on the half circle through the upper and lower
    // surface points of their chord station, with the outward radial normal.
    int on_cap = 0;
    for (int i = 1; i < 20; ++i)
      for (const double dy : {-0.3, 0.0, 0.3}) {
        const Vector3d q = ref.project(Vector3d(0.1 * i, dy, 3.2));
        const auto [yu, yl] = sec.y_at(q.x());
        const double yc = 0.5 * (yu + yl), r = 0.5 * (yu - yl);
        CHECK(q.z() > 3.0);
        CHECK(std::hypot(q.y() - yc, q.z() - 3.0) == doctest::Approx(r).epsilon(1e-5));
        CHECK((ref.project(q) - q).norm() < 1e-12);
        CHECK(ref.normal(q).dot(Vector3d(0, q.y() - yc, q.z() - 3.0)) > 0);
        ++on_cap;
      }
    CHECK(on_cap == 57);
    // Tangent continuity: just below and just above the tip along the contour, the normals agree.
    for (int i = 0; i < 40; ++i) {
      const Vector2d c = sec.loop.point(sec.loop.period() * (i + 0.5) / 40);
      const Vector3d below = ref.project(Vector3d(c.x(), c.y(), 3 - 1e-7));
      const Vector3d above = ref.project(Vector3d(c.x(), c.y(), 3 + 1e-7));
      CHECK((below - above).norm() < 1e-6);
      CHECK(ref.normal(below).dot(ref.normal(above)) > 0.999);
    }
    // The trailing edge: a sharp one ends its ridge at the cap's tip (a convex corner); a blunt
    // one continues both ridges into the half circle closing its flat base (no corner at all).
    const Counts counts = count(b.initial);
    if (p.naca ? p.naca->sharp : true) {
      CHECK(counts.vertices.at(VertexFeature::ConvexCorner) == 1);
      CHECK(counts.vertices.at(VertexFeature::BoundaryCorner) == 1);
    } else {
      CHECK(counts.vertices.count(VertexFeature::ConvexCorner) == 0);
      CHECK(counts.vertices.at(VertexFeature::BoundaryCorner) == 2);
      // A point behind the base, above the tip plane, lands on the flat half disc (normal +x).
      const Vector3d q = ref.project(Vector3d(2.5, 0.0, 3.001));
      CHECK(q.x() == doctest::Approx(2.0));
      CHECK((ref.normal(q) - Vector3d(1, 0, 0)).norm() < 1e-9);
      // The half circle (curve edges above the tip plane) belongs to the curve of both spanwise
      // ridges: one curve, projecting onto the circle above the tip and onto the ridges below.
      const TriSurface& s = b.initial;
      std::set<int> above, ridge;
      for (const auto e : s.mesh.edges()) {
        const int cv = s.mesh.property(s.edge_curve, e);
        const auto hh = s.mesh.halfedge_handle(e, 0);
        const Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(hh)), c = s.mesh.point(s.mesh.to_vertex_handle(hh));
        if (cv >= 0 && std::max(a.z(), c.z()) > 3.0) above.insert(cv);
        if (cv >= 0 && a.z() != c.z()) ridge.insert(cv);
      }
      REQUIRE(above.size() == 1);
      CHECK(ridge == above);
      const int curve = *above.begin();
      const Vector3d h = ref.project_to_curve(Vector3d(2.0, 0.0, 3.01), curve);
      CHECK(h.z() > 3.0);
      CHECK(h.x() == doctest::Approx(2.0));
      const Vector3d h2 = ref.project_to_curve(Vector3d(2.0, 0.05, 1.5), curve);
      CHECK(h2.z() == doctest::Approx(1.5));
      CHECK(h2.y() > 0);
    }
  }
}

TEST_CASE("analytic wing: a rounded tip is a half body of revolution, tangent-continuous with the side") {
  check_rounded_tip("naca 4412 sharp");
  check_rounded_tip("naca 0012 blunt");
}

TEST_CASE("analytic wing: the E387's rounded tip is a half body of revolution, tangent-continuous with the side") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  check_rounded_tip("e387.dat");
}
