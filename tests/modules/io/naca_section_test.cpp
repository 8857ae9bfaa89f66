// SPDX-License-Identifier: MIT
// Generated NACA 4- and 5-digit sections (modules/io/naca_section.h) and the `naca:` key
// (modules/pipeline/naca_config.h): thickness, camber and trailing edges against the formulas'
// known values, contours as a file's would be, clear errors.
#include "modules/io/naca_section.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/geometry2d.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/naca_config.h"

using Eigen::Vector2d;
using plaf::NacaSection;

namespace {

// Upper point k (from the LE, k = 1..n) and lower point k of a Selig-ordered section of n
// intervals per surface: the upper surface runs TE -> LE as indices 0..n-1, the LE is n.
Vector2d upper(const std::vector<Vector2d>& p, int n, int k) { return p[static_cast<std::size_t>(n - k)]; }
Vector2d lower(const std::vector<Vector2d>& p, int n, int k) { return p[static_cast<std::size_t>(n + k)]; }

double shoelace(const std::vector<Vector2d>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vector2d& u = p[i];
    const Vector2d& v = p[(i + 1) % p.size()];
    a += u.x() * v.y() - v.x() * u.y();
  }
  return a / 2;
}

// The camber line at station k: the midpoint of the upper and lower points (the thickness is laid
// off on either side along the same normal), and the largest camber with its station.
struct Camber {
  double max = -1, at = 0, te = 0;
};
Camber camber(const NacaSection& s) {
  const std::vector<Vector2d> p = plaf::naca_points(s);
  Camber c;
  for (int k = 1; k <= s.intervals; ++k) {
    const Vector2d mid = 0.5 * (upper(p, s.intervals, k) + lower(p, s.intervals, k));
    if (mid.y() > c.max) c = {mid.y(), mid.x(), c.te};
  }
  c.te = 0.5 * (upper(p, s.intervals, s.intervals) + lower(p, s.intervals, s.intervals)).y();
  return c;
}

}  // namespace

TEST_CASE("naca: the 4-digit thickness: 12 % at 30 % chord, sharp or with the standard 0.00252 base") {
  for (const bool sharp : {true, false}) {
    CAPTURE(sharp);
    const NacaSection s{"0012", sharp, 200};
    const std::vector<Vector2d> p = plaf::naca_points(s);
    REQUIRE(p.size() == 2 * 200 + 1);
    double t = 0, at = 0;
    for (int k = 1; k <= 200; ++k) {
      const Vector2d u = upper(p, 200, k), l = lower(p, 200, k);
      CHECK(u.x() == l.x());         // no camber: upper and lower at the same station
      CHECK(u.y() == -l.y());        // symmetric
      if (u.y() - l.y() > t) t = u.y() - l.y(), at = u.x();
    }
    CHECK(t == doctest::Approx(0.12).epsilon(2e-3));
    CHECK(at == doctest::Approx(0.30).epsilon(0.03));
    CHECK(p[200] == Vector2d(0, 0));  // the leading edge
    if (sharp) {
      CHECK(p.front() == Vector2d(1, 0));
      CHECK(p.back() == p.front());
    } else {
      CHECK(p.front().x() == 1.0);
      CHECK(p.front().y() == doctest::Approx(0.00126).epsilon(1e-6));
      CHECK(p.back().y() == doctest::Approx(-0.00126).epsilon(1e-6));
    }
    CHECK(shoelace(p) > 0);  // Selig order is counter-clockwise
  }
}

TEST_CASE("naca: 4-digit camber: 2412 has 2 % at 40 % chord, 6409 has 6 % at 40 %") {
  const Camber c2412 = camber({"2412", true, 400});
  CHECK(c2412.max == doctest::Approx(0.02).epsilon(1e-3));
  CHECK(c2412.at == doctest::Approx(0.4).epsilon(0.02));
  CHECK(std::abs(c2412.te) < 1e-12);
  const Camber c6409 = camber({"6409", false, 400});
  CHECK(c6409.max == doctest::Approx(0.06).epsilon(1e-3));
  CHECK(c6409.at == doctest::Approx(0.4).epsilon(0.02));
}

TEST_CASE("naca: 5-digit mean lines: 23012 has 1.84 % at 15 %, the reflexed 23112 ends at 0 and flattens behind") {
  // The 230 mean line: r = 0.2025, k1 = 15.957; the maximum k1/6 (x^3 - 3 r x^2 + r^2 (3 - r) x)
  // is at x = r (1 - sqrt(r/3)) = 0.1499, where it is 0.018385.
  const Camber simple = camber({"23012", true, 400});
  CHECK(simple.max == doctest::Approx(0.018385).epsilon(2e-3));
  CHECK(simple.at == doctest::Approx(0.15).epsilon(0.03));
  CHECK(std::abs(simple.te) < 1e-12);
  // Design lift 0.15 L: 43012 has twice the camber of 23012 (k1 scales with the lift).
  CHECK(camber({"43012", true, 400}).max == doctest::Approx(2 * simple.max).epsilon(1e-9));
  // The reflexed line: zero at the trailing edge, its maximum near 15 % too, and at 90 % chord
  // nearer the chord than the simple line (the reflex lifts the rear).
  const Camber reflex = camber({"23112", true, 400});
  CHECK(std::abs(reflex.te) < 1e-12);
  CHECK(reflex.at == doctest::Approx(0.15).epsilon(0.1));
  const auto camber_at = [](const NacaSection& s, double x) {
    const std::vector<Vector2d> p = plaf::naca_points(s);
    for (int k = 1; k <= s.intervals; ++k)
      if (upper(p, s.intervals, k).x() >= x) return 0.5 * (upper(p, s.intervals, k) + lower(p, s.intervals, k)).y();
    return 0.0;
  };
  CHECK(camber_at({"23112", true, 400}, 0.9) < camber_at({"23012", true, 400}, 0.9));
}

