// SPDX-License-Identifier: MIT
#include "surface3d/features.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "modules/base/error.h"
#include "surface3d/analytic.h"
#include "surface3d/discrete_reference.h"
#include "tests/surface3d/feature_checks.h"
#include "tests/surface3d/test_surfaces.h"

namespace plaf {
namespace {

using test::check_box_features;
using test::voxel_soup;

constexpr double kPi = 3.14159265358979323846;

// A body of revolution about z: profile (r, z) from the bottom pole (r = 0) to the top pole
// (r = 0), `around` segments. Quads between rings are split into two triangles, the poles are
// fans; faces are counter-clockwise seen from outside.
TriangleSoup revolution_soup(const std::vector<std::array<double, 2>>& profile, int around) {
  TriangleSoup soup;
  soup.source = "revolution";
  const int rings = static_cast<int>(profile.size());
  std::vector<std::vector<int>> id(static_cast<std::size_t>(rings));
  for (int i = 0; i < rings; ++i) {
    const auto [r, z] = profile[static_cast<std::size_t>(i)];
    const int n = (i == 0 || i == rings - 1) ? 1 : around;
    for (int j = 0; j < n; ++j) {
      const double t = 2 * kPi * j / around;
      id[static_cast<std::size_t>(i)].push_back(static_cast<int>(soup.points.size()));
      soup.points.emplace_back(r * std::cos(t), r * std::sin(t), z);
    }
  }
  const auto at = [&](int i, int j) {
    const auto& ring = id[static_cast<std::size_t>(i)];
    return ring[static_cast<std::size_t>(j % static_cast<int>(ring.size()))];
  };
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < around; ++j) {
      const int pa = at(i, j), pb = at(i, j + 1), pc = at(i + 1, j + 1), pd = at(i + 1, j);
      if (pa != pb) soup.triangles.push_back({pa, pb, pc});
      if (pc != pd) soup.triangles.push_back({pa, pc, pd});
    }
  return soup;
}

std::vector<std::array<double, 2>> sphere_profile(int rings) {
  std::vector<std::array<double, 2>> p;
  for (int i = 0; i <= rings; ++i) {
    const double phi = -kPi / 2 + kPi * i / rings;
    p.push_back({i == 0 || i == rings ? 0.0 : std::cos(phi), std::sin(phi)});
  }
  return p;
}

// A flat sheet, x in [0, 2], folded about the x axis: y < 0 stays in z = 0, y > 0 turns by
// fold_deg about +x (towards +z, the side the normals face, for fold_deg > 0: a valley).
TriangleSoup folded_sheet(double fold_deg) {
  TriangleSoup soup;
  soup.source = "sheet";
  const int nx = 4, ny = 2;
  const double t = fold_deg * kPi / 180;
  for (int j = 0; j <= 2 * ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double x = 2.0 * i / nx, y = static_cast<double>(j - ny) / ny;
      soup.points.emplace_back(x, y <= 0 ? y : y * std::cos(t), y <= 0 ? 0.0 : y * std::sin(t));
    }
  const auto at = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < 2 * ny; ++j)
    for (int i = 0; i < nx; ++i) {
      soup.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      soup.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return soup;
}

struct CurveShapes {
  int open = 0, closed = 0;
};

// The invariants every detection must satisfy, and feature_curves checked against the edges:
// consecutive vertices share an edge of the curve, every curve edge is walked once, open curves
// end at corners, Curve vertices continue one curve of one kind, and count_features agrees.
CurveShapes check_consistent(const TriSurface& s, const FeatureReport& report) {
  const TriMesh& m = s.mesh;
  const FeatureReport again = count_features(s);
  CHECK(again.ridges_convex == report.ridges_convex);
  CHECK(again.ridges_concave == report.ridges_concave);
  CHECK(again.boundary_edges == report.boundary_edges);
  CHECK(again.corners_convex == report.corners_convex);
  CHECK(again.corners_concave == report.corners_concave);
  CHECK(again.corners_saddle == report.corners_saddle);
  CHECK(again.corners_boundary == report.corners_boundary);
  CHECK(again.curves == report.curves);

  std::map<int, std::size_t> edges_of;
  for (const auto e : m.edges()) {
    const EdgeFeature f = m.property(s.edge_feature, e);
    const int c = m.property(s.edge_curve, e);
    CHECK((f == EdgeFeature::Smooth) == (c < 0));
    CHECK((f == EdgeFeature::Boundary) == m.is_boundary(e));
    if (c >= 0) ++edges_of[c];
  }
  CHECK(edges_of.size() == report.curves);
  for (const auto v : m.vertices()) {
    std::vector<TriMesh::EdgeHandle> feature;
    for (const auto h : m.voh_range(v))
      if (m.property(s.edge_feature, m.edge_handle(h)) != EdgeFeature::Smooth) feature.push_back(m.edge_handle(h));
    const VertexFeature vf = m.property(s.vertex_feature, v);
    if (vf == VertexFeature::Curve) {
      REQUIRE(feature.size() == 2);
      CHECK(m.property(s.edge_curve, feature[0]) == m.property(s.edge_curve, feature[1]));
      CHECK((m.property(s.edge_feature, feature[0]) == EdgeFeature::Boundary) ==
            (m.property(s.edge_feature, feature[1]) == EdgeFeature::Boundary));
    } else if (vf == VertexFeature::Smooth) {
      CHECK(feature.empty());
    }
  }

  CurveShapes shapes;
  const auto curves = feature_curves(s);
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const auto& path = curves[c];
    if (!edges_of.count(static_cast<int>(c))) {
      CHECK(path.empty());
      continue;
    }
    REQUIRE(path.size() == edges_of[static_cast<int>(c)] + 1);
    std::set<int> walked;
    bool has_boundary = false, has_ridge = false;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      const auto h = m.find_halfedge(path[i], path[i + 1]);
      REQUIRE(h.is_valid());
      const auto e = m.edge_handle(h);
      CHECK(m.property(s.edge_curve, e) == static_cast<int>(c));
      walked.insert(e.idx());
      (m.property(s.edge_feature, e) == EdgeFeature::Boundary ? has_boundary : has_ridge) = true;
    }
    CHECK(walked.size() == edges_of[static_cast<int>(c)]);
    CHECK(!(has_boundary && has_ridge));
    if (path.front() == path.back()) {
      ++shapes.closed;
    } else {
      ++shapes.open;
      CHECK(is_corner(m.property(s.vertex_feature, path.front())));
      CHECK(is_corner(m.property(s.vertex_feature, path.back())));
    }
    for (std::size_t i = 1; i + 1 < path.size(); ++i) CHECK(!is_corner(m.property(s.vertex_feature, path[i])));
  }
  return shapes;
}

