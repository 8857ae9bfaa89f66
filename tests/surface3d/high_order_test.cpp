// SPDX-License-Identifier: MIT
#include "surface3d/high_order.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/msh_io.h"
#include "modules/mesh/quality.h"
#include "tests/test_support.h"
#include "tests/surface3d/test_surfaces.h"

using namespace plaf;

namespace {

constexpr double pi = std::numbers::pi;

// The unit sphere as the reference; curve 0 (when there is one) is the equator z = 0.
class SphereReference : public ReferenceGeometry<3> {
 public:
  explicit SphereReference(int curves = 0) : curves_(curves) {}
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return p.normalized(); }
  Eigen::Vector3d normal(const Eigen::Vector3d& x) const override { return x.normalized(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override {
    return Eigen::Vector3d(p.x(), p.y(), 0).normalized();
  }
  int num_curves() const override { return curves_; }
  double scale() const override { return 2 * std::sqrt(3.0); }

 private:
  int curves_;
};

// A sphere projection that moves the node of one point (the midpoint of a chosen edge) along
// that edge by `shift` times its length: a deliberately folded edge node.
class FoldingReference : public SphereReference {
 public:
  FoldingReference(Eigen::Vector3d at, Eigen::Vector3d along) : at_(std::move(at)), along_(std::move(along)) {}
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override {
    return (p - at_).norm() < 1e-12 ? (p + along_).normalized() : p.normalized();
  }

 private:
  Eigen::Vector3d at_, along_;
};

// The plane z = 0; curve 0 is the unit circle in it.
class DiskReference : public ReferenceGeometry<3> {
 public:
  Eigen::Vector3d project(const Eigen::Vector3d& p) const override { return {p.x(), p.y(), 0}; }
  Eigen::Vector3d normal(const Eigen::Vector3d&) const override { return Eigen::Vector3d::UnitZ(); }
  Eigen::Vector3d project_to_curve(const Eigen::Vector3d& p, int) const override {
    return Eigen::Vector3d(p.x(), p.y(), 0).normalized();
  }
  int num_curves() const override { return 1; }
  double scale() const override { return 2; }
};

// A sphere triangulation: a regular polyhedron (counter-clockwise seen from outside) whose
// triangles are split in four `levels` times, new vertices projected onto the unit sphere.
TriSurface sphere(bool icosahedron, int levels) {
  TriangleSoup soup;
  soup.source = icosahedron ? "icosphere" : "octasphere";
  if (icosahedron) {
    soup = test::icosahedron_soup();
    soup.source = "icosphere";
  } else {
    soup.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    soup.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  }
  for (auto& p : soup.points) p.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto [it, fresh] = mid.try_emplace(key, static_cast<int>(soup.points.size()));
      if (fresh) {
        const Eigen::Vector3d p = soup.points[static_cast<std::size_t>(a)] + soup.points[static_cast<std::size_t>(b)];
        soup.points.push_back(p.normalized());
      }
      return it->second;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : soup.triangles) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    soup.triangles = std::move(next);
  }
  return surface_from_soup(soup);
}

// The upper half (z > 0) of an octasphere: its rim is the equator, made of edges in z = 0, tagged
// "symmetry" and on feature curve 0.
TriSurface hemisphere(int levels) {
  const TriSurface full = sphere(false, levels);
  TriangleSoup soup = soup_from_surface(full);
  soup.source = "hemisphere";
  std::vector<std::array<int, 3>> upper;
  for (const auto& t : soup.triangles) {
    double z = 0;
    for (int v : t) z += soup.points[static_cast<std::size_t>(v)].z();
    if (z > 0) upper.push_back(t);
  }
  soup.triangles = upper;
  TriSurface s = surface_from_soup(soup);
  s.mesh.delete_isolated_vertices();
  s.mesh.garbage_collection();
  const int symmetry = s.add_tag("symmetry", BoundaryKind::Symmetry);
  for (const auto e : s.mesh.edges())
    if (s.mesh.is_boundary(e)) {
      s.mesh.property(s.edge_tag, e) = symmetry;
      s.mesh.property(s.edge_curve, e) = 0;
      s.mesh.property(s.edge_feature, e) = EdgeFeature::Boundary;
    }
  return s;
}

