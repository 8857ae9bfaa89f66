// SPDX-License-Identifier: MIT
#include "volume/tetgen_fill.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "tests/volume/box_front.h"

using namespace plaf;
using volume::TetFillResult;
using Vec = Eigen::Vector3d;
using test::add_cube;
using test::Normals;

namespace {

// The box o + [0, 3a]^3 (farfield, normals inward) around the body o + [a, 2a]^3 (wall, normals
// out of the body), with the body's hole point at its centre when `hole`. Two nodes inside the
// body that no triangle uses come first, as the layer stage's nodes do (linear_front.h).
struct BoxWithBody {
  LinearFront<3> front;
  Vec body_lo, body_hi;
  double region_volume = 0;  // box minus body
  double box_volume = 0;
};

BoxWithBody box_with_body(double a, const Vec& o, bool hole) {
  BoxWithBody b;
  b.front.nodes = {o + a * Vec(1.4, 1.5, 1.6), o + a * Vec(1.6, 1.5, 1.4)};
  add_cube(b.front, o, 3 * a, 6, Normals::In, "farfield");
  add_cube(b.front, o + Vec(a, a, a), a, 3, Normals::Out, "body");
  if (hole) b.front.holes.push_back(o + 1.5 * a * Vec(1, 1, 1));
  b.body_lo = o + Vec(a, a, a);
  b.body_hi = o + Vec(2 * a, 2 * a, 2 * a);
  b.box_volume = 27 * a * a * a;
  b.region_volume = 26 * a * a * a;
  return b;
}

double tet_volume(const TetFillResult& r, const std::array<NodeId, 4>& t) {
  const Vec &a = r.nodes[t[0]], &b = r.nodes[t[1]], &c = r.nodes[t[2]], &d = r.nodes[t[3]];
  return (b - a).cross(c - a).dot(d - a) / 6;
}

// The invariants of tetgen_fill.h on any result: front nodes first and unchanged, positive tets
// (exact predicate), every front triangle a face of exactly one tet, on its normal's side, and no
// tet on a node no triangle uses. Returns the tets' total volume. (`flat_allowed`: a front with
// points closer than rounding of an angle, whose smallest dihedral angle may come out 0.)
double check_fill(const LinearFront<3>& f, const TetFillResult& r, bool flat_allowed = false) {
  REQUIRE(r.nodes.size() >= f.nodes.size());
  std::size_t moved = 0;
  for (std::size_t i = 0; i < f.nodes.size(); ++i) moved += r.nodes[i] != f.nodes[i];
  CHECK(moved == 0);
  CHECK(r.stats.tets == r.simplices.size());
  CHECK(r.stats.new_points == r.nodes.size() - f.nodes.size());
  std::vector<bool> on_front(f.nodes.size(), false);
  for (const auto& t : f.triangles)
    for (NodeId v : t) on_front[v] = true;

  std::size_t non_positive = 0, on_unused = 0;
  double volume = 0;
  for (const auto& t : r.simplices) {
    if (!(orient3d(r.nodes[t[0]], r.nodes[t[1]], r.nodes[t[2]], r.nodes[t[3]]) < 0)) ++non_positive;
    volume += tet_volume(r, t);
    for (int k = 0; k < 4; ++k)
      if (static_cast<std::size_t>(t[k]) < f.nodes.size() && !on_front[t[k]]) ++on_unused;
  }
  CHECK(non_positive == 0);
  CHECK(on_unused == 0);
  const test::FrontUse use = test::front_use(f, r.nodes, test::face_apexes(r.simplices));
  CHECK(use.not_once == 0);
  CHECK(use.behind == 0);
  // Golden bounds of the shape measures: the regular tet has the largest least dihedral angle,
  // arccos(1/3) = 70.53 deg, and the smallest radius-edge ratio, sqrt(6)/4 (both exact).
  CHECK(r.stats.min_dihedral_deg >= 0);
  if (!flat_allowed) CHECK(r.stats.min_dihedral_deg > 0);
  CHECK(r.stats.min_dihedral_deg <= std::acos(1.0 / 3) * 180 / std::numbers::pi + 1e-9);
  CHECK(r.stats.max_radius_edge >= std::sqrt(6.0) / 4 - 1e-12);
  return volume;
}

}  // namespace