TEST_CASE("features: a cube with k x k squares per face has 12 convex ridge curves and 8 convex corners") {
  // k = 91 is a 100k-face cube (6 * 2 * 91^2 = 99,372 faces); bench_features times it.
  for (const auto& [k, scale] : {std::pair{2, 1e-8}, {2, 1.0}, {2, 1e8}, {91, 1.0}}) {
    CAPTURE(k);
    CAPTURE(scale);
    TriSurface s = surface_from_soup(voxel_soup({{0, 0, 0}}, k, scale));
    REQUIRE(s.mesh.n_faces() == static_cast<std::size_t>(12 * k * k));
    const FeatureReport r = detect_features(s, {});
    CHECK(r.ridges_convex == static_cast<std::size_t>(12 * k));
    check_box_features(s);
    check_consistent(s, r);
    for (const auto& path : feature_curves(s)) CHECK(path.size() == static_cast<std::size_t>(k + 1));
    // Edge points are Curve vertices, face points smooth.
    int curve_vertices = 0, smooth_vertices = 0;
    for (const auto v : s.mesh.vertices()) {
      const VertexFeature vf = s.mesh.property(s.vertex_feature, v);
      curve_vertices += vf == VertexFeature::Curve;
      smooth_vertices += vf == VertexFeature::Smooth;
    }
    CHECK(curve_vertices == 12 * (k - 1));
    CHECK(smooth_vertices == 6 * (k - 1) * (k - 1));
  }
}

