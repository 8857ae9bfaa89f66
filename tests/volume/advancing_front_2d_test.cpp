// SPDX-License-Identifier: MIT
#include "volume/advancing_front_2d.h"

#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <utility>

#include <Eigen/Geometry>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "volume/optimize_2d.h"

using namespace plaf;
using volume::AdvancingFrontResult;
using LinearFront2 = LinearFront<2>;

namespace {

using Vec = Eigen::Vector2d;

double loop_area(const LinearFront2& f, const std::vector<NodeId>& l) {
  double a = 0;
  for (std::size_t k = 0; k < l.size(); ++k) {
    const Vec &p = f.nodes[l[k]], &q = f.nodes[l[(k + 1) % l.size()]];
    a += 0.5 * (p.x() * q.y() - p.y() * q.x());
  }
  return a;
}

// The fill is a triangulation of the front's region: every triangle counter-clockwise (exact
// predicate), every front edge used by exactly one triangle in its own direction, every other
// edge by exactly two in opposite directions, and the areas summing to the region's. Together
// these leave no overlap and no gap.
void check_triangulation(const LinearFront2& f, const AdvancingFrontResult& r) {
  std::map<std::pair<NodeId, NodeId>, int> directed;
  double area = 0, region = 0;
  std::size_t inverted = 0;
  for (const auto& t : r.simplices) {
    const Vec &a = r.nodes[t[0]], &b = r.nodes[t[1]], &c = r.nodes[t[2]];
    if (!(orient2d(a, b, c) > 0)) ++inverted;
    area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  CHECK(inverted == 0);
  std::size_t front_ok = 0, front_edges = 0;
  std::map<std::pair<NodeId, NodeId>, int> front;
  for (const LinearLoop& loop : f.loops) {
    const std::vector<NodeId>& l = loop.nodes;
    region += loop_area(f, l);
    for (std::size_t k = 0; k < l.size(); ++k) {
      const std::pair<NodeId, NodeId> e{l[k], l[(k + 1) % l.size()]};
      front[e] = 1;
      ++front_edges;
      if (directed.count(e) && directed[e] == 1 && !directed.count({e.second, e.first})) ++front_ok;
    }
  }
  CHECK(front_ok == front_edges);
  std::size_t unpaired = 0;
  for (const auto& [e, n] : directed) {
    if (front.count(e)) continue;
    const auto it = directed.find({e.second, e.first});
    if (n != 1 || it == directed.end() || it->second != 1) ++unpaired;
  }
  CHECK(unpaired == 0);
  CHECK(area == doctest::Approx(region).epsilon(1e-9));
}

// Fraction of the triangles' distinct edges with metric length in [1/sqrt 2, sqrt 2].
double unit_fraction(const AdvancingFrontResult& r, const MetricField<2>& m) {
  std::map<std::pair<NodeId, NodeId>, double> len;
  for (const auto& t : r.simplices)
    for (int k = 0; k < 3; ++k) {
      const NodeId a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
      len[{a, b}] = metric_length(m, r.nodes[a], r.nodes[b]);
    }
  std::size_t unit = 0;
  for (const auto& [e, l] : len)
    if (l >= std::sqrt(0.5) && l <= std::sqrt(2.0)) ++unit;
  return static_cast<double>(unit) / static_cast<double>(len.size());
}

// A polygon loop of n points on an ellipse (counter-clockwise unless reversed), appended to f.
void add_ellipse(LinearFront2& f, Vec c, double a, double b, int n, bool clockwise) {
  std::vector<NodeId> loop;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * k / n * (clockwise ? -1 : 1);
    loop.push_back(static_cast<NodeId>(f.nodes.size()));
    f.nodes.emplace_back(c.x() + a * std::cos(t), c.y() + b * std::sin(t));
  }
  f.loops.push_back({"loop", BoundaryKind::Wall, false, -1, loop});
}

// An ellipse loop whose edges have unit length in `metric` (equidistributed), appended to f.
void add_metric_ellipse(LinearFront2& f, Vec c, double a, double b, const MetricField<2>& metric, bool clockwise) {
  const int fine = 20000;
  auto at = [&](int k) {
    const double t = 2 * std::numbers::pi * k / fine * (clockwise ? -1 : 1);
    return Vec(c.x() + a * std::cos(t), c.y() + b * std::sin(t));
  };
  std::vector<double> s{0};
  for (int k = 0; k < fine; ++k) s.push_back(s.back() + metric_length(metric, at(k), at(k + 1)));
  const int n = std::max(3, static_cast<int>(std::lround(s.back())));
  std::vector<NodeId> loop;
  for (int k = 0, j = 0; j < n; ++j) {
    while (s[k] < s.back() * j / n) ++k;
    loop.push_back(static_cast<NodeId>(f.nodes.size()));
    f.nodes.push_back(at(k));
  }
  f.loops.push_back({"loop", BoundaryKind::Wall, false, -1, loop});
}

// A star polygon of 20-100 points at radii 0.4-1 about the origin, counter-clockwise.
LinearFront2 random_star(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  LinearFront2 f;
  const int n = 20 + static_cast<int>(80 * u(rng));
  std::vector<NodeId> loop;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * k / n, r = 0.4 + 0.6 * u(rng);
    loop.push_back(static_cast<NodeId>(f.nodes.size()));
    f.nodes.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  f.loops.push_back({"loop", BoundaryKind::Wall, false, -1, loop});
  return f;
}

LinearFront2 square(double scale, Vec offset, int n) {
  LinearFront2 f;
  std::vector<NodeId> loop;
  const Vec corners[] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < n; ++k) {
      loop.push_back(static_cast<NodeId>(f.nodes.size()));
      f.nodes.push_back(offset + scale * (corners[s] + (corners[(s + 1) % 4] - corners[s]) * k / n));
    }
  f.loops.push_back({"loop", BoundaryKind::Wall, false, -1, loop});
  return f;
}

}  // namespace

