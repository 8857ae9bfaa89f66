// SPDX-License-Identifier: MIT
#include "surface3d/smooth_reference.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <thread>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "surface3d/discrete_reference.h"
#include "surface3d/features.h"
#include "tests/surface3d/test_surfaces.h"

namespace plaf {
namespace {

using Eigen::Vector3d;

// The angle between two unit vectors (atan2 form, accurate near 0).
double angle(const Vector3d& a, const Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

struct Errors {
  double distance = 0;  // max distance of a reference point to the true body
  double normal = 0;    // max angle (radians) between the reference's and the body's normal
};

// Points of every face at barycentric (i, j, k) / 6, i, j, k >= 1 (inside, off the edges, where
// the body's normal is defined even beside its ridges), projected onto `ref` and measured against
// `truth`.
Errors measure(const TriSurface& s, const ReferenceGeometry<3>& ref, const ReferenceGeometry<3>& truth) {
  Errors e;
  constexpr int n = 6;
  for (const auto f : s.mesh.faces()) {
    const auto fv = s.face_vertices(f);
    const Vector3d a = s.mesh.point(fv[0]), b = s.mesh.point(fv[1]), c = s.mesh.point(fv[2]);
    for (int i = 1; i < n; ++i)
      for (int j = 1; i + j < n; ++j) {
        const Vector3d x = (i * a + j * b + (n - i - j) * c) / n;
        Vector3d normal;
        const Vector3d q = ref.project(x, normal);
        const Vector3d t = truth.project(q);
        e.distance = std::max(e.distance, (q - t).norm());
        e.normal = std::max(e.normal, angle(normal, truth.normal(t)));
      }
  }
  return e;
}

// A body at three resolutions (h, h/2, h/4): its triangulation and its exact reference.
using BodyAt = std::function<AnalyticBody(int level)>;

struct Convergence {
  Errors facets[3], smooth[3];
  double order(const Errors (&e)[3], double Errors::*what) const { return std::log2(e[1].*what / e[2].*what); }
};

Convergence converge(const std::string& name, const BodyAt& body) {
  Convergence c;
  std::ostringstream table;
  table << name << ": level, triangles, facets distance, smooth distance, facets normal, smooth normal (rad)\n";
  for (int level = 0; level < 3; ++level) {
    const AnalyticBody b = body(level);
    c.facets[level] = measure(b.initial, *make_discrete_reference(b.initial), *b.reference);
    c.smooth[level] = measure(b.initial, *make_smooth_reference(b.initial), *b.reference);
    table << "  h/" << (1 << level) << "  " << b.initial.mesh.n_faces() << "  " << c.facets[level].distance << "  "
          << c.smooth[level].distance << "  " << c.facets[level].normal << "  " << c.smooth[level].normal << '\n';
  }
  table << "  orders (last halving): distance facets " << c.order(c.facets, &Errors::distance) << ", smooth "
        << c.order(c.smooth, &Errors::distance) << "; normal facets " << c.order(c.facets, &Errors::normal)
        << ", smooth " << c.order(c.smooth, &Errors::normal);
  MESSAGE(table.str());
  return c;
}

// The unit sphere as an icosphere soup with 20 m^2 triangles (features detected: none).
AnalyticBody icosphere_body(int m) {
  AnalyticBody b = make_sphere(Vector3d::Zero(), 1, 1);
  b.initial = surface_from_soup(test::icosphere_soup(m));
  detect_features(b.initial, {});
  return b;
}

// The flat facets converge in distance with order 2 and in normal with order 1; the smooth
// reference's thresholds sit a little below its measured orders (smooth_reference.h).
void check_faster(const Convergence& c, double distance_order, double normal_order) {
  CHECK(c.smooth[2].distance < c.facets[2].distance / 4);
  CHECK(c.smooth[2].normal < c.facets[2].normal / 5);
  CHECK(c.order(c.smooth, &Errors::distance) >= distance_order);
  CHECK(c.order(c.smooth, &Errors::normal) >= normal_order);
}

TEST_CASE("smooth reference: sphere converges faster than the facets") {
  check_faster(converge("sphere (icosphere)", [](int level) { return icosphere_body(4 << level); }), 3.5, 2.7);
}

TEST_CASE("smooth reference: ellipsoid converges faster than the facets") {
  check_faster(converge("ellipsoid (1.5, 1.2, 1)",
                        [](int level) {
                          return make_ellipsoid(Vector3d::Zero(), Vector3d(1.5, 1.2, 1), 0.4 / (1 << level));
                        }),
               3.5, 2.5);
}

// A straight NACA 0012 wing (chord 1, span 1, flat ends) triangulated from its section at n
// cosine-spaced intervals per surface: the side a (contour x span) grid of n / 2 rows, each end
// strips between the upper and lower points of the same chord station; the vertices projected onto
// the exact wing (from the section at 400 intervals).
AnalyticBody naca_wing(int n) {
  WingParams w;
  w.naca = NacaSection{"0012", true, 400};
  w.root = WingEnd::Flat;
  w.tip = WingEnd::Flat;
  AnalyticBody b = make_wing(w, 0.5);  // the exact reference; its triangulation is replaced
  const std::vector<Eigen::Vector2d> section = naca_points(NacaSection{"0012", true, n});  // TE, upper, LE, lower, TE
  const int loop = 2 * n, rows = n / 2;
  TriangleSoup soup;
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i < loop; ++i) {
      const Eigen::Vector2d& x = section[static_cast<std::size_t>(i)];
      soup.points.push_back(b.reference->project(Vector3d(x.x(), x.y(), static_cast<double>(k) / rows)));
    }
  for (int k = 0; k < rows; ++k)
    for (int i = 0; i < loop; ++i) {
      const int a = k * loop + i, c = k * loop + (i + 1) % loop;
      soup.triangles.push_back({a, c, c + loop});
      soup.triangles.push_back({a, c + loop, a + loop});
    }
  for (const int end : {0, rows}) {
    const int o = end * loop;
    for (int i = 0; i < n; ++i) {
      const int u0 = o + i, u1 = o + i + 1, l0 = o + (loop - i) % loop, l1 = o + loop - i - 1;
      std::vector<std::array<int, 3>> strip;
      if (i + 1 < n) strip.push_back({u0, u1, l1});
      if (i > 0) strip.push_back({u0, l1, l0});
      for (auto t : strip) {
        if (end == 0) std::swap(t[1], t[2]);  // the root faces -z
        soup.triangles.push_back(t);
      }
    }
  }
  b.initial = surface_from_soup(soup);
  detect_features(b.initial, {});
  return b;
}

TEST_CASE("smooth reference: NACA 0012 wing with flat ends converges faster than the facets") {
  check_faster(converge("wing (NACA 0012, chord 1, span 1, flat ends)", [](int level) { return naca_wing(16 << level); }),
               2.7, 1.7);
}

TEST_CASE("smooth reference: a box keeps its ridges and face normals exactly") {
  const Vector3d lo(-1, -0.5, -2), hi(1, 0.5, 2);
  const AnalyticBody box = make_box(lo, hi, 0.3);
  const auto ref = make_smooth_reference(box.initial);
  REQUIRE(ref->num_curves() == box.reference->num_curves());
  REQUIRE(ref->num_curves() == 12);
  const double tol = 1e-12 * ref->scale();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3d p(u(rng), u(rng), u(rng));
    for (int c = 0; c < 12; ++c) CHECK((ref->project_to_curve(p, c) - box.reference->project_to_curve(p, c)).norm() < tol);
    // Outside the box, the closest point of the flat faces is the box's.
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) {
      Vector3d n;
      const Vector3d q = ref->project(p, n);
      CHECK((q - box.reference->project(p)).norm() < tol);
      CHECK(std::abs(n.norm() - 1) < 1e-12);
    }
  }
  // Beside every ridge, on either side, the face's own normal.
  for (const Vector3d& x : {Vector3d(0.3, 0.5, 2 - 1e-9), Vector3d(0.3, 0.5 - 1e-9, 2), Vector3d(1 - 1e-7, -0.2, -2),
                            Vector3d(1, -0.2, -2 + 1e-7), Vector3d(-1 + 1e-3, 0.5, 0.7), Vector3d(-1, 0.5 - 1e-3, 0.7)}) {
    const Vector3d n = ref->normal(x), exact = box.reference->normal(box.reference->project(x));
    CHECK((n - exact).norm() < 1e-12);
  }
}