TEST_CASE("features: an extruded L has one concave spanwise ridge with saddle corners at its ends") {
  TriSurface s = surface_from_soup(voxel_soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 2));
  const FeatureReport r = detect_features(s, {});
  // The outline has 8 unit sides on each cap (2 edges each), plus 5 convex vertical unit edges.
  CHECK(r.ridges_convex == (8 + 8 + 5) * 2);
  CHECK(r.ridges_concave == 2);
  CHECK(r.corners_convex == 10);
  CHECK(r.corners_saddle == 2);
  CHECK(r.corners_concave == 0);
  CHECK(r.curves == 6 + 6 + 6);
  const CurveShapes shapes = check_consistent(s, r);
  CHECK(shapes.open == 18);
  const TriMesh& m = s.mesh;
  for (const auto v : m.vertices()) {
    const Eigen::Vector3d p = m.point(v);
    const bool reentrant_end = p.x() == 1 && p.y() == 1 && (p.z() == 0 || p.z() == 1);
    CHECK((m.property(s.vertex_feature, v) == VertexFeature::SaddleCorner) == reentrant_end);
  }
  // The concave edges are the two on x = y = 1, and they form one curve.
  std::set<int> concave_curves;
  for (const auto e : m.edges()) {
    if (m.property(s.edge_feature, e) != EdgeFeature::ConcaveRidge) continue;
    const auto h = m.halfedge_handle(e, 0);
    for (const auto v : {m.from_vertex_handle(h), m.to_vertex_handle(h)}) {
      CHECK(m.point(v).x() == 1);
      CHECK(m.point(v).y() == 1);
    }
    concave_curves.insert(m.property(s.edge_curve, e));
  }
  CHECK(concave_curves.size() == 1);
}

TEST_CASE("features: a finely triangulated sphere has no features at 30 degrees") {
  TriSurface s = surface_from_soup(revolution_soup(sphere_profile(24), 48));
  const FeatureReport r = detect_features(s, {});
  CHECK(r.ridges_convex + r.ridges_concave + r.boundary_edges == 0);
  CHECK(r.corners_convex + r.corners_concave + r.corners_saddle + r.corners_boundary == 0);
  CHECK(r.curves == 0);
  CHECK(feature_curves(s).empty());
  for (const auto v : s.mesh.vertices()) CHECK(s.mesh.property(s.vertex_feature, v) == VertexFeature::Smooth);
  // A threshold below the 7.5 degree facet angle turns every latitude edge into a ridge.
  const FeatureReport fine = detect_features(s, {.ridge_angle_deg = 3});
  CHECK(fine.ridges_convex > 0);
  CHECK(fine.ridges_concave == 0);
  check_consistent(s, fine);
}

TEST_CASE("features: a capped cylinder has two closed convex loops without corners") {
  TriSurface s = surface_from_soup(revolution_soup({{0, 0}, {1, 0}, {1, 0.5}, {1, 1}, {1, 1.5}, {1, 2}, {0, 2}}, 32));
  const FeatureReport r = detect_features(s, {});
  CHECK(r.ridges_convex == 64);
  CHECK(r.ridges_concave == 0);
  CHECK(r.corners_convex + r.corners_concave + r.corners_saddle + r.corners_boundary == 0);
  CHECK(r.curves == 2);
  const CurveShapes shapes = check_consistent(s, r);
  CHECK(shapes.closed == 2);
  for (const auto& path : feature_curves(s)) {
    REQUIRE(path.size() == 33);
    const double z = s.mesh.point(path.front()).z();
    CHECK((z == 0 || z == 2));
    for (const auto v : path) CHECK(s.mesh.point(v).z() == z);
  }
}