std::size_t count_boundary_edges(const TriSurface& s) {
  std::size_t n = 0;
  for (const auto e : s.mesh.edges()) n += s.mesh.is_boundary(e) ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("high_order: icosphere area converges to 4 pi at rate about Q + 1, every triangle certified valid") {
  const SphereReference reference;
  constexpr int levels = 4;  // 20 .. 5120 triangles
  // (An ostringstream: GCC 12 flags "literal" + std::string chains with a false -Wrestrict.)
  std::ostringstream table;
  table << "area errors for 20, 80, 320, 1280, 5120 triangles; observed rates; min scaled Jacobian at 5120\n";
  for (int q = 1; q <= max_order; ++q) {
    std::vector<double> err;
    double min_sj = 0;
    for (int l = 0; l <= levels; ++l) {
      TriSurface s = sphere(true, l);
      const CurvingReport r = curve_surface(s, reference, q);
      INFO("order ", q, " level ", l);
      CHECK(r.triangles == s.mesh.n_faces());
      CHECK(r.invalid == 0);
      CHECK(r.straightened == 0);
      // Coarse order-1 triangles are flat (scaled Jacobian 1); curved ones stay close to it.
      CHECK(r.min_scaled_jacobian > (q == 1 ? 0.999 : l == 0 ? 0.3 : 0.7));
      CHECK(r.min_scaled_jacobian <= 1 + 1e-9);
      if (l == levels) min_sj = r.min_scaled_jacobian;
      err.push_back(std::abs(surface_area(s) - 4 * pi));
    }
    table << "  Q" << q << ":" << std::setprecision(3);
    for (double e : err) table << ' ' << e;
    table << "; rates";
    for (std::size_t l = 1; l < err.size(); ++l) {
      const double rate = std::log2(err[l - 1] / err[l]);
      table << ' ' << rate;
      // The first refinement is pre-asymptotic (20 triangles); after it the rate is Q + 1 or more.
      if (l >= 2) CHECK_MESSAGE(rate > q + 0.5, "order ", q, " refinement ", l, ": rate ", rate);
    }
    table << "; " << min_sj << '\n';
  }
  MESSAGE(table.str());
}

TEST_CASE("high_order: a scaled-Jacobian floor straightens the triangles below it, and only those") {
  // The 20-triangle icosphere at order 3: curved triangles around 0.3-0.5 (the test above).
  const SphereReference reference;
  TriSurface free_ = sphere(true, 0);
  const CurvingReport loose = curve_surface(free_, reference, 3);
  REQUIRE(loose.min_scaled_jacobian < 0.9);
  for (const double floor : {0.5 * loose.min_scaled_jacobian, 0.9}) {
    CAPTURE(floor);
    TriSurface s = sphere(true, 0);
    const CurvingReport r = curve_surface(s, reference, 3, {}, floor);
    CHECK(r.invalid == 0);
    CHECK(r.min_scaled_jacobian >= floor);
    // Below the loose minimum nothing moves; at 0.9 every triangle is pulled toward flat, and the
    // surface is no longer on the sphere at its pulled nodes.
    CHECK(r.straightened == (floor < loose.min_scaled_jacobian ? 0u : r.triangles));
    double off = 0;
    for (const auto f : s.mesh.faces())
      for (const Eigen::Vector3d& x : s.triangle_nodes(f)) off = std::max(off, std::abs(x.norm() - 1));
    CHECK((floor < loose.min_scaled_jacobian ? off < 1e-12 : off > 1e-3));
  }
}

TEST_CASE("high_order: nodes lie on the sphere in Gmsh order and order 1 clears them") {
  const SphereReference reference;
  TriSurface s = sphere(true, 1);
  const CurvingReport r = curve_surface(s, reference, 3);
  CHECK(s.order == 3);
  const LagrangeElement& tri = lagrange_element(CellType::Triangle, 3);
  for (const auto f : s.mesh.faces()) {
    const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(f);
    REQUIRE(nodes.size() == 10);
    const Eigen::Vector3d flat_centroid = (nodes[0] + nodes[1] + nodes[2]) / 3;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      CHECK(nodes[k].norm() == doctest::Approx(1).epsilon(1e-14));
      // Each node is the projection of its flat lattice point, up to the blending (near it).
      const auto x = tri.ref_node(static_cast<int>(k));
      const Eigen::Vector3d flat = nodes[0] * (1 - x[0] - x[1]) + nodes[1] * x[0] + nodes[2] * x[1];
      CHECK((nodes[k] - flat.normalized()).norm() < 1e-2);
    }
    // The face node of Q3 is the centroid's projection (by symmetry of the blending).
    CHECK((nodes[9] - flat_centroid.normalized()).norm() < 1e-3);
  }
  CHECK(r.invalid == 0);
  const CurvingReport r1 = curve_surface(s, reference, 1);
  CHECK(r1.invalid == 0);
  CHECK(r1.min_scaled_jacobian == doctest::Approx(1));
  for (const auto e : s.mesh.edges()) CHECK(s.mesh.property(s.edge_nodes, e).empty());
  CHECK(surface_area(s) < 4 * pi);
  CHECK_THROWS_AS(curve_surface(s, reference, 5), Error);
}