// Random points within 0.1 of the body's scale of a surface, for the projection checks.
std::vector<Vector3d> points_near(const TriSurface& s, double scale, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> vertex(0, static_cast<int>(s.mesh.n_vertices()) - 1);
  std::normal_distribution<double> gauss(0, 0.05 * scale);
  std::vector<Vector3d> out;
  for (int k = 0; k < count; ++k)
    out.push_back(s.mesh.point(TriMesh::VertexHandle(vertex(rng))) + Vector3d(gauss(rng), gauss(rng), gauss(rng)));
  return out;
}

TEST_CASE("smooth reference: projection is idempotent, finite, with unit normals") {
  std::vector<AnalyticBody> bodies;
  bodies.push_back(icosphere_body(8));
  bodies.push_back(make_ellipsoid(Vector3d::Zero(), Vector3d(1.5, 1.2, 1), 0.2));
  bodies.push_back(naca_wing(32));
  bodies.push_back(make_box(Vector3d::Zero(), Vector3d(1, 2, 3), 0.4));
  for (const AnalyticBody& b : bodies) {
    const auto ref = make_smooth_reference(b.initial);
    for (const Vector3d& p : points_near(b.initial, ref->scale(), 300, 11)) {
      Vector3d n;
      const Vector3d q = ref->project(p, n);
      REQUIRE(q.allFinite());
      CHECK(std::abs(n.norm() - 1) < 1e-12);
      CHECK((ref->project(q) - q).norm() <= 1e-12 * ref->scale());
    }
  }
}