TEST_CASE("features: a cone's apex is a corner by its angle defect and its base a closed convex loop") {
  // Half angle 30 degrees: the apex defect is 2 pi (1 - sin 30) = 180 degrees, with no ridge there.
  const double h = std::sqrt(3.0);
  TriSurface s = surface_from_soup(
      revolution_soup({{0, 0}, {0.5, 0}, {1, 0}, {0.75, 0.25 * h}, {0.5, 0.5 * h}, {0.25, 0.75 * h}, {0, h}}, 32));
  const FeatureReport r = detect_features(s, {});
  CHECK(r.ridges_convex == 32);
  CHECK(r.ridges_concave == 0);
  CHECK(r.corners_convex == 1);
  CHECK(r.corners_concave + r.corners_saddle + r.corners_boundary == 0);
  CHECK(r.curves == 1);
  const CurveShapes shapes = check_consistent(s, r);
  CHECK(shapes.closed == 1);
  for (const auto v : s.mesh.vertices()) {
    const bool apex = s.mesh.point(v).z() == h;
    CHECK((s.mesh.property(s.vertex_feature, v) == VertexFeature::ConvexCorner) == apex);
  }
  // Above the apex defect the apex is no corner.
  const FeatureReport loose = detect_features(s, {.corner_defect_deg = 200});
  CHECK(loose.corners_convex == 0);
  CHECK(loose.curves == 1);
}

TEST_CASE("features: a bicone's apexes are its discrete reference's cone points, and nothing else is") {
  // Both apexes on the z axis (the same x: the sorted lookup scans ties), the equator a ridge
  // loop whose vertices are on a feature and so no cone points.
  const double h = std::sqrt(3.0);
  TriSurface s = surface_from_soup(revolution_soup({{0, -h}, {0.5, -0.5 * h}, {1, 0}, {0.5, 0.5 * h}, {0, h}}, 24));
  const FeatureReport r = detect_features(s, {});
  CHECK(r.corners_convex == 2);
  CHECK(r.curves == 1);
  const auto ref = make_discrete_reference(s);
  const double tol = 1e-6 * ref->scale();
  for (const double z : {-h, h}) {
    CHECK(ref->is_cone_point(Eigen::Vector3d(0, 0, z), tol));
    CHECK(ref->is_cone_point(Eigen::Vector3d(0.5 * tol, 0, z), tol));
    CHECK_FALSE(ref->is_cone_point(Eigen::Vector3d(2 * tol, 0, z), tol));
    CHECK_FALSE(ref->is_cone_point(Eigen::Vector3d(0, 0, z - 2 * tol * (z > 0 ? -1 : 1)), tol));
  }
  int cones = 0;
  for (const auto v : s.mesh.vertices()) cones += ref->is_cone_point(s.mesh.point(v), tol) ? 1 : 0;
  CHECK(cones == 2);
}

TEST_CASE("features: a cone dented into a cylinder's top is a concave corner, the rim a concave loop") {
  // Cylinder r = 1 with its top cap replaced by a cone pointing into the body (depth 1).
  TriSurface s = surface_from_soup(revolution_soup({{0, 0}, {1, 0}, {1, 1}, {1, 2}, {0.5, 1.5}, {0, 1}}, 32));
  const FeatureReport r = detect_features(s, {});
  CHECK(r.corners_concave == 1);  // the dent's apex: positive defect, pointing inwards
  CHECK(r.corners_convex + r.corners_saddle + r.corners_boundary == 0);
  CHECK(r.ridges_convex == 64);  // the bottom rim, and the top rim (side to dent is 45 degrees convex)
  CHECK(r.curves == 2);
  check_consistent(s, r);
}

