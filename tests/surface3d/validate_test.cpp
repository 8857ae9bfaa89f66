// SPDX-License-Identifier: MIT
#include "surface3d/validate.h"
#include "tests/surface3d/test_surfaces.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "modules/base/error.h"
#include "surface3d/features.h"

namespace plaf {
namespace {

using Eigen::Vector3d;

TriangleSoup tetrahedron(const Vector3d& o = Vector3d::Zero(), double h = 1) {
  TriangleSoup s;
  s.source = "tet";
  s.points = {o, o + Vector3d(h, 0, 0), o + Vector3d(0, h, 0), o + Vector3d(0, 0, h)};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  return s;
}

// The cube [lo, lo + h]^3, outward; faces in the order -x, +x, -y, +y, -z, +z (two triangles each).
TriangleSoup cube(const Vector3d& lo = Vector3d::Zero(), double h = 1) {
  TriangleSoup s;
  s.source = "cube";
  for (int k = 0; k < 8; ++k) s.points.push_back(lo + h * Vector3d(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  // Point k = (x, y, z) bits; each quad counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  return s;
}

TriangleSoup icosphere(int m) { return test::icosphere_soup(m); }

TriangleSoup merged(TriangleSoup a, const TriangleSoup& b) {
  const int off = static_cast<int>(a.points.size());
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  return a;
}

TriangleSoup flipped(TriangleSoup s) {
  for (auto& t : s.triangles) std::swap(t[1], t[2]);
  return s;
}

TriangleSoup without(TriangleSoup s, std::initializer_list<int> drop) {
  std::vector<std::array<int, 3>> kept;
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    if (std::find(drop.begin(), drop.end(), static_cast<int>(t)) == drop.end()) kept.push_back(s.triangles[t]);
  s.triangles = kept;
  return s;
}

// Every face's normal points away from the given centre.
bool outward_from(const TriSurface& s, const Vector3d& centre) {
  for (const auto f : s.mesh.faces()) {
    const auto v = s.face_vertices(f);
    const Vector3d a = s.mesh.point(v[0]), b = s.mesh.point(v[1]), c = s.mesh.point(v[2]);
    if ((b - a).cross(c - a).dot((a + b + c) / 3 - centre) <= 0) return false;
  }
  return true;
}

TEST_CASE("validate: closed tetrahedron, cube and icosphere pass unchanged with chi = 2") {
  SurfaceCheckOptions opt;
  opt.wall_tag = "body";
  SurfaceCheckReport rep;
  const TriSurface tet = validate_surface(tetrahedron(), opt, &rep);
  CHECK(tet.mesh.n_faces() == 4);
  CHECK(rep.euler_characteristic == 2);
  CHECK(rep.volume == doctest::Approx(1.0 / 6));
  CHECK(rep.repairs.empty());
  CHECK(rep.components == 1);

  for (const double h : {1e-8, 1.0, 1e8}) {
    CAPTURE(h);
    const TriSurface c = validate_surface(cube(Vector3d::Constant(3 * h), h), opt, &rep);
    CHECK(c.mesh.n_faces() == 12);
    CHECK(c.mesh.n_vertices() == 8);
    CHECK(rep.euler_characteristic == 2);
    CHECK(rep.volume == doctest::Approx(h * h * h));
    CHECK(rep.repairs.empty());
    CHECK(rep.boundary_loops == 0);
    CHECK(rep.symmetry_edges == 0);
    CHECK(rep.self_intersection_pairs_tested > 0);
    REQUIRE(c.tags.size() == 1);
    CHECK(c.tags[0].name == "body");
    CHECK(c.tags[0].kind == BoundaryKind::Wall);
    for (const auto e : c.mesh.edges()) {
      CHECK(c.mesh.property(c.edge_tag, e) == -1);
      CHECK(c.mesh.property(c.edge_curve, e) == -1);
    }
    CHECK(outward_from(c, Vector3d::Constant(3.5 * h)));
  }

  const TriangleSoup ball = icosphere(6);
  const TriSurface s = validate_surface(ball, opt, &rep);
  CHECK(s.mesh.n_faces() == 720);
  CHECK(rep.euler_characteristic == 2);
  CHECK(rep.volume < 4 * std::numbers::pi / 3);
  CHECK(rep.volume > 0.95 * 4 * std::numbers::pi / 3);
  CHECK(count_self_intersections(s) == 0);
}

TEST_CASE("validate: repeated-vertex and duplicate triangles are dropped and counted") {
  TriangleSoup s = cube();
  s.triangles.push_back({0, 0, 5});  // repeated vertex
  s.triangles.push_back({3, 3, 3});  // all the same
  s.triangles.push_back({0, 6, 4});  // a copy of triangle 0 reversed
  s.triangles.push_back({0, 4, 6});  // a copy of triangle 0
  s.triangles.push_back({7, 5, 1});  // a copy of triangle 3 rotated
  SurfaceCheckReport rep;
  const TriSurface out = validate_surface(s, {}, &rep);
  CHECK(out.mesh.n_faces() == 12);
  CHECK(rep.input_triangles == 17);
  CHECK(rep.dropped_degenerate == 2);
  CHECK(rep.dropped_duplicate == 3);
  REQUIRE(rep.repairs.size() == 2);
  CHECK(rep.repairs[0].find("2 triangles with a repeated vertex (first: triangle 12)") != std::string::npos);
  CHECK(rep.repairs[1].find("3 duplicate triangles (first: triangle 14, a copy of triangle 0)") != std::string::npos);
  CHECK(rep.euler_characteristic == 2);
  CHECK(rep.flipped_inconsistent == 0);
}

TEST_CASE("validate: zero-area, non-manifold edge and bow-tie vertex are errors naming the first") {
  TriangleSoup zero = cube();
  zero.points.push_back({0.5, 0, 0});
  zero.triangles.push_back({0, 1, 8});  // three distinct collinear points
  CHECK_THROWS_WITH_AS(validate_surface(zero, {}),
                       "cube: 1 triangle with zero area (three distinct collinear points); first: triangle 12 at "
                       "(0.5, 0, 0)",
                       InputError);

  TriangleSoup fin = cube();
  fin.points.push_back({0.5, -1, -1});
  fin.triangles.push_back({0, 1, 8});  // a third triangle on edge (0, 1)
  CHECK_THROWS_WITH_AS(validate_surface(fin, {}), doctest::Contains("1 non-manifold edge"), InputError);

  // Two tetrahedra touching at one vertex: two fans there.
  const TriangleSoup bowtie = merged(tetrahedron(), tetrahedron(Vector3d(1, 0, 0)));
  TriangleSoup shared = bowtie;
  for (auto& t : shared.triangles)
    for (int& v : t)
      if (v == 4) v = 1;  // the second tetrahedron's origin is the first one's point 1
  CHECK_THROWS_WITH_AS(validate_surface(shared, {}),
                       doctest::Contains("1 non-manifold vertex (triangles around it form more than one fan); first: "
                                         "point 1 at (1, 0, 0)"),
                       InputError);
}

TEST_CASE("validate: a flipped triangle is turned back and an inward surface is turned out") {
  TriangleSoup s = cube();
  std::swap(s.triangles[5][0], s.triangles[5][1]);
  SurfaceCheckReport rep;
  TriSurface out = validate_surface(s, {}, &rep);
  CHECK(rep.flipped_inconsistent == 1);
  CHECK(rep.flipped_inward == 0);
  CHECK(rep.volume == doctest::Approx(1));
  CHECK(outward_from(out, Vector3d::Constant(0.5)));
  CHECK(rep.repairs.size() == 1);

  // Flipping triangle 0 alone makes the other eleven disagree with the first: they flip, then
  // the whole component is inward and flips back.
  TriangleSoup t = cube();
  std::swap(t.triangles[0][0], t.triangles[0][1]);
  out = validate_surface(t, {}, &rep);
  CHECK(rep.flipped_inconsistent == 11);
  CHECK(rep.flipped_inward == 12);
  CHECK(outward_from(out, Vector3d::Constant(0.5)));

  const TriangleSoup ball = flipped(icosphere(4));
  out = validate_surface(ball, {}, &rep);
  CHECK(rep.flipped_inconsistent == 0);
  CHECK(rep.flipped_inward == ball.triangles.size());
  CHECK(rep.volume > 3.9);
  CHECK(outward_from(out, Vector3d::Zero()));
}

TEST_CASE("validate: a symmetry plane must hold the cut of a half model that lies on one side of it") {
  // Issue 37, item 8: a plane crossing or missing a closed body was accepted without a word.
  SurfaceCheckOptions opt;
  opt.symmetry_planes = {{Vector3d(0, 0, 1), 3.5}};  // through the closed cube [3, 4]^3
  CHECK_THROWS_WITH_AS(validate_surface(cube(Vector3d::Constant(3)), opt),
                       doctest::Contains("symmetry plane 0 (geometry.symmetry_planes[0]: normal (0, 0, 1), offset 3.5) "
                                         "holds none of the surface's open edges (the surface is closed)"),
                       InputError);
  opt.symmetry_planes = {{Vector3d(0, 0, 1), 9}};  // beside it
  CHECK_THROWS_WITH_AS(validate_surface(cube(Vector3d::Constant(3)), opt), doctest::Contains("holds none"), InputError);
  // The cube open at x = 3 on its plane, and a second plane through the hole's edge at y = 3 that
  // cuts the cube diagonally: y = x holds that edge, the cube reaches 1 beyond it on both sides.
  const TriangleSoup open = without(cube(Vector3d::Constant(3)), {0, 1});
  opt.symmetry_planes = {{Vector3d(-1, 0, 0), -3}, {Vector3d(-1, 1, 0), 0}};
  CHECK_THROWS_WITH_AS(validate_surface(open, opt), doctest::Contains("the surface lies on both sides of symmetry plane 1"),
                       InputError);
}

TEST_CASE("validate: an open cube needs a symmetry plane, and the half model comes out outward") {
  // The face x = 3 of the cube [3, 4]^3 removed (triangles 0, 1).
  const TriangleSoup open = without(cube(Vector3d::Constant(3)), {0, 1});
  CHECK_THROWS_WITH_AS(validate_surface(open, {}),
                       "cube: 1 open boundary loop not on a symmetry plane; first: a loop of 4 edges through (3, 3, 4)",
                       InputError);
  SurfaceCheckOptions opt;
  opt.symmetry_planes = {{Vector3d(0, 0, 1), 3}};  // a plane, but not that of the hole
  CHECK_THROWS_WITH_AS(validate_surface(open, opt), doctest::Contains("open boundary loop"), InputError);

  // The plane of the hole is x = 3: away from the origin, so a volume about the origin would be
  // wrong; both orientations come out outward with volume 1.
  opt.symmetry_planes = {{Vector3d(0, 0, 1), 3}, {Vector3d(-2, 0, 0), -6}};
  for (const bool inward : {false, true}) {
    CAPTURE(inward);
    SurfaceCheckReport rep;
    const TriSurface s = validate_surface(inward ? flipped(open) : open, opt, &rep);
    CHECK(rep.volume == doctest::Approx(1));
    CHECK(rep.flipped_inward == (inward ? 10u : 0u));
    CHECK(rep.boundary_loops == 1);
    CHECK(rep.symmetry_edges == 4);
    CHECK(rep.euler_characteristic == 1);
    CHECK(outward_from(s, Vector3d::Constant(3.5)));
    REQUIRE(s.tags.size() == 2);
    CHECK(s.tags[1].name == "symmetry");
    CHECK(s.tags[1].kind == BoundaryKind::Symmetry);
    int tagged = 0;
    for (const auto e : s.mesh.edges()) {
      const bool boundary = s.mesh.is_boundary(e);
      CHECK(s.mesh.property(s.edge_tag, e) == (boundary ? 1 : -1));
      CHECK((s.mesh.property(s.edge_feature, e) == EdgeFeature::Boundary) == boundary);
      CHECK(s.mesh.property(s.edge_curve, e) == -1);
      tagged += boundary ? 1 : 0;
    }
    CHECK(tagged == 4);
    for (const auto f : s.mesh.faces()) CHECK(s.mesh.property(s.face_tag, f) == 0);
  }

  // A quarter model: the faces x = 3 and y = 3 removed, one loop over two planes.
  const TriangleSoup quarter = without(cube(Vector3d::Constant(3)), {0, 1, 4, 5});
  opt.symmetry_planes = {{Vector3d(1, 0, 0), 3}, {Vector3d(0, 1, 0), 3}};
  for (const bool inward : {false, true}) {
    SurfaceCheckReport rep;
    const TriSurface s = validate_surface(inward ? flipped(quarter) : quarter, opt, &rep);
    CHECK(rep.volume == doctest::Approx(1));
    CHECK(rep.boundary_loops == 1);
    CHECK(rep.symmetry_edges == 6);
    CHECK(outward_from(s, Vector3d::Constant(3.5)));
  }
}

TEST_CASE("validate: disjoint bodies pass, nested ones are an error or dropped") {
  SurfaceCheckReport rep;
  const TriangleSoup two = merged(cube(), cube(Vector3d(2, 0.5, 0.25)));
  const TriSurface s = validate_surface(two, {}, &rep);
  CHECK(rep.components == 2);
  CHECK(rep.volume == doctest::Approx(2));
  CHECK(rep.euler_characteristic == 4);
  CHECK(s.mesh.n_faces() == 24);

  // A small cube inside a large one (given first), inward as a cavity would be.
  const TriangleSoup nested = merged(cube(Vector3d::Constant(-1), 3), flipped(cube(Vector3d::Constant(0.25), 0.5)));
  SurfaceCheckOptions strict;
  strict.drop_inner_components = false;
  CHECK_THROWS_WITH_AS(validate_surface(nested, strict), doctest::Contains("1 component inside another"), InputError);
  const TriSurface big = validate_surface(nested, {}, &rep);  // dropped by default
  CHECK(rep.dropped_inner == 12);
  CHECK(rep.components == 1);
  CHECK(big.mesh.n_faces() == 12);
  CHECK(big.mesh.n_vertices() == 8);
  CHECK(rep.volume == doctest::Approx(27));
  CHECK(rep.euler_characteristic == 2);
  CHECK(outward_from(big, Vector3d::Constant(0.5)));

  // A body beside an open half model is not inside it.
  SurfaceCheckOptions half;
  half.symmetry_planes = {{Vector3d(0, 0, 1), 0}};
  const TriangleSoup beside = merged(without(cube(Vector3d(0, 0, 0), 2), {8, 9}), cube(Vector3d(0.5, 0.5, 5)));
  validate_surface(beside, half, &rep);
  CHECK(rep.components == 2);
  // A closed body inside the half model is.
  const TriangleSoup inside = merged(without(cube(Vector3d(0, 0, 0), 2), {8, 9}), cube(Vector3d(0.5, 0.5, 0.5)));
  half.drop_inner_components = false;
  CHECK_THROWS_WITH_AS(validate_surface(inside, half), doctest::Contains("inside another"), InputError);
}

TEST_CASE("validate: a folded sliver cap is flipped over its long edge, the rest of a fold stays an error") {
  // The cube's top face (4, 5, 7), (4, 7, 6) with a point m inserted on the diagonal 4-7 but just
  // across it, toward 6: the cap (7, 4, m) folds over (4, 7, 6) and the fan around m with it (a
  // CAD tessellation's defect, the published Orion capsule's five).
  TriangleSoup fold = without(cube(), {10, 11});
  fold.points.push_back({0.495, 0.505, 1});  // point 8, 0.007 across the diagonal
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{{7, 4, 8}, {4, 5, 8}, {5, 7, 8}, {4, 7, 6}})
    fold.triangles.push_back(t);
  SurfaceCheckOptions check;
  check.repair_folded_caps = false;
  CHECK_THROWS_WITH_AS(validate_surface(fold, check), doctest::Contains("self-intersecting triangle pair"), InputError);
  SurfaceCheckReport rep;
  const TriSurface s = validate_surface(fold, {}, &rep);
  REQUIRE(rep.repairs.size() == 1);
  MESSAGE(rep.repairs[0]);
  CHECK(rep.repairs[0].find("1 folded sliver triangle") == 0);
  CHECK(rep.repairs[0].find("moved by at most 0.00707107") != std::string::npos);
  CHECK(count_self_intersections(s) == 0);
  CHECK(s.mesh.n_faces() == fold.triangles.size());
  CHECK(s.euler_characteristic() == 2);
  CHECK(rep.volume == doctest::Approx(1.0));
  // A fold that is no cap (the fan's centre pushed well past the edge) is not touched.
  TriangleSoup far = without(cube(), {10, 11});
  far.points.push_back({0.5, -0.5, 1});
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{{4, 5, 8}, {5, 7, 8}, {7, 6, 8}, {6, 4, 8}})
    far.triangles.push_back(t);
  CHECK_THROWS_WITH_AS(validate_surface(far, {}), doctest::Contains("self-intersecting triangle pair"), InputError);
}

// The same cap lifted 0.001 off the top face: it crosses nothing (the pairs sharing its edges are
// not coplanar), but it is back to back with the three triangles across its edges (the published
// Orion capsule's eight, in a wedge of the sheet or a fan that doubles back). Left, its tip's
// normal is no body's and the remesher may keep it as a fold; repaired, it is flipped.
TEST_CASE("validate: a folded cap back to back with the surface all around is flipped though it crosses nothing") {
  TriangleSoup fold = without(cube(), {10, 11});
  fold.points.push_back({0.495, 0.505, 1.001});  // point 8, 0.007 across the diagonal 4-7
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{{7, 4, 8}, {4, 5, 8}, {5, 7, 8}, {4, 7, 6}})
    fold.triangles.push_back(t);
  SurfaceCheckOptions check;
  check.repair_folded_caps = false;
  SurfaceCheckReport rep;
  const TriSurface kept = validate_surface(fold, check, &rep);
  CHECK(rep.repairs.empty());
  CHECK(kept.mesh.n_faces() == fold.triangles.size());
  const TriSurface s = validate_surface(fold, {}, &rep);
  REQUIRE(rep.repairs.size() == 1);
  MESSAGE(rep.repairs[0]);
  CHECK(rep.repairs[0].find("1 folded sliver triangle (a cap over its long edge, back to back") == 0);
  CHECK(s.euler_characteristic() == 2);
  // No face is turned against all its neighbours any more.
  for (const char inverted : inverted_faces(s.mesh)) CHECK(inverted == 0);
}

TEST_CASE("validate: interpenetrating bodies and a folded surface are self-intersections") {
  const TriangleSoup two = merged(tetrahedron(), tetrahedron(Vector3d(0.2, 0.2, 0.2)));
  CHECK_THROWS_WITH_AS(validate_surface(two, {}), doctest::Contains("self-intersecting triangle pair"), InputError);
  SurfaceCheckOptions off;
  off.check_self_intersections = false;
  SurfaceCheckReport rep;
  const TriSurface s = validate_surface(two, off, &rep);
  CHECK(rep.self_intersection_pairs_tested == 0);
  std::string first;
  CHECK(count_self_intersections(s, &first) > 0);
  CHECK(first.find("near (") != std::string::npos);

  // A cube whose top face is fanned from a centre point pushed out past the edge y = 0, in the
  // plane: the triangle on that edge folds back over its neighbours.
  TriangleSoup fold = without(cube(), {10, 11});
  fold.points.push_back({0.5, -0.5, 1});  // point 8
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{{4, 5, 8}, {5, 7, 8}, {7, 6, 8}, {6, 4, 8}})
    fold.triangles.push_back(t);
  CHECK_THROWS_WITH_AS(validate_surface(fold, {}), doctest::Contains("self-intersecting triangle pair"), InputError);
  // With the centre inside the face, the same fan is fine.
  fold.points.back() = {0.5, 0.4, 1};
  CHECK_NOTHROW(validate_surface(fold, {}));
  // Lifting the centre out of the plane removes the fold too (a tent over the edge).
  fold.points.back() = {0.5, -0.5, 1.5};
  CHECK_NOTHROW(validate_surface(fold, {}));