TEST_CASE("high_order: a folded edge node makes two invalid triangles that are straightened and counted") {
  TriSurface s = sphere(true, 1);
  const auto e = *s.mesh.edges().begin();
  const auto h = s.mesh.halfedge_handle(e, 0);
  const Eigen::Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(h)), b = s.mesh.point(s.mesh.to_vertex_handle(h));
  // The Q2 node at 0.8 of the edge instead of 0.5: an order-2 edge folds when its middle node
  // leaves the middle half of the chord (x'(0) = 4c - 1, x'(1) = 3 - 4c at fraction c).
  const FoldingReference folding(a + (b - a) * 0.5, 0.3 * (b - a));
  const CurvingReport r = curve_surface(s, folding, 2);
  CHECK(r.triangles == 80);
  CHECK(r.invalid == 0);
  CHECK(r.straightened == 2);
  CHECK(r.min_scaled_jacobian > 0);
  // The first step (0.75 of the displacement, c = 0.725) is enough.
  const Eigen::Vector3d flat = a + (b - a) * 0.5;
  const Eigen::Vector3d curved = (flat + 0.3 * (b - a)).normalized();
  CHECK((s.mesh.property(s.edge_nodes, e)[0] - (flat + 0.75 * (curved - flat))).norm() < 1e-14);
  // Every triangle certifies valid afterwards.
  JacobianCertifier certifier;
  for (const auto f : s.mesh.faces()) CHECK(certify_surface_triangle(certifier, 2, s.triangle_nodes(f).data()).valid);

  // A fold that no step short of flat repairs (c = 2) ends with the edge straight.
  TriSurface t = sphere(true, 1);
  const FoldingReference worse(a + (b - a) * 0.5, 1.5 * (b - a));
  const CurvingReport rw = curve_surface(t, worse, 2);
  CHECK(rw.invalid == 0);
  CHECK(rw.straightened == 2);
  CHECK((t.mesh.property(t.edge_nodes, e)[0] - flat).norm() < 1e-14);
}

TEST_CASE("high_order: the hemisphere rim stays on the equator curve, area 2 pi, a missing curve throws") {
  TriSurface s = hemisphere(3);
  const SphereReference reference(1);
  const CurvingReport r = curve_surface(s, reference, 4);
  CHECK(r.invalid == 0);
  for (const auto e : s.mesh.edges())
    if (s.mesh.is_boundary(e))
      for (const Eigen::Vector3d& x : s.mesh.property(s.edge_nodes, e)) {
        CHECK(std::abs(x.z()) < 1e-15);
        CHECK(x.norm() == doctest::Approx(1).epsilon(1e-14));
      }
  CHECK(surface_area(s) == doctest::Approx(2 * pi).epsilon(1e-6));
  TriSurface u = hemisphere(1);
  const SphereReference no_curves(0);
  CHECK_THROWS_AS(curve_surface(u, no_curves, 2), MesherError);
}