TEST_CASE("smooth reference: results do not depend on threads") {
  const TriSurface s = make_ellipsoid(Vector3d::Zero(), Vector3d(1.5, 1.2, 1), 0.2).initial;
  const auto ref = make_smooth_reference(s);
  const std::vector<Vector3d> points = points_near(s, ref->scale(), 2000, 3);
  std::vector<Vector3d> serial;
  for (const Vector3d& p : points) serial.push_back(ref->project(p));
  std::vector<Vector3d> parallel(points.size());
  std::vector<std::thread> workers;
  for (std::size_t t = 0; t < 4; ++t)
    workers.emplace_back([&, t] {
      for (std::size_t i = t; i < points.size(); i += 4) parallel[i] = ref->project(points[i]);
    });
  for (std::thread& w : workers) w.join();
  CHECK(parallel == serial);
}

// The icosphere with every face split at an off-centre point into three (valence-3 vertices, the
// old ones at twice their valence, slivers where the point is near an edge), back on the sphere;
// its features are not detected (every edge smooth), so the slivers are fitted like the rest.
TriSurface split_icosphere(int m, unsigned seed) {
  TriangleSoup soup = test::icosphere_soup(m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::array<int, 3>> tris;
  for (const auto& t : soup.triangles) {
    Vector3d w(u(rng), u(rng), 0.01 * u(rng));  // near edge (0, 1)
    w /= w.sum();
    const Vector3d x = w.x() * soup.points[static_cast<std::size_t>(t[0])] +
                       w.y() * soup.points[static_cast<std::size_t>(t[1])] +
                       w.z() * soup.points[static_cast<std::size_t>(t[2])];
    const int c = static_cast<int>(soup.points.size());
    soup.points.push_back(x.normalized());
    tris.push_back({t[0], t[1], c});
    tris.push_back({t[1], t[2], c});
    tris.push_back({t[2], t[0], c});
  }
  soup.triangles = tris;
  return surface_from_soup(soup);  // no features: the slivers' steep edges would be ridges
}

TEST_CASE("smooth reference: slivers, valence 3 and high valence stay finite and near the sphere") {
  const TriSurface s = split_icosphere(8, 7);
  const auto ref = make_smooth_reference(s);
  const auto facets = make_discrete_reference(s);
  double smooth_err = 0, facet_err = 0;
  for (const Vector3d& p : points_near(s, ref->scale(), 2000, 9)) {
    Vector3d n;
    const Vector3d q = ref->project(p, n);
    REQUIRE(q.allFinite());
    REQUIRE(n.allFinite());
    CHECK(std::abs(n.norm() - 1) < 1e-12);
    smooth_err = std::max(smooth_err, std::abs(q.norm() - 1));
    facet_err = std::max(facet_err, std::abs(facets->project(p).norm() - 1));
  }
  MESSAGE("split icosphere: max distance to the sphere, smooth " << smooth_err << ", facets " << facet_err);
  CHECK(smooth_err < facet_err);
}

TEST_CASE("smooth reference: an empty surface and a missing curve are errors") {
  CHECK_THROWS_AS(make_smooth_reference(TriSurface()), MesherError);
  const auto ref = make_smooth_reference(icosphere_body(2).initial);
  CHECK(is_smooth_reference(*ref));
  CHECK(!is_smooth_reference(*make_discrete_reference(icosphere_body(2).initial)));
  CHECK_THROWS_AS(ref->project_to_curve(Vector3d::Zero(), 0), MesherError);
}

}  // namespace
}  // namespace plaf