TEST_CASE("advancing front: a square in a uniform metric is a metric-unit triangulation") {
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.1));
  const LinearFront2 f = square(1, {0, 0}, 10);
  const AdvancingFrontResult r = volume::advancing_front_fill(f, metric);
  check_triangulation(f, r);
  // Equilateral triangles of side 0.1 cover the unit square with 1 / (sqrt(3)/4 0.01) = 231.
  CHECK(r.simplices.size() > 0.8 * 231);
  CHECK(r.simplices.size() < 1.3 * 231);
  CHECK(unit_fraction(r, metric) > 0.9);
  CHECK(r.stats.new_points > 50);
}

TEST_CASE("advancing front: the same triangulation at every scale and offset (exact predicates)") {
  const LinearFront2 ref = square(1, {0, 0}, 8);
  const UniformMetricField<2> m1(Metric<2>::isotropic(0.13));
  const std::size_t n = volume::advancing_front_fill(ref, m1).simplices.size();
  for (const auto& [scale, offset] : {std::pair{1e-6, Vec(0, 0)}, std::pair{1e6, Vec(0, 0)},
                                      std::pair{1e-3, Vec(1e3, -1e3)}, std::pair{1.0, Vec(1e7, 1e7)}}) {
    INFO("scale " << scale << " offset " << offset.transpose());
    const LinearFront2 f = square(scale, offset, 8);
    const UniformMetricField<2> m(Metric<2>::isotropic(0.13 * scale));
    const AdvancingFrontResult r = volume::advancing_front_fill(f, m);
    check_triangulation(f, r);
    CHECK(r.simplices.size() == doctest::Approx(static_cast<double>(n)).epsilon(0.05));
  }
}