TEST_CASE("features: a cube open on top has boundary curves split at the boundary corners") {
  TriSurface s = surface_from_soup(voxel_soup({{0, 0, 0}}, 2, 1.0, {{0, 2, 1}}));  // voxel 0's +z face open
  const FeatureReport r = detect_features(s, {});
  CHECK(r.boundary_edges == 8);
  CHECK(r.ridges_convex == 16);  // 4 bottom and 4 vertical cube edges
  CHECK(r.ridges_concave == 0);
  // Each top vertex joins two boundary edges and a vertical ridge: a BoundaryCorner, which splits
  // the boundary loop into its 4 sides.
  CHECK(r.corners_boundary == 4);
  CHECK(r.corners_convex == 4);
  CHECK(r.curves == 4 + 8);
  const CurveShapes shapes = check_consistent(s, r);
  CHECK(shapes.open == 12);
  CHECK(shapes.closed == 0);
  int boundary_curves = 0;
  for (const auto& path : feature_curves(s)) {
    const auto e = s.mesh.edge_handle(s.mesh.find_halfedge(path[0], path[1]));
    if (s.mesh.property(s.edge_feature, e) != EdgeFeature::Boundary) continue;
    ++boundary_curves;
    CHECK(path.size() == 3);
    for (const auto v : path) CHECK(s.mesh.point(v).z() == 1);
  }
  CHECK(boundary_curves == 4);
}

TEST_CASE("features: a fold just below the ridge angle is smooth, just above it a ridge of the right sign") {
  const FeatureOptions options;  // 30 degrees
  for (const double sign : {1.0, -1.0}) {
    CAPTURE(sign);
    TriSurface below = surface_from_soup(folded_sheet(sign * 29.99));
    const FeatureReport rb = detect_features(below, options);
    CHECK(rb.ridges_convex + rb.ridges_concave == 0);
    CHECK(rb.boundary_edges == 2 * 4 + 2 * 4);
    CHECK(rb.corners_boundary == 4);  // the sheet's corners; the fold's ends turn by < 45 degrees
    CHECK(rb.curves == 4);
    CHECK(check_consistent(below, rb).open == 4);

    TriSurface above = surface_from_soup(folded_sheet(sign * 30.01));
    const FeatureReport ra = detect_features(above, options);
    // Folding towards the normals' side is a valley (concave), away from it a crest (convex).
    CHECK(ra.ridges_concave == (sign > 0 ? 4u : 0u));
    CHECK(ra.ridges_convex == (sign > 0 ? 0u : 4u));
    CHECK(ra.corners_boundary == 6);  // plus the fold's ends, where the ridge meets the boundary
    CHECK(ra.corners_convex + ra.corners_concave + ra.corners_saddle == 0);
    CHECK(ra.curves == 6 + 1);
    CHECK(check_consistent(above, ra).open == 7);
  }
}

TEST_CASE("features: keep_existing keeps marked edges and their curve ids") {
  SUBCASE("a marked equator on a sphere") {
    TriSurface s = surface_from_soup(revolution_soup(sphere_profile(24), 48));
    const TriMesh& m = s.mesh;
    int marked = 0;
    for (const auto e : m.edges()) {
      const auto h = m.halfedge_handle(e, 0);
      if (std::abs(m.point(m.from_vertex_handle(h)).z()) < 1e-12 &&
          std::abs(m.point(m.to_vertex_handle(h)).z()) < 1e-12) {
        s.mesh.property(s.edge_curve, e) = 3;
        ++marked;
      }
    }
    REQUIRE(marked == 48);
    const FeatureReport r = detect_features(s, {.keep_existing = true});
    CHECK(r.ridges_convex == 48);  // kind from the geometry though the angle is small
    CHECK(r.curves == 1);
    const auto curves = feature_curves(s);
    REQUIRE(curves.size() == 4);
    CHECK(curves[3].size() == 49);
    CHECK(curves[3].front() == curves[3].back());
    check_consistent(s, r);
    // Without keep_existing the marks are dropped.
    const FeatureReport fresh = detect_features(s, {});
    CHECK(fresh.curves == 0);
    CHECK(fresh.ridges_convex == 0);
  }
  SUBCASE("a cube with one edge already on curve 0") {
    TriSurface s = surface_from_soup(voxel_soup({{0, 0, 0}}, 2));
    TriMesh& m = s.mesh;
    for (const auto e : m.edges()) {
      const auto h = m.halfedge_handle(e, 0);
      const Eigen::Vector3d a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h));
      if (a.x() == 0 && a.y() == 0 && b.x() == 0 && b.y() == 0) {
        m.property(s.edge_curve, e) = 0;
        m.property(s.edge_feature, e) = EdgeFeature::ConvexRidge;
      }
    }
    const FeatureReport r = detect_features(s, {.keep_existing = true});
    check_box_features(s);
    CHECK(feature_curves(s)[0].size() == 3);
    check_consistent(s, r);
  }
}

