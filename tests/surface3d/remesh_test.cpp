// SPDX-License-Identifier: MIT
#include "surface3d/remesh.h"

#include <doctest/doctest.h>

#include <cmath>
#include <map>

#include "modules/metric.h"
#include "modules/tri_surface.h"

namespace plaf {
namespace {

// The unit sphere, projecting radially (test-local: the remesher sees only the interface).
class UnitSphere final : public ReferenceGeometry {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return p.normalized(); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return x.normalized(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override { return p.normalized(); }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * std::sqrt(3.0); }
};

// An icosahedron on the unit sphere, outward.
TriSurface icosahedron() {
  const double t = (1 + std::sqrt(5.0)) / 2;
  TriangleSoup s;
  s.source = "icosahedron";
  s.points = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : s.points) p.normalize();
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return surface_from_soup(s);
}

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
  MESSAGE("anisotropic: " << s.mesh.n_faces() << " faces, unit fraction " << r.unit_fraction);
}

}  // namespace
}  // namespace plaf