TEST_CASE("advancing front: anisotropic metric, holes, and fronts merging in narrow gaps") {
  SUBCASE("a uniform anisotropic metric at 30 degrees, aspect ratio 20") {
    const Eigen::Matrix2d dirs = Eigen::Rotation2Dd(std::numbers::pi / 6).toRotationMatrix();
    const UniformMetricField<2> metric(Metric<2>::from_directions(dirs, Vec(0.2, 0.01)));
    LinearFront2 f;
    add_metric_ellipse(f, {0, 0}, 1, 0.6, metric, false);
    const AdvancingFrontResult r = volume::advancing_front_fill(f, metric);
    check_triangulation(f, r);
    // 1.88 / (0.2 x 0.01) metric units of area: about 2170 unit equilateral triangles.
    CHECK(r.simplices.size() > 0.6 * 2170);
    CHECK(r.simplices.size() < 1.4 * 2170);
    CHECK(unit_fraction(r, metric) > 0.9);
  }
  SUBCASE("two holes in a disk, a gap of a tenth of the size between them") {
    const UniformMetricField<2> metric(Metric<2>::isotropic(0.2));
    LinearFront2 f;
    add_ellipse(f, {0, 0}, 3, 3, 90, false);
    add_ellipse(f, {-0.51, 0}, 0.5, 0.3, 16, true);
    add_ellipse(f, {0.51, 0}, 0.5, 0.3, 16, true);
    const AdvancingFrontResult r = volume::advancing_front_fill(f, metric);
    check_triangulation(f, r);
    CHECK(unit_fraction(r, metric) > 0.8);
  }
}

TEST_CASE("advancing front: random star polygons in random metrics all fill") {
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 40; ++trial) {
    INFO("trial " << trial);
    const LinearFront2 f = random_star(rng);
    const double h1 = 0.02 + 0.2 * u(rng), ratio = 1 + 19 * u(rng) * u(rng);
    const Eigen::Matrix2d dirs = Eigen::Rotation2Dd(std::numbers::pi * u(rng)).toRotationMatrix();
    const UniformMetricField<2> metric(Metric<2>::from_directions(dirs, Vec(h1 / ratio, h1)));
    const AdvancingFrontResult r = volume::advancing_front_fill(f, metric);
    check_triangulation(f, r);
  }
}

TEST_CASE("advancing front: crossing, touching and mis-oriented loops are MesherErrors") {
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.2));
  LinearFront2 crossing;
  add_ellipse(crossing, {0, 0}, 3, 3, 40, false);
  add_ellipse(crossing, {2.9, 0}, 0.5, 0.5, 12, true);  // pokes out of the outer loop
  CHECK_THROWS_WITH_AS(volume::advancing_front_fill(crossing, metric), doctest::Contains("cross or touch"),
                       MesherError);
  LinearFront2 reversed;
  add_ellipse(reversed, {0, 0}, 1, 1, 20, true);
  CHECK_THROWS_WITH_AS(volume::advancing_front_fill(reversed, metric), doctest::Contains("enclose no region"),
                       MesherError);
  LinearFront2 hole_ccw;
  add_ellipse(hole_ccw, {0, 0}, 3, 3, 40, false);
  add_ellipse(hole_ccw, {0, 0}, 0.5, 0.5, 12, false);  // a hole must run clockwise
  CHECK_THROWS_WITH_AS(volume::advancing_front_fill(hole_ccw, metric), doctest::Contains("a hole"), MesherError);
  LinearFront2 tiny;
  tiny.nodes = {{0, 0}, {1, 0}};
  tiny.loops = {{"tiny", BoundaryKind::Wall, false, -1, {0, 1}}};
  CHECK_THROWS_AS(volume::advancing_front_fill(tiny, metric), MesherError);
  volume::AdvancingFrontParams few;
  few.max_triangles = 10;
  CHECK_THROWS_WITH_AS(volume::advancing_front_fill(square(1, {0, 0}, 10), metric, few),
                       doctest::Contains("max_triangles"), MesherError);
}

namespace {

// A wall-like field: sizes h_n = 0.01 + 0.3 |y| across the line y = 0 and 0.15 along it, capped
// at 0.3 (anisotropy up to 15, graded).
class BandMetric final : public MetricField<2> {
 public:
  Metric<2> evaluate(const Vec& x) const override {
    const double hn = std::min(0.3, 0.01 + 0.3 * std::abs(x.y())), ht = std::max(hn, 0.15);
    return Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Vec(ht, hn));
  }
};

}  // namespace