TEST_CASE("volume: TetGen fills a box with positive tets whose volumes sum to the box's") {
  for (double a : {1e-8, 1.0, 1e8}) {
    LinearFront<3> f;
    add_cube(f, Vec(-0.3 * a, 2 * a, 0), a, 6, Normals::In, "farfield");
    volume::TetFillParams p;
    p.max_volume = a * a * a / 2000;
    const TetFillResult r = volume::tetgen_fill(f, p);
    CHECK(r.simplices.size() >= 2000);
    CHECK(r.stats.switches.find("pYQzJ") == 0);
    const double volume = check_fill(f, r);
    CHECK(std::abs(volume - a * a * a) <= 1e-12 * a * a * a);
    MESSAGE("box a=" << a << ": " << r.stats.tets << " tets, " << r.stats.new_points << " new points, min dihedral "
                     << r.stats.min_dihedral_deg << " deg, max radius-edge " << r.stats.max_radius_edge
                     << ", volume error " << std::abs(volume - a * a * a) / (a * a * a));
  }
}

TEST_CASE("volume: a single tet comes back whole, with its dihedral angle and radius-edge ratio") {
  // Golden values by elementary geometry. Regular tet (edge 2 sqrt 2): every dihedral angle is
  // arccos(1/3), circumradius sqrt 3, so R / l = sqrt(6)/4. Corner tet: right dihedral angles at
  // the three axis edges, arccos(1/sqrt 3) at the other three; circumcentre (1/2, 1/2, 1/2), so
  // R / l = (sqrt(3)/2) / 1.
  struct Case {
    const char* name;
    std::array<Vec, 4> p;
    double min_dihedral_deg, radius_edge;
  };
  const double deg = 180 / std::numbers::pi;
  const Case cases[] = {
      {"regular", {Vec(1, 1, 1), Vec(1, -1, -1), Vec(-1, 1, -1), Vec(-1, -1, 1)}, std::acos(1.0 / 3) * deg,
       std::sqrt(6.0) / 4},
      {"corner", {Vec(0, 0, 0), Vec(1, 0, 0), Vec(0, 1, 0), Vec(0, 0, 1)}, std::acos(1 / std::sqrt(3.0)) * deg,
       std::sqrt(3.0) / 2},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    LinearFront<3> f;
    f.nodes.assign(c.p.begin(), c.p.end());
    f.tags.push_back({"farfield", BoundaryKind::Farfield});
    for (int l = 0; l < 4; ++l) {  // the face opposite node l, its normal towards l
      std::array<NodeId, 3> t{(l + 1) % 4, (l + 2) % 4, (l + 3) % 4};
      if ((c.p[t[1]] - c.p[t[0]]).cross(c.p[t[2]] - c.p[t[0]]).dot(c.p[l] - c.p[t[0]]) < 0) std::swap(t[1], t[2]);
      f.triangles.push_back(t);
      f.triangle_tag.push_back(0);
    }
    volume::TetFillParams no_refinement;
    no_refinement.max_radius_edge = 0;
    const TetFillResult r = volume::tetgen_fill(f, no_refinement);
    CHECK(r.stats.switches == "pYQzJM0/1");
    CHECK(r.stats.tets == 1);
    CHECK(r.stats.new_points == 0);
    check_fill(f, r);
    CHECK(r.stats.min_dihedral_deg == doctest::Approx(c.min_dihedral_deg).epsilon(1e-12));
    CHECK(r.stats.max_radius_edge == doctest::Approx(c.radius_edge).epsilon(1e-12));
  }
}

TEST_CASE("volume: with a hole point TetGen fills a box around a body and leaves the body empty") {
  for (double a : {1e-8, 1.0, 1e8}) {
    const BoxWithBody b = box_with_body(a, Vec(0.7 * a, -5 * a, 2 * a), true);
    const TetFillResult r = volume::tetgen_fill(b.front, {});
    const double volume = check_fill(b.front, r);
    CHECK(std::abs(volume - b.region_volume) <= 1e-12 * b.region_volume);
    std::size_t inside_body = 0;
    for (const auto& t : r.simplices) {
      const Vec c = (r.nodes[t[0]] + r.nodes[t[1]] + r.nodes[t[2]] + r.nodes[t[3]]) / 4;
      if ((c.array() > b.body_lo.array()).all() && (c.array() < b.body_hi.array()).all()) ++inside_body;
    }
    CHECK(inside_body == 0);
    MESSAGE("box with body a=" << a << ": " << r.stats.tets << " tets, " << r.stats.new_points
                               << " new points, min dihedral " << r.stats.min_dihedral_deg << " deg, max radius-edge "
                               << r.stats.max_radius_edge << ", volume error "
                               << std::abs(volume - b.region_volume) / b.region_volume);
  }
}