TEST_CASE("high_order: surface_to_mesh conforms for a closed sphere and a hemisphere whose rim is a curves block") {
  const SphereReference reference(1);
  SUBCASE("closed sphere") {
    for (int q = 1; q <= max_order; ++q) {
      TriSurface s = sphere(true, 1);
      curve_surface(s, reference, q);
      const HybridMesh<3> m = surface_to_mesh(s);
      REQUIRE(m.boundary.size() == 1);
      CHECK(m.boundary[0].order == q);
      CHECK(m.boundary[0].size() == 80);
      CHECK(m.curves.empty());
      // V + E (q - 1) + F (q - 1)(q - 2) / 2 nodes, all used.
      CHECK(m.nodes.size() == static_cast<std::size_t>(42 + 120 * (q - 1) + 80 * (q - 1) * (q - 2) / 2));
      const ConformityReport c = check_conformity(m);
      CHECK_MESSAGE(c.ok, c.first_problem);
      CHECK(c.interior_facets == 120);
      CHECK(c.boundary_facets == 0);
      // The mesh's triangles are the surface's, node for node.
      std::size_t i = 0;
      for (const auto f : s.mesh.faces()) {
        const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(f);
        for (std::size_t k = 0; k < nodes.size(); ++k) CHECK(m.nodes[m.boundary[0].cell(i)[k]] == nodes[k]);
        ++i;
      }
    }
  }
  SUBCASE("hemisphere") {
    TriSurface s = hemisphere(2);
    curve_surface(s, reference, 3);
    HybridMesh<3> m = surface_to_mesh(s);
    const std::size_t rim = count_boundary_edges(s);
    CHECK(rim == 16);
    REQUIRE(m.curves.size() == 1);
    CHECK(m.curves[0].order == 3);
    CHECK(m.curves[0].size() == rim);
    CHECK(m.tags.at(static_cast<std::size_t>(m.curves[0].tag)).name == "symmetry");
    CHECK(m.tags.at(static_cast<std::size_t>(m.curves[0].tag)).kind == BoundaryKind::Symmetry);
    ConformityReport c = check_conformity(m);
    CHECK_MESSAGE(c.ok, c.first_problem);
    CHECK(c.boundary_facets == rim);
    CHECK(c.open_facets == 0);

    // Without the curves block the rim is a hole.
    HybridMesh<3> open = m;
    open.curves.clear();
    c = check_conformity(open);
    CHECK_FALSE(c.ok);
    CHECK(c.open_facets == rim);
    // A curve line with other high-order nodes than its triangle's edge is a mismatch.
    HybridMesh<3> wrong = m;
    wrong.curves[0].connectivity[2] = wrong.curves[0].connectivity[6];  // a node of the next rim edge
    c = check_conformity(wrong);
    CHECK_FALSE(c.ok);
    CHECK(c.node_mismatches >= 1);

    // MSH 4.1 round trip keeps the curves block and its tag; the quality check reads it back.
    test::TempDir dir("high_order_msh");
    write_msh41(m, dir / "hemisphere.msh");
    const MshMesh back = read_msh41(dir / "hemisphere.msh");
    REQUIRE(back.dim == 3);
    REQUIRE(back.mesh3.curves.size() == 1);
    CHECK(back.mesh3.curves[0].connectivity == m.curves[0].connectivity);
    CHECK(back.mesh3.boundary[0].connectivity == m.boundary[0].connectivity);
    REQUIRE(back.mesh3.tags.size() == m.tags.size());
    CHECK(back.mesh3.tags[static_cast<std::size_t>(back.mesh3.curves[0].tag)].name == "symmetry");
    CHECK(back.mesh3.tags[static_cast<std::size_t>(back.mesh3.curves[0].tag)].kind == BoundaryKind::Symmetry);
    const QualityReport q = assess_quality<3>(back.mesh3, nullptr, QualityOptions{});
    CHECK(q.surface);
    CHECK(q.ok());
    CHECK(q.cells_total == s.mesh.n_faces());
    CHECK(q.cells_by_type.at("triangle_Q3") == s.mesh.n_faces());
    CHECK(q.scaled_jacobian_min > 0.5);
    CHECK(q.conformity.boundary_facets == rim);
  }
}

