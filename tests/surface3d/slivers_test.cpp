// SPDX-License-Identifier: MIT
#include "surface3d/slivers.h"

#include <doctest/doctest.h>

#include <string>

#include "modules/base/error.h"
#include "surface3d/validate.h"
#include "tests/surface3d/test_surfaces.h"

namespace plaf {
namespace {

using Eigen::Vector3d;

// The unit cube, outward, two triangles per face, with the top face's (z = 1) triangles given.
TriangleSoup cube_with_top(std::vector<Vector3d> extra, std::vector<std::array<int, 3>> top) {
  TriangleSoup s;
  s.source = "cube";
  for (int k = 0; k < 8; ++k) s.points.push_back(Vector3d(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  for (const Vector3d& x : extra) s.points.push_back(x);
  const int quads[5][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}};
  for (const auto& q : quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  for (const auto& t : top) s.triangles.push_back(t);
  return s;
}

double volume(const TriSurface& s) {
  double v = 0;
  for (const auto f : s.mesh.faces()) {
    const auto x = s.face_vertices(f);
    v += s.mesh.point(x[0]).dot(s.mesh.point(x[1]).cross(s.mesh.point(x[2]))) / 6;
  }
  return v;
}

double thinnest(const TriSurface& s) {
  double r = 1;
  for (const auto f : s.mesh.faces()) {
    const auto x = s.face_vertices(f);
    r = std::min(r, sliver_ratio(s.mesh.point(x[0]), s.mesh.point(x[1]), s.mesh.point(x[2])));
  }
  return r;
}

// The unit square (z = 0, open) with point q = 4 just above the diagonal a - c (0 - 2), near a:
// the needle (a, q, c) lies face down over (a, c, d), every face across its edges face up.
TriangleSoup folded_square() {
  TriangleSoup soup;
  soup.source = "square";
  soup.points = {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(1, 1, 0), Vector3d(0, 1, 0), Vector3d(0.01, 0.0101, 0)};
  soup.triangles = {{0, 1, 4}, {1, 2, 4}, {0, 4, 2}, {0, 2, 3}};
  return soup;
}

SurfaceCheckOptions keep_slivers() {
  SurfaceCheckOptions o;
  o.repair_slivers = false;
  return o;
}

TEST_CASE("slivers: a needle on a cube's edge is collapsed into the corner, the cube unchanged") {
  // Point 8 sits 1e-4 from the top corner 4 = (0, 0, 1) on the edge to 5 = (1, 0, 1): the side
  // face y = 0 and the top face each get a needle along that edge.
  TriangleSoup soup = cube_with_top({Vector3d(1e-4, 0, 1)}, {{8, 5, 7}, {4, 8, 7}, {4, 7, 6}});
  // The side face's triangle (0, 5, 4) split at point 8.
  for (auto& t : soup.triangles)
    if (t == std::array<int, 3>{0, 5, 4}) t = {0, 5, 8};
  soup.triangles.push_back({0, 8, 4});
  TriSurface s = validate_surface(soup, keep_slivers());
  REQUIRE(thinnest(s) < 1e-3);
  const double v0 = volume(s);
  const long chi = s.euler_characteristic();
  const SliverRepairReport r = repair_slivers(s);
  CHECK(r.found == 2);
  CHECK(r.collapsed == 1);
  CHECK(r.left == 0);
  CHECK(r.max_moved < 1e-12);  // the point was on the edge
  CHECK(thinnest(s) >= 1e-3);
  CHECK(s.mesh.n_vertices() == 8);
  CHECK(s.euler_characteristic() == chi);
  CHECK(volume(s) == doctest::Approx(v0).epsilon(1e-12));
  CHECK(volume(s) == doctest::Approx(1).epsilon(1e-12));
}

TEST_CASE("slivers: a cap over the top face's diagonal gets its long edge flipped, in the plane") {
  // Point 8 lies 1e-5 from the midpoint of the diagonal 4 - 7 toward corner 5: (7, 4, 8) is a cap.
  const Vector3d q = Vector3d(0.5, 0.5, 1) + 1e-5 * Vector3d(1, -1, 0).normalized();
  TriangleSoup soup = cube_with_top({q}, {{4, 5, 8}, {5, 7, 8}, {7, 4, 8}, {4, 7, 6}});
  TriSurface s = validate_surface(soup, keep_slivers());
  const SliverRepairReport r = repair_slivers(s);
  CHECK(r.found == 1);
  CHECK(r.flipped == 1);
  CHECK(r.collapsed == 0);
  CHECK(r.left == 0);
  CHECK(r.max_moved < 2e-5);
  CHECK(thinnest(s) >= 1e-3);
  CHECK(s.mesh.n_vertices() == 9);
  CHECK(volume(s) == doctest::Approx(1).epsilon(1e-12));
}

TEST_CASE("slivers: an operation that would move the surface by more than the bound is not made") {
  // The folded needle, whose repair moves the surface by 7e-5 (q's distance to the new face),
  // against a bound of 1e-5 of the square's diagonal (1.4e-5).
  const TriangleSoup soup = folded_square();
  TriSurface s = surface_from_soup(soup);
  const SliverRepairReport r = repair_slivers(s, kSliverRatio, 1e-5);
  CHECK(r.found == 1);
  CHECK(r.collapsed + r.flipped == 0);
  CHECK(r.left == 1);
  CHECK(s.mesh.n_faces() == 4);
  TriSurface t = surface_from_soup(soup);
  CHECK(repair_slivers(t, kSliverRatio, 1e-4).collapsed == 1);  // (1.4e-4: made)
}

TEST_CASE("slivers: a narrow face of the body's own between two sharp edges stays") {
  // A wedge 1e-4 thick at its blunt end, 1 long and 10 wide: the blunt base x = 1 is a strip of
  // two needles at right angles to the faces beside it (a blunt trailing edge's base on a long
  // wing), not a sliver of the tessellation.
  TriangleSoup soup;
  soup.source = "wedge";
  const double t = 1e-4, w = 10;
  soup.points = {Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(1, 0, t), Vector3d(0, w, 0), Vector3d(1, w, 0),
                 Vector3d(1, w, t)};
  soup.triangles = {{0, 2, 1}, {3, 4, 5},             // the ends y = 0 and y = w
                    {0, 1, 4}, {0, 4, 3},             // the bottom z = 0
                    {0, 3, 5}, {0, 5, 2},             // the top, sloping to the blunt base
                    {1, 2, 5}, {1, 5, 4}};            // the blunt base x = 1
  TriSurface s = validate_surface(soup, keep_slivers());
  const double v0 = volume(s);
  const SliverRepairReport r = repair_slivers(s);
  CHECK(r.found >= 2);
  CHECK(r.collapsed == 0);
  CHECK(r.flipped == 0);
  CHECK(r.left == r.found);
  CHECK(volume(s) == doctest::Approx(v0).epsilon(1e-12));
}

TEST_CASE("slivers: a needle folded back over the sheet is repaired, whatever its angle") {
  const TriangleSoup soup = folded_square();
  TriSurface s = surface_from_soup(soup);
  const SliverRepairReport r = repair_slivers(s);
  CHECK(r.found == 1);
  CHECK(r.collapsed == 1);
  CHECK(r.left == 0);
  CHECK(r.max_moved < 1e-4);  // q's distance to the new face (a, b, c)
  CHECK(s.mesh.n_faces() == 2);
  for (const auto f : s.mesh.faces()) {
    const auto x = s.face_vertices(f);
    CHECK((s.mesh.point(x[1]) - s.mesh.point(x[0])).cross(s.mesh.point(x[2]) - s.mesh.point(x[0])).z() > 0);
  }
}

TEST_CASE("slivers: validation repairs them by default, with a repair line, and keeps them on request") {
  TriangleSoup soup = cube_with_top({Vector3d(1e-4, 0, 1)}, {{8, 5, 7}, {4, 8, 7}, {4, 7, 6}});
  for (auto& t : soup.triangles)
    if (t == std::array<int, 3>{0, 5, 4}) t = {0, 5, 8};
  soup.triangles.push_back({0, 8, 4});
  SurfaceCheckReport rep;
  const TriSurface s = validate_surface(soup, SurfaceCheckOptions{}, &rep);
  CHECK(rep.slivers_found == 2);
  CHECK(rep.slivers_left == 0);
  CHECK(s.mesh.n_vertices() == 8);
  REQUIRE(!rep.repairs.empty());
  CHECK(rep.repairs.back().find("cube: 2 sliver triangles") == 0);
  CHECK(rep.repairs.back().find("1 short edge collapsed, 0 long edges flipped") != std::string::npos);
  SurfaceCheckReport kept;
  const TriSurface k = validate_surface(soup, keep_slivers(), &kept);
  CHECK(k.mesh.n_vertices() == 9);
  CHECK(kept.slivers_found == 2);  // (counted, not repaired)
  CHECK(kept.slivers_left == 2);
  // A clean body: nothing found, nothing said.
  SurfaceCheckReport clean;
  const TriSurface sphere = validate_surface(test::icosphere_soup(3), SurfaceCheckOptions{}, &clean);
  CHECK(clean.slivers_found == 0);
  CHECK(clean.repairs.empty());
}

}  // namespace
}  // namespace plaf