  // Two cubes touching along an edge line (distinct vertices): separate components that meet.
  const TriangleSoup touching = merged(cube(), cube(Vector3d(1, 1, 0)));
  CHECK_THROWS_WITH_AS(validate_surface(touching, {}), doctest::Contains("self-intersecting"), InputError);
}

// count_self_intersections on a two-triangle surface u v w1, v u w2.
std::size_t pair_count(const Vector3d& w1, const Vector3d& w2) {
  TriangleSoup s;
  s.points = {{0, 0, 0}, {1, 0, 0}, w1, w2};
  s.triangles = {{0, 1, 2}, {1, 0, 3}};
  return count_self_intersections(surface_from_soup(s));
}

// ... and on u a1 b1, u a2 b2 sharing only u.
std::size_t vertex_pair_count(const Vector3d& a1, const Vector3d& b1, const Vector3d& a2, const Vector3d& b2) {
  TriangleSoup s;
  s.points = {{0, 0, 0}, a1, b1, a2, b2};
  s.triangles = {{0, 1, 2}, {0, 3, 4}};
  return count_self_intersections(surface_from_soup(s));
}

// self_intersecting_pairs names the faces: three triangles, the third through the first only.
TEST_CASE("validate: self_intersecting_pairs lists the crossing faces by index") {
  TriangleSoup s;
  s.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 0}, {6, 5, 0}, {5, 6, 0}, {0.2, 0.2, -1}, {0.3, 0.2, 1}, {0.2, 0.3, 1}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}};
  const TriSurface surface = surface_from_soup(s);
  const std::vector<std::pair<int, int>> pairs = self_intersecting_pairs(surface);
  REQUIRE(pairs.size() == 1);
  CHECK(std::min(pairs[0].first, pairs[0].second) == 0);
  CHECK(std::max(pairs[0].first, pairs[0].second) == 2);
  CHECK(count_self_intersections(surface) == 1);
}