TEST_CASE("features: bad options are rejected and an empty surface has no features") {
  TriSurface s = surface_from_soup(voxel_soup({{0, 0, 0}}, 1));
  CHECK_THROWS_AS(detect_features(s, {.ridge_angle_deg = 0}), ConfigError);
  CHECK_THROWS_AS(detect_features(s, {.ridge_angle_deg = std::nan("")}), ConfigError);
  CHECK_THROWS_AS(detect_features(s, {.corner_defect_deg = 400}), ConfigError);
  CHECK_THROWS_AS(detect_features(s, {.curve_turn_deg = -1}), ConfigError);
  CHECK_THROWS_AS(detect_features(s, {.min_curve_length = -1}), ConfigError);
  const AnalyticBody box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.5);
  CHECK_THROWS_AS(detect_features(s, {.keep_existing = true, .reference = box.reference.get()}), ConfigError);
  TriSurface empty = surface_from_soup(TriangleSoup{});
  const FeatureReport r = detect_features(empty, {});
  CHECK(r.curves == 0);
  CHECK(feature_curves(empty).empty());
  // A curve id set by hand that is not a chain is reported, not walked forever.
  TriMesh& m = s.mesh;
  for (const auto e : m.edges()) m.property(s.edge_curve, e) = 0;
  CHECK_THROWS_AS(feature_curves(s), MesherError);
}


TEST_CASE("features: a rounded edge narrower than the mesh's scale is one ridge on its crest") {
  // A slab of thickness 2t with both long edges rounded (8 segments of 22.5 degrees: none a
  // ridge at 30), extruded along z over m cells and closed by flat caps.
  const double t = 0.002, length = 0.5;
  const int m = 6;
  const TriangleSoup soup = test::rounded_slab_soup(t, length, 10, m);
  // Spanwise ridge edges (not on the caps' rims), and whether they lie on a crest (y = 0).
  auto spanwise = [&](const TriSurface& s, std::size_t& on_crest) {
    std::size_t count = 0;
    on_crest = 0;
    for (const auto e : s.mesh.edges()) {
      const EdgeFeature f = s.mesh.property(s.edge_feature, e);
      if (f != EdgeFeature::ConvexRidge && f != EdgeFeature::ConcaveRidge) continue;
      const auto h = s.mesh.halfedge_handle(e, 0);
      const Eigen::Vector3d a = s.mesh.point(s.mesh.from_vertex_handle(h)), b = s.mesh.point(s.mesh.to_vertex_handle(h));
      if (std::abs(a.z() - b.z()) < 1e-12) continue;  // a rim edge of a flat cap
      ++count;
      if (std::abs(a.y()) < 1e-12 && std::abs(b.y()) < 1e-12) ++on_crest;
    }
    return count;
  };
  std::size_t crest = 0;
  TriSurface plain = surface_from_soup(soup);
  detect_features(plain, {});
  CHECK(spanwise(plain, crest) == 0);
  for (double r : {0.01, 0.05}) {
    CAPTURE(r);
    TriSurface s = surface_from_soup(soup);
    FeatureOptions o;
    o.crest_scale = r;
    const FeatureReport rep = detect_features(s, o);
    // One row of m edges per rounded edge, on its crest.
    CHECK(spanwise(s, crest) == static_cast<std::size_t>(2 * m));
    CHECK(crest == static_cast<std::size_t>(2 * m));
    CHECK(rep.ridges_concave == 0);
  }
  // A scale smaller than the cap sees no crest (the normals r across turn by under 30 degrees).
  TriSurface fine = surface_from_soup(soup);
  FeatureOptions o;
  o.crest_scale = 0.0002;
  detect_features(fine, o);
  CHECK(spanwise(fine, crest) == 0);
}

