// SPDX-License-Identifier: MIT
// The 3D farfield surfaces (volume/farfield3d.h): closed, without duplicate nodes, inward, every
// edge under the size, enclosing what they must; bad sizes refused with the key named.
#include "volume/farfield3d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "modules/base/error.h"

using namespace plaf;
using namespace plaf::volume;
using Eigen::Vector3d;

namespace {

struct Measured {
  double volume = 0;  // signed: negative for inward normals
  double longest = 0;
  std::size_t duplicates = 0, open_edges = 0;
};

Measured measure(const FarfieldMesh3& m) {
  Measured r;
  std::map<std::pair<int, int>, int> edges;  // directed edge counts
  for (const auto& t : m.triangles) {
    const Vector3d &a = m.nodes[static_cast<std::size_t>(t[0])], &b = m.nodes[static_cast<std::size_t>(t[1])],
                   &c = m.nodes[static_cast<std::size_t>(t[2])];
    r.volume += a.dot(b.cross(c)) / 6;
    for (int k = 0; k < 3; ++k) {
      const int u = t[static_cast<std::size_t>(k)], v = t[static_cast<std::size_t>((k + 1) % 3)];
      ++edges[{u, v}];
      r.longest = std::max(r.longest, (m.nodes[static_cast<std::size_t>(u)] - m.nodes[static_cast<std::size_t>(v)]).norm());
    }
  }
  // Closed and consistently oriented: every directed edge once, its reverse once.
  for (const auto& [e, n] : edges)
    if (n != 1 || !edges.count({e.second, e.first})) ++r.open_edges;
  std::set<std::array<double, 3>> seen;
  for (const Vector3d& x : m.nodes)
    if (!seen.insert({x.x(), x.y(), x.z()}).second) ++r.duplicates;
  return r;
}

}  // namespace

TEST_CASE("farfield 3D: a sphere of radius r is closed, inward, its edges under h, its volume near 4/3 pi r^3") {
  const Vector3d lo(-1, -1, -1), hi(1, 1, 1);
  for (double h : {40.0, 10.0, 3.0}) {
    CAPTURE(h);
    FarfieldParams3 p;
    p.radius = 20;
    p.h = h;
    p.has_center = true;
    p.center = Vector3d(0.5, 0, -0.25);
    const FarfieldMesh3 m = make_farfield(p, lo, hi);
    const Measured r = measure(m);
    CHECK(r.open_edges == 0);
    CHECK(r.duplicates == 0);
    CHECK(r.longest <= h);
    for (const Vector3d& x : m.nodes) CHECK((x - p.center).norm() == doctest::Approx(20).epsilon(1e-12));
    // Inscribed polyhedron: a little under the ball's volume, and inward (negative).
    const double ball = 4.0 / 3 * M_PI * 8000;
    CHECK(-r.volume < ball);
    CHECK(-r.volume > (h >= 40 ? 0.6 : 0.9) * ball);
  }
}

TEST_CASE("farfield 3D: a box is closed, inward, its edges under h, its volume exact") {
  FarfieldParams3 p;
  p.shape = "box";
  p.size = {10, 6, 4};
  p.h = 1.5;
  const FarfieldMesh3 m = make_farfield(p, Vector3d(-1, -1, -1), Vector3d(1, 1, 1));
  const Measured r = measure(m);
  CHECK(r.open_edges == 0);
  CHECK(r.duplicates == 0);
  CHECK(r.longest <= 1.5 * std::sqrt(2.0));  // the cells' diagonals
  CHECK(r.volume == doctest::Approx(-240).epsilon(1e-12));
}

TEST_CASE("farfield 3D: a farfield that does not enclose the bodies, or a bad size, is refused by key") {
  FarfieldParams3 p;
  p.radius = 1.5;
  p.h = 0.5;
  CHECK_THROWS_WITH_AS(make_farfield(p, Vector3d(-1, -1, -1), Vector3d(1, 1, 1)), doctest::Contains("fill.farfield.radius"),
                       ConfigError);
  p.shape = "box";
  p.size = {3, 3, 1};
  CHECK_THROWS_WITH_AS(make_farfield(p, Vector3d(-1, -1, -1), Vector3d(1, 1, 1)), doctest::Contains("fill.farfield.size"),
                       ConfigError);
  p.h = 0;
  CHECK_THROWS_WITH_AS(make_farfield(p, Vector3d(-1, -1, -1), Vector3d(1, 1, 1)), doctest::Contains("fill.farfield.h"),
                       ConfigError);
}

TEST_CASE("farfield 3D: a box cut by two planes leaves both faces out, its cut loops closed on the planes") {
  FarfieldParams3 p;
  p.shape = "box";
  p.size = {6, 6, 0};
  p.h = 1;
  p.cuts = {{2, 0.0, 1}, {2, 0.5, -1}};
  const FarfieldMesh3 m = make_farfield(p, Vector3d(-1, -1, 0), Vector3d(1, 1, 0.5));
  REQUIRE(m.cut_loops.size() == 2);
  for (std::size_t c = 0; c < 2; ++c) {
    CAPTURE(c);
    const std::vector<int>& loop = m.cut_loops[c];
    CHECK(loop.size() == 24);  // 6 x 6 grid: 4 sides of 6 edges
    std::set<int> distinct(loop.begin(), loop.end());
    CHECK(distinct.size() == loop.size());
    for (int id : loop) CHECK(m.nodes[static_cast<std::size_t>(id)].z() == p.cuts[c].offset);
    // Every loop edge is an open edge of the box's triangles (the plane's region closes it).
    std::map<std::pair<int, int>, int> edges;
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k) ++edges[{std::min(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]),
                                          std::max(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)])}];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k], b = loop[(k + 1) % loop.size()];
      CHECK(edges[{std::min(a, b), std::max(a, b)}] == 1);
    }
  }
  // No triangle on either plane.
  for (const auto& t : m.triangles) {
    bool all0 = true, all1 = true;
    for (int id : t) all0 = all0 && m.nodes[static_cast<std::size_t>(id)].z() == 0, all1 = all1 && m.nodes[static_cast<std::size_t>(id)].z() == 0.5;
    CHECK_FALSE(all0);
    CHECK_FALSE(all1);
  }
  FarfieldParams3 fine = p;
  fine.h = 1e-4;
  CHECK_THROWS_WITH_AS(make_farfield(fine, Vector3d(-1, -1, 0), Vector3d(1, 1, 0.5)), doctest::Contains("fill.farfield.h"), ConfigError);
}