TEST_CASE("validate: neighbours intersect only beyond what they share") {
  // Sharing an edge: a fold (coplanar, same side) intersects; flat, bent or opposite do not.
  CHECK(pair_count({0.5, 1, 0}, {0.3, 0.5, 0}) == 1);
  CHECK(pair_count({0.5, 1, 0}, {3, 2, 0}) == 1);  // the far vertices' triangles still overlap
  CHECK(pair_count({0.5, 1, 0}, {0.3, -0.5, 0}) == 0);
  CHECK(pair_count({0.5, 1, 0}, {0.3, 0.5, 1e-12}) == 0);
  CHECK(pair_count({0.5, 1, 0}, {0.3, 0.5, -1e-12}) == 0);
  // Sharing a vertex: coplanar overlap, one edge piercing the other, or touching only at u.
  CHECK(vertex_pair_count({1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, 2, 0}) == 1);
  CHECK(vertex_pair_count({1, 0, 0}, {0, 1, 0}, {1, 0.2, -1}, {1, 0.2, 1}) == 1);
  CHECK(vertex_pair_count({1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}) == 0);
  CHECK(vertex_pair_count({1, 0, 0}, {0, 1, 0}, {1, 1, 1}, {2, 0, 1}) == 0);
  CHECK(vertex_pair_count({1, 0, 0}, {0, 1, 0}, {0.5, 0.5, 0}, {1, 1, 1}) == 1);  // a vertex on the edge
}