TEST_CASE("naca: a section is a contour as a file's: clockwise, a sharp TE one corner, a blunt one a closing segment") {
  const plaf::BodyContour sharp = plaf::naca_contour({"4412", true, 100});
  CHECK(sharp.corners == std::vector<int>{0});
  CHECK_FALSE(sharp.blunt);
  CHECK(sharp.points.size() == 200);
  CHECK(shoelace(sharp.points) < 0);
  CHECK(sharp.file == "NACA 4412 (sharp trailing edge)");
  const plaf::BodyContour blunt = plaf::naca_contour({"0012", false, 100});
  CHECK(blunt.blunt);
  CHECK(blunt.corners == std::vector<int>{0, 200});
  CHECK(blunt.points.size() == 201);
  CHECK((blunt.points[0] - blunt.points[200]).norm() == doctest::Approx(0.00252).epsilon(1e-5));
}

TEST_CASE("naca: designations plaf cannot generate are refused naming them") {
  const std::pair<const char*, const char*> bad[] = {
      {"012", "4 digits"},      {"123456", "4 digits"},       {"00A2", "'A' is not a digit"},
      {"2400", "thickness"},    {"0412", "its position"},      {"2012", "its position"},
      {"03012", "design lift"}, {"23212", "0 (simple) or 1"}, {"26012", "not in the 5-digit tables"},
      {"21112", "not in the 5-digit tables"}};
  for (const auto& [digits, why] : bad) {
    CAPTURE(digits);
    CHECK_THROWS_WITH_AS(plaf::naca_points({digits, true, 100}), doctest::Contains(why), plaf::InputError);
    CHECK_THROWS_WITH_AS(plaf::naca_points({digits, true, 100}), doctest::Contains((std::string("'") + digits + "'").c_str()),
                         plaf::InputError);
  }
  CHECK_THROWS_AS(plaf::naca_points({"0012", true, 3}), plaf::InputError);
}

TEST_CASE("naca: the naca key, as a designation or a map, in a 2D body, errors naming the key") {
  const auto parse = [](const std::string& yaml) {
    const plaf::ConfigNode n = plaf::ConfigNode::load_string(yaml, "c.yaml");
    auto s = plaf::parse_naca(n);
    n.finish();
    return s;
  };
  const auto a = parse("naca: \"0012\"\n");
  REQUIRE(a.has_value());
  CHECK(a->digits == "0012");
  CHECK(a->sharp);
  CHECK(a->intervals == 100);
  const auto b = parse("naca: {digits: \"23012\", trailing_edge: blunt, intervals: 60}\n");
  REQUIRE(b.has_value());
  CHECK(b->digits == "23012");
  CHECK_FALSE(b->sharp);
  CHECK(b->intervals == 60);
  CHECK_FALSE(parse("{}\n").has_value());
  CHECK_THROWS_WITH_AS(parse("naca: \"0412\"\n"), doctest::Contains("c.yaml:1:7: naca: NACA '0412'"), plaf::ConfigError);
  CHECK_THROWS_WITH_AS(parse("naca: {digits: \"0012\", colour: red}\n"), doctest::Contains("colour"), plaf::ConfigError);
  CHECK_THROWS_WITH_AS(parse("naca: {trailing_edge: blunt}\n"), doctest::Contains("digits is required"), plaf::ConfigError);
  CHECK_THROWS_WITH_AS(parse("naca: {digits: \"0012\", trailing_edge: round}\n"), doctest::Contains("trailing_edge"),
                       plaf::ConfigError);

  // In a body: the geometry of a generated section, and one source per body.
  const plaf::ConfigNode g = plaf::ConfigNode::load_string(
      "type: airfoils\nbodies:\n  - naca: \"2412\"\n  - {naca: \"0012\", name: second}\n", "g.yaml");
  plaf::AirfoilsParams p = plaf::parse_airfoils_params(g);
  REQUIRE(p.bodies.size() == 2);
  p.bodies[1].naca->digits = "0009";
  // Two overlapping sections are refused as crossing contours, named by their sections.
  CHECK_THROWS_WITH_AS(plaf::build_airfoils_geometry(p), doctest::Contains("NACA 2412 (sharp trailing edge)"),
                       plaf::InputError);
  p.bodies.pop_back();
  const plaf::Geometry2D geo = plaf::build_airfoils_geometry(p);
  CHECK(geo.loops.size() == 2);  // the body and the farfield
  CHECK(geo.loops[0].loop.signed_area() < 0);
  const plaf::ConfigNode both =
      plaf::ConfigNode::load_string("type: airfoils\nbodies:\n  - {naca: \"2412\", file: x.dat}\n", "g.yaml");
  CHECK_THROWS_WITH_AS(plaf::parse_airfoils_params(both), doctest::Contains("one of file, naca or circle"),
                       plaf::ConfigError);
}