TEST_CASE("high_order: surface_to_mesh rejects a tag outside the surface's tags") {
  TriSurface s = sphere(false, 0);
  s.mesh.property(s.face_tag, *s.mesh.faces().begin()) = 3;
  CHECK_THROWS_AS(surface_to_mesh(s), MesherError);
  TriSurface t = sphere(false, 0);
  t.mesh.property(t.edge_tag, *t.mesh.edges().begin()) = 1;
  CHECK_THROWS_AS(surface_to_mesh(t), MesherError);
}

TEST_CASE("high_order: face nodes follow a curved edge that moves along the surface (a quarter disk)") {
  // The triangle (0,0), (1,0), (0,1) in z = 0 with its long edge on the unit circle: curving it
  // moves the edge nodes outward within the plane, and the face nodes must follow.
  TriangleSoup soup;
  soup.source = "quarter disk";
  soup.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  soup.triangles = {{0, 1, 2}};
  const DiskReference disk;
  for (int q = 2; q <= max_order; ++q) {
    INFO("order ", q);
    TriSurface s = surface_from_soup(soup);
    for (const auto e : s.mesh.edges()) {
      const auto h = s.mesh.halfedge_handle(e, 0);
      const bool arc = s.mesh.point(s.mesh.from_vertex_handle(h)).norm() > 0.5 &&
                       s.mesh.point(s.mesh.to_vertex_handle(h)).norm() > 0.5;
      s.mesh.property(s.edge_curve, e) = arc ? 0 : -1;
    }
    const CurvingReport r = curve_surface(s, disk, q);
    CHECK(r.invalid == 0);
    // The projection of equispaced chord points spaces the arc's nodes unevenly (18 and 27
    // degrees at Q = 4), which alone bends det J along the arc.
    CHECK(r.min_scaled_jacobian > 0.2);
    const std::vector<Eigen::Vector3d> nodes = s.triangle_nodes(s.mesh.face_handle(0));
    // The arc's nodes lie on the circle; the face nodes moved outward from their flat lattice
    // points (x + y grows), all in the plane.
    const LagrangeElement& tri = lagrange_element(CellType::Triangle, q);
    int arcs = 0;
    for (int i = 0; i < 3; ++i) {
      if (nodes[static_cast<std::size_t>(i)].norm() < 0.5 || nodes[static_cast<std::size_t>((i + 1) % 3)].norm() < 0.5)
        continue;
      ++arcs;
      for (int k = 0; k < q - 1; ++k)
        CHECK(nodes[static_cast<std::size_t>(3 + i * (q - 1) + k)].norm() == doctest::Approx(1).epsilon(1e-14));
    }
    CHECK(arcs == 1);
    for (int k = 0; k < tri.size(); ++k) {
      const Eigen::Vector3d& x = nodes[static_cast<std::size_t>(k)];
      CHECK(x.z() == 0);
      if (k < 3 * q) continue;
      const auto ref = tri.ref_node(k);
      const Eigen::Vector3d flat = nodes[0] * (1 - ref[0] - ref[1]) + nodes[1] * ref[0] + nodes[2] * ref[1];
      CHECK(x.x() + x.y() > flat.x() + flat.y() + 1e-3);
    }
    // The area approaches the quarter disk's pi / 4 (one triangle for a 90 degree arc: loosely;
    // measured errors -0.0093, 0.0102, 0.0005 at Q = 2, 3, 4).
    CHECK(std::abs(surface_area(s) - pi / 4) < 1.5e-2);
  }
}