TEST_CASE("validate: a Moebius band is non-orientable") {
  TriangleSoup band;
  band.source = "band";
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    const Vector3d centre(std::cos(a), std::sin(a), 0);
    // The strip's cross-direction turns by half a turn around the loop.
    const Vector3d across = 0.3 * (std::cos(a / 2) * centre + std::sin(a / 2) * Vector3d::UnitZ());
    band.points.push_back(centre - across);
    band.points.push_back(centre + across);
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    // After the last segment the strip comes back upside down: its sides swap.
    const int c = i + 1 < n ? 2 * i + 2 : 1, d = i + 1 < n ? 2 * i + 3 : 0;
    band.triangles.push_back({a, c, d});
    band.triangles.push_back({a, d, b});
  }
  CHECK_THROWS_WITH_AS(validate_surface(band, {}), doctest::Contains("is non-orientable"), InputError);
}

TEST_CASE("validate: unusable soups are one-line errors") {
  TriangleSoup s = cube();
  s.triangles.push_back({0, 1, 99});
  CHECK_THROWS_WITH_AS(validate_surface(s, {}), "cube: triangle 12 refers to point 99 but there are 8 points",
                       InputError);
  s = cube();
  s.points[3].x() = std::nan("");
  CHECK_THROWS_WITH_AS(validate_surface(s, {}), doctest::Contains("point 3 has a non-finite coordinate"), InputError);
  s.triangles.clear();
  CHECK_THROWS_WITH_AS(validate_surface(s, {}), "cube: the surface has no triangles", InputError);
  s = cube();
  s.triangles = {{0, 0, 1}, {2, 3, 3}};
  CHECK_THROWS_WITH_AS(validate_surface(s, {}), "cube: no triangles left after dropping the degenerate ones",
                       InputError);
  // A closed flat pillow: two triangulations of one square, back to back.
  TriangleSoup pillow;
  pillow.source = "pillow";
  pillow.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  pillow.triangles = {{0, 1, 3}, {0, 3, 2}, {0, 2, 1}, {1, 2, 3}};
  CHECK_THROWS_WITH_AS(validate_surface(pillow, {}), doctest::Contains("encloses (near) zero volume"), InputError);
}

TEST_CASE("validate: a 100k-triangle sphere validates") {
  const TriangleSoup ball = icosphere(71);
  REQUIRE(ball.triangles.size() == 100820);
  const auto t0 = std::chrono::steady_clock::now();
  SurfaceCheckReport rep;
  const TriSurface s = validate_surface(ball, {}, &rep);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  MESSAGE("validate_surface on " << ball.triangles.size() << " triangles: " << seconds << " s, "
                                 << rep.self_intersection_pairs_tested << " pairs tested");
  CHECK(s.mesh.n_faces() == 100820);
  CHECK(rep.euler_characteristic == 2);
  CHECK(rep.volume == doctest::Approx(4 * std::numbers::pi / 3).epsilon(1e-3));
}

}  // namespace
}  // namespace plaf