TEST_CASE("features: ridge curves shorter than min_curve_length are dropped, the corners found again") {
  // A plate 1 x 1 x 0.01: four ridges 0.01 long join its top and bottom faces' edges.
  AnalyticBody plate = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 0.01), 0.3);
  TriSurface all = plate.initial;
  const FeatureReport every = detect_features(all, {});
  CHECK(every.curves == 12);
  CHECK(every.corners_convex == 8);
  FeatureOptions o;
  o.min_curve_length = 0.05;
  const FeatureReport kept = detect_features(plate.initial, o);
  CHECK(kept.curves == 8);
  CHECK(kept.dropped_curves == 4);
  CHECK(every.dropped_curves == 0);
  CHECK(kept.ridges_convex == every.ridges_convex - 4);
  CHECK(kept.corners_convex == 8);  // the long edges turn by 90 degrees there
  check_consistent(plate.initial, kept);
  for (const auto& path : feature_curves(plate.initial))
    CHECK((plate.initial.mesh.point(path.front()) - plate.initial.mesh.point(path.back())).norm() == doctest::Approx(1.0));
}

TEST_CASE("features: judged on the body, a coarse sphere has none and a box its 12 ridges and 8 corners") {
  // Eight facets around: the latitude edges bend by 45 degrees, ridges by the mesh's dihedral.
  TriSurface coarse = surface_from_soup(revolution_soup(sphere_profile(4), 8));
  CHECK(detect_features(coarse, {}).ridges_convex > 0);
  const AnalyticBody sphere = make_sphere(Eigen::Vector3d::Zero(), 1.0, 0.5);
  FeatureOptions judged;
  judged.reference = sphere.reference.get();
  const FeatureReport on_sphere = detect_features(coarse, judged);
  CHECK(on_sphere.ridges_convex + on_sphere.ridges_concave == 0);
  CHECK(on_sphere.corners_convex + on_sphere.corners_concave + on_sphere.corners_saddle == 0);  // no defect rule
  CHECK(on_sphere.curves == 0);

  AnalyticBody box = make_box(Eigen::Vector3d(-1, -2, -0.5), Eigen::Vector3d(1, 2, 0.5), 0.3);
  judged.reference = box.reference.get();
  const FeatureReport on_box = detect_features(box.initial, judged);
  CHECK(on_box.ridges_concave == 0);
  CHECK(on_box.curves == 12);
  CHECK(on_box.corners_convex == 8);
  check_box_features(box.initial);
  check_consistent(box.initial, on_box);
}

// A flat fan from apex A whose far ends double back once: the needle (A, X2, Q) is inverted
// between its two neighbours (the published Orion capsule has one, 6 long and 0.003 wide). Its
// edges A-X2 and A-Q turn by 180 degrees but are no ridges: its normal is the triangulation's
// fold, not the body's (features.cpp, inverted_faces).
TEST_CASE("features: the edges of a needle inverted between its neighbours are no ridges") {
  TriangleSoup soup;
  soup.points = {{0, 0, 0}, {-1, 1, 0}, {-0.5, 1, 0}, {0, 1, 0}, {-0.25, 1, 0}, {0.5, 1, 0}, {1, 1, 0}};
  soup.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 6}};
  TriSurface s = surface_from_soup(soup);
  const FeatureReport r = detect_features(s, FeatureOptions{});
  CHECK(r.ridges_convex + r.ridges_concave == 0);
  // Without the inverted needle the fan is flat, and the same detection finds no ridge either;
  // with it made a real crease (its far vertex lifted, not doubled back), its edges are ridges.
  soup.points[4] = {0.25, 1, 0.8};
  TriSurface lifted = surface_from_soup(soup);
  const FeatureReport rl = detect_features(lifted, FeatureOptions{});
  CHECK(rl.ridges_convex + rl.ridges_concave > 0);
}

}  // namespace
}  // namespace plaf