TEST_CASE("volume: two bodies whose corners are closer than TetGen's merge tolerance keep every front triangle") {
  // The box [0, 4]^3 around the bodies [1, 2]^3 and [2 + e, 3 + e]^3, their facing corners e sqrt 3
  // apart: under 1e-8 of the box's diagonal (6.9e-8), within which TetGen replaces one point by the
  // other unless told not to (M0/1, tetgen_switches): the triangles on the replaced corner would be
  // lost (a flange's layers, 4e-7 apart at a bore's rim in a farfield 40 wide, lost 11).
  const double e = 1e-9;
  LinearFront<3> f;
  add_cube(f, Vec(0, 0, 0), 4, 4, Normals::In, "farfield");
  add_cube(f, Vec(1, 1, 1), 1, 2, Normals::Out, "a");
  add_cube(f, Vec(2 + e, 2 + e, 2 + e), 1, 2, Normals::Out, "b");
  f.holes = {Vec(1.5, 1.5, 1.5), Vec(2.5 + e, 2.5 + e, 2.5 + e)};
  const TetFillResult r = volume::tetgen_fill(f, {});
  const double volume = check_fill(f, r, true);
  CHECK(std::abs(volume - 62) <= 1e-9 * 62);
}

TEST_CASE("volume: without its hole point TetGen fills the body's inside too, which the fill refuses") {
  // TetGen meshes the convex hull of the PLC and removes only what a hole point (or the
  // outside of the outermost surface) reaches: without one in the body, the body's inside is
  // meshed as a second region, the tets then fill the whole box (27 a^3 instead of 26 a^3) and
  // overlap the layers grown around the body. The body's triangles become faces of two tets, and
  // the fill reports the missing hole instead of returning overlapping cells.
  const BoxWithBody b = box_with_body(1.0, Vec::Zero(), false);
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(b.front, {}), doctest::Contains("a body without a hole point"), InputError);
}

TEST_CASE("volume: a hole point outside every body carves the region away and is a MesherError") {
  BoxWithBody b = box_with_body(1.0, Vec::Zero(), false);
  b.front.holes.push_back(Vec(0.5, 0.5, 0.5));  // in the region to fill, not in the body
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(b.front, {}), doctest::Contains("the front was not preserved"),
                       MesherError);
}

TEST_CASE("volume: a front whose normals point out of the region is an InputError") {
  LinearFront<3> f;
  add_cube(f, Vec::Zero(), 1.0, 3, Normals::Out, "farfield");  // a box filled from inside, normals outward
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("must point into the region"), InputError);
}

TEST_CASE("volume: bad node ids, too few triangles, bad tags and non-finite points are InputErrors") {
  LinearFront<3> good;
  add_cube(good, Vec::Zero(), 1.0, 2, Normals::In, "farfield");
  CHECK_NOTHROW(volume::tetgen_fill(good, {}));

  CHECK_THROWS_AS(volume::tetgen_fill(LinearFront<3>{}, {}), InputError);
  LinearFront<3> f = good;
  f.triangles.resize(3);
  f.triangle_tag.resize(3);
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("at least 4"), InputError);

  f = good;
  f.triangles[5][1] = static_cast<NodeId>(f.nodes.size());
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("front triangle 5"), InputError);
  f = good;
  f.triangles[0][2] = -1;
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("refers to node -1"), InputError);
  f = good;
  f.triangles[0][2] = f.triangles[0][0];
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("repeats a node"), InputError);
  f = good;
  f.triangles.push_back({f.triangles[0][1], f.triangles[0][2], f.triangles[0][0]});
  f.triangle_tag.push_back(0);
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("have the same nodes"), InputError);

  f = good;
  f.triangle_tag[3] = 1;
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("has tag 1 of 1"), InputError);
  f = good;
  f.triangle_tag.pop_back();
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("triangle tags"), InputError);

  f = good;
  f.nodes[f.triangles[2][0]].y() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("non-finite"), InputError);
  f = good;
  f.holes.push_back(Vec(0.5, std::numeric_limits<double>::infinity(), 0.5));
  CHECK_THROWS_WITH_AS(volume::tetgen_fill(f, {}), doctest::Contains("hole point 0"), InputError);
  f = good;
  f.nodes.push_back(Vec(std::numeric_limits<double>::quiet_NaN(), 0, 0));  // used by no triangle: left alone
  CHECK_NOTHROW(volume::tetgen_fill(f, {}));
}

TEST_CASE("volume: self-intersecting facets make TetGen fail, a MesherError naming the switches") {
  LinearFront<3> f;
  add_cube(f, Vec::Zero(), 1.0, 2, Normals::In, "farfield");
  add_cube(f, Vec(0.5, 0.3, 0.4), 1.0, 2, Normals::Out, "body");  // pokes through three faces of the box
  f.holes.push_back(Vec(1.2, 1.1, 1.2));
  volume::TetFillParams p;
  p.max_radius_edge = 1.4;
  std::string what;
  try {
    volume::tetgen_fill(f, p);
  } catch (const MesherError& e) {
    what = e.what();
  }
  CHECK(what.find("switches -pYQzJM0/1q1.4") != std::string::npos);
  MESSAGE(what);
}