TEST_CASE("fill post-optimisation: swaps and smoothing keep the triangulation and its fronts, and raise quality and unit edges") {
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<double> u(0, 1);
  const BandMetric band;
  double unit_gain = 0;
  for (int trial = 0; trial < 30; ++trial) {
    INFO("trial " << trial);
    const LinearFront2 f = random_star(rng);
    const double h1 = 0.02 + 0.2 * u(rng), ratio = 1 + 19 * u(rng) * u(rng);
    const Eigen::Matrix2d dirs = Eigen::Rotation2Dd(std::numbers::pi * u(rng)).toRotationMatrix();
    const UniformMetricField<2> uniform(Metric<2>::from_directions(dirs, Vec(h1 / ratio, h1)));
    const MetricField<2>& metric = trial % 2 ? static_cast<const MetricField<2>&>(band) : uniform;
    AdvancingFrontResult r = volume::advancing_front_fill(f, metric);
    const AdvancingFrontResult before = r;
    const volume::OptimizeStats st = volume::optimize_fill(r, f.nodes.size(), metric);
    check_triangulation(f, r);  // still the region's triangulation with every front edge kept
    for (std::size_t v = 0; v < f.nodes.size(); ++v) CHECK(r.nodes[v] == f.nodes[v]);  // front nodes fixed
    // Splits add a node and two triangles each, collapses remove them.
    CHECK(r.nodes.size() == before.nodes.size() + st.splits - st.collapses);
    CHECK(r.simplices.size() == before.simplices.size() + 2 * st.splits - 2 * st.collapses);
    CHECK(st.quality_min_after >= st.quality_min_before);
    CHECK(st.unit_fraction_after >= st.unit_fraction_before - 0.01);
    CHECK(unit_fraction(r, metric) >= unit_fraction(before, metric) - 0.01);
    unit_gain += st.unit_fraction_after - st.unit_fraction_before;
  }
  MESSAGE("mean unit-fraction gain " << unit_gain / 30);
  CHECK(unit_gain > 0);
}

namespace {

// A shock-like band across the slanted line x = 0.5 + 0.1 y: size 0.1 everywhere, across the
// band 0.1 - 0.095 exp(-(d / 0.02)^2) (0.005 at its centre, anisotropy 20, about 0.04 wide: thinner
// than the 0.1 steps of the front outside it).
class ShockMetric final : public MetricField<2> {
 public:
  Metric<2> evaluate(const Vec& x) const override {
    const Vec n = Vec(1, -0.1).normalized();
    const double d = (x - Vec(0.5, 0)).dot(n);
    Eigen::Matrix2d dirs;
    dirs << n.x(), -n.y(), n.y(), n.x();
    return Metric<2>::from_directions(dirs, Vec(0.1 - 0.095 * std::exp(-(d / 0.02) * (d / 0.02)), 0.1));
  }
};

}  // namespace

TEST_CASE("fill post-optimisation: an edge across a feature thinner than the front's steps is split until the band is resolved") {
  const ShockMetric shock;
  AdvancingFrontResult r = volume::advancing_front_fill(square(1, {0, 0}, 10), shock);
  // The longest edge integrated along it (8 Gauss points), as the quality report measures it.
  const auto longest = [&](const AdvancingFrontResult& m) {
    double out = 0;
    for (const auto& t : m.simplices)
      for (int k = 0; k < 3; ++k) {
        const Vec a = m.nodes[t[k]], b = m.nodes[t[(k + 1) % 3]];
        const double xs[4] = {a.x(), a.y(), b.x(), b.y()};
        out = std::max(out, metric_length_curved<2>(shock, xs, 1));
      }
    return out;
  };
  const double before = longest(r);
  const volume::OptimizeStats st = volume::optimize_fill(r, 40, shock);
  check_triangulation(square(1, {0, 0}, 10), r);
  const double after = longest(r);
  MESSAGE("longest edge " << before << " -> " << after << ", unit fraction " << st.unit_fraction_before << " -> "
                          << st.unit_fraction_after << ", least quality " << st.quality_min_before << " -> "
                          << st.quality_min_after);
  CHECK(before > 3);  // the front stepped over the band
  CHECK(after <= 2.5);
  CHECK(st.unit_fraction_after > st.unit_fraction_before + 0.03);
  CHECK(st.quality_min_after >= st.quality_min_before);
}
