// SPDX-License-Identifier: MIT
#include "layers/grow_layers_2d.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "modules/io/airfoil_io.h"
#include "modules/io/picture.h"
#include "modules/mesh/quality.h"
#include "modules/mesh/curve_mesh.h"
#include "modules/metric/wall_metric.h"
#include "tests/layers/layer_test_support.h"
#include "tests/published_data.h"

using namespace plaf;
using Eigen::Vector2d;

namespace {

using test::body;

// Certified validity and conformity of the layer mesh (its outer front tagged, so it closes).
QualityReport check(const LayerResult<2>& r) {
  HybridMesh<2> m = r.mesh;
  const int outer = m.add_tag("outer", BoundaryKind::Named);
  CellBlock& b = m.boundary_block(CellType::Line, r.outer.order, outer);
  for (const FrontLoop& l : r.outer.loops)
    b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
  return assess_quality<2>(m, nullptr, QualityOptions{});
}

// A clockwise polygon body with one corner of interior (body-side) angle `angle_deg` at the
// origin, opening to the right, and a rounded far end.
std::vector<Vector2d> wedge(double angle_deg) {
  const double a = angle_deg * M_PI / 360;  // half angle
  std::vector<Vector2d> p = {{0, 0}};
  const double len = 1.0;
  // Upper side from the tip to the far end, round cap, lower side back (clockwise: upper side
  // has the body below it... traverse tip -> upper -> cap -> lower keeps the body on the right).
  for (int i = 1; i <= 8; ++i) p.emplace_back(len * i / 8 * std::cos(a), len * i / 8 * std::sin(a));
  const Vector2d c(len * std::cos(a), 0);
  const double rc = len * std::sin(a);
  for (int i = 1; i < 16; ++i) {
    const double t = M_PI / 2 - M_PI * i / 16;
    p.push_back(c + rc * Vector2d(std::cos(t), std::sin(t)));
  }
  for (int i = 8; i >= 1; --i) p.emplace_back(len * i / 8 * std::cos(a), -len * i / 8 * std::sin(a));
  return p;
}

// A circle of radius r0 through n points (a body), and the wall law h0, g on it with sizes 0.1
// along the wall.
struct CircleCase {
  Geometry2D geo;
  WallPowerLawField metric;
  CircleCase(double r0, int n, double h0, double g)
      : geo(circle_body(r0, n)), metric({geo.loops[0].loop}, law(h0, g)) {}
  static Geometry2D circle_body(double r0, int n) {
    std::vector<Vector2d> c;
    for (int i = 0; i < n; ++i) c.emplace_back(r0 * std::cos(-2 * M_PI * i / n), r0 * std::sin(-2 * M_PI * i / n));
    return body(c, {});
  }
  static WallLawParams law(double h0, double g) {
    WallLawParams w;
    w.h0 = h0;
    w.growth = g;
    w.h_max = 10;
    w.h_wall_max = 0.1;
    return w;
  }
};

}  // namespace

TEST_CASE("layers: on a circle with the wall law, layer k has height h0 g^(k-1), the table says so, and the analytic radius") {
  const double r0 = 1.0, h0 = 1e-3, g = 1.2;
  const CircleCase cc(r0, 128, h0, g);
  const WallPowerLawField& metric = cc.metric;
  const CurvedFront<2> front = mesh_curves(cc.geo, metric, 2);
  layers::LayerParams p;
  p.max_layers = 12;
  const LayerResult<2> r = layers::grow_layers(front, metric, p);
  REQUIRE(r.layers.size() == 12);
  CHECK(r.events.empty());  // no cell had to be shrunk: growth alone keeps them valid
  CHECK(check(r).ok());
  // The outer front's vertices lie at radius r0 + h0 (g^K - 1)/(g - 1) (geometric layers).
  const double expected = r0 + h0 * (std::pow(g, 12) - 1) / (g - 1);
  for (const FrontLoop& l : r.outer.loops)
    for (std::size_t e = 0; e < l.size(); ++e)
      CHECK(r.mesh.nodes[l.elements[e * 3]].norm() == doctest::Approx(expected).epsilon(1e-6));
  // The table's heights are the columns' lengths: h0 g^(k-1) at every vertex.
  const std::size_t vertices = front.loops[0].size();
  for (const LayerStats& st : r.layers) {
    INFO("layer " << st.layer);
    CHECK(st.height_columns == vertices);  // one column per vertex, every vertex measured
    CHECK(st.height_min == doctest::Approx(h0 * std::pow(g, st.layer - 1)).epsilon(1e-9));
    CHECK(st.height_max == doctest::Approx(h0 * std::pow(g, st.layer - 1)).epsilon(1e-9));
    CHECK(st.height_mean == doctest::Approx(h0 * std::pow(g, st.layer - 1)).epsilon(1e-9));
    CHECK(st.f_atten == 0.2);
    CHECK_FALSE(st.shrunk);
  }
  // A probe keeps the columns whose base it accepts: the upper half.
  p.height_probe = [](const Eigen::Vector3d& x) { return x.y() > 0; };
  const LayerResult<2> upper = layers::grow_layers(front, metric, p);
  CHECK(upper.layers[0].height_columns > 0);
  CHECK(upper.layers[0].height_columns < vertices);
  CHECK(upper.layers[3].height_max == doctest::Approx(r.layers[3].height_max));
}

TEST_CASE("layers: an attenuation that folds the cells (f_atten 1 on thin layers) is halved for that layer, an event") {
  // The sag of order-3 elements of size 0.1 on a circle of radius 0.5 is about 2.5e-3, much more
  // than h0 = 1e-4: moving the tops by up to the layer height would flatten the high-order
  // columns to nothing, whatever the height; the layer is rebuilt with f_atten halved.
  const CircleCase cc(0.5, 256, 1e-4, 1.2);
  const WallPowerLawField& metric = cc.metric;
  const CurvedFront<2> front = mesh_curves(cc.geo, metric, 3);
  layers::LayerParams p;
  p.max_layers = 30;
  p.f_atten = 1.0;
  const LayerResult<2> r = layers::grow_layers(front, metric, p);
  REQUIRE(r.layers.size() == 30);
  CHECK(check(r).ok());
  CHECK(r.linear_after > 0);
  CHECK(r.layers[0].f_atten < 1.0);  // the first layer needed a smaller attenuation
  CHECK(r.layers.back().f_atten == 1.0);  // linear fronts need none
  bool event = false;
  for (const std::string& e : r.events) event = event || e.find("rebuilt with f_atten 0.5") != std::string::npos;
  CHECK(event);
  // Every layer moved its tops by at most its own f_atten times the height: the table's
  // attenuation need decreases to 0 and stays there.
  for (std::size_t k = 1; k < r.layers.size(); ++k)
    if (r.layers[k - 1].max_clipped_rel == 0) CHECK(r.layers[k].max_clipped_rel == 0);
}

TEST_CASE("layers: attenuation moves no node by more than f_atten times its height") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int q = 2 + trial % 3;
    std::vector<Vector2d> tops(static_cast<std::size_t>(q + 1)), before;
    std::vector<double> h(static_cast<std::size_t>(q + 1));
    const Vector2d a(0, 0), b(1, 0);
    for (int k = 1; k < q; ++k) {
      tops[static_cast<std::size_t>(k)] = Vector2d(static_cast<double>(k) / q + 0.1 * u(rng), 0.3 * u(rng));
      h[static_cast<std::size_t>(k)] = 0.05 + 0.05 * (u(rng) + 1);
    }
    before = tops;
    const double clipped = layers::attenuate(tops, a, b, h, 0.2);
    bool all_reached = true;
    for (int k = 1; k < q; ++k) {
      const auto i = static_cast<std::size_t>(k);
      const Vector2d target = a + (static_cast<double>(k) / q) * (b - a);
      CHECK((tops[i] - before[i]).norm() <= 0.2 * h[i] * (1 + 1e-12));
      const bool reached = (tops[i] - target).norm() < 1e-12;
      all_reached = all_reached && reached;
      // Either the node reached its linear position, or it moved the full allowance toward it.
      if (!reached) CHECK((tops[i] - before[i]).norm() == doctest::Approx(0.2 * h[i]));
    }
    CHECK((clipped == 0) == all_reached);
  }
}

TEST_CASE("layers: convex corners of 90, 150 and 179 degrees get fans of valid cells") {
  for (double turn : {90.0, 150.0, 179.0}) {
    INFO("turning ", turn);
    // Interior angle of the body at the tip = 180 - turning.
    const Geometry2D geo = body(wedge(180.0 - turn), {0});
    const UniformMetricField<2> metric(Metric<2>::isotropic(0.05));
    const CurvedFront<2> front = mesh_curves(geo, metric, 3);
    layers::LayerParams p;
    p.max_layers = 3;
    const UniformMetricField<2> thin(Metric<2>::from_directions(Eigen::Matrix2d::Identity(), Vector2d(0.01, 0.01)));
    const LayerResult<2> r = layers::grow_layers(front, thin, p);
    CHECK(r.layers.size() == 3);
    const QualityReport q = check(r);
    CHECK(r.events.empty());  // no cell had to be shrunk: growth alone keeps them valid

    CHECK(q.cells_invalid == 0);
    CHECK(q.conformity.ok);
    // A fan: more cells in the first layer than front elements.
    CHECK(r.layers[0].cells > front.loops[0].size());
  }
}

namespace {

// `layers` layers of height h (an isotropic metric) at order q on an L-shaped body (clockwise:
// the corner at (1, 1) turns left by 90 degrees) whose elements are 0.1 long.
LayerResult<2> grow_on_l(int q, int layers, double h) {
  const Geometry2D geo = body({{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}}, {0, 1, 2, 3, 4, 5});
  const CurvedFront<2> front = mesh_curves(geo, UniformMetricField<2>(Metric<2>::isotropic(0.1)), q);
  layers::LayerParams p;
  p.max_layers = layers;
  return layers::grow_layers(front, UniformMetricField<2>(Metric<2>::isotropic(h)), p);
}

}  // namespace

TEST_CASE("layers: a concave 90 degree corner gets valid cells") {
  for (int q = 1; q <= 4; ++q) {
    const LayerResult<2> r = grow_on_l(q, 4, 0.02);
    CHECK(r.layers.size() == 4);
    CHECK(r.events.empty());  // no cell had to be shrunk: growth alone keeps them valid
    const QualityReport qr = check(r);
    CHECK(qr.cells_invalid == 0);
    CHECK(qr.conformity.ok);
  }
}

TEST_CASE("layers: next to a concave corner a layer as tall as the neighbouring element merges their tops into a triangle") {
  // The L-shaped body of the test above, its elements 0.1 long; layers of height h near 0.1 put
  // the corner's top and its neighbour's |0.1 - h| apart (h = 0.0993: 7e-4, a near-duplicate
  // node), or past each other (h > 0.1: a folded quadrilateral).
  for (int q = 1; q <= 4; ++q)
    for (double h : {0.0993, 0.1, 0.104, 0.13}) {
      INFO("order " << q << ", h " << h);
      const LayerResult<2> r = grow_on_l(q, 3, h);
      CHECK(r.layers.size() == 3);
      const QualityReport qr = check(r);
      CHECK(qr.cells_invalid == 0);
      CHECK(qr.conformity.ok);
      // The corner's two neighbours merged (no node stops here, so every triangle is a merge's).
      CHECK(r.layers[0].transition_cells == 2);
      // No two nodes closer than a tenth of the smallest spacing the layers are built with.
      double closest = 1e300;
      for (std::size_t a = 0; a < r.mesh.nodes.size(); ++a)
        for (std::size_t b = a + 1; b < r.mesh.nodes.size(); ++b)
          closest = std::min(closest, (r.mesh.nodes[a] - r.mesh.nodes[b]).norm());
      CHECK(closest > 0.1 * 0.09 / q);
    }
}

TEST_CASE("layers: a layer more than twice as tall as the elements at a concave corner shrinks the corner's top too") {
  // h = 0.25 over elements 0.1 long: the corner's neighbour merges (its top lies past the
  // corner's), and the next element's top runs back from the corner's top. Its failure must
  // lower the corner's height, which lies outside the element's own span; else every shrink
  // leaves the corner's top where it is and the part stops before its first layer (Q >= 2).
  for (int q = 1; q <= 3; ++q) {
    INFO("order " << q);
    const LayerResult<2> r = grow_on_l(q, 1, 0.25);
    CHECK(r.layers.size() == 1);
    const QualityReport qr = check(r);
    CHECK(qr.cells_invalid == 0);
    CHECK(qr.conformity.ok);
  }
}

TEST_CASE("layers: Q = 1..4 on the E387 give valid, conforming layers") {
  PLAF_NEEDS_PUBLISHED("airfoils/e387.dat");
  BodyContour c = read_body_contour(plaf::test::published("airfoils/e387.dat"));
  const Geometry2D geo = body(c.points, c.corners);
  WallLawParams w;
  w.h0 = 0.005;
  w.h_max = 10;
  w.h_wall_max = 0.05;
  w.curvature_factor = 0.3;
  const WallPowerLawField metric({geo.loops[0].loop}, w);
  for (int q = 1; q <= 4; ++q) {
    INFO("Q = ", q);
    const CurvedFront<2> front = mesh_curves(geo, metric, q);
    layers::LayerParams p;
    p.max_layers = 8;
    p.corner_angle_deg = 70;
    const LayerResult<2> r = layers::grow_layers(front, metric, p);
    CHECK(r.layers.size() == 8);
    CHECK(r.events.empty());  // no cell had to be shrunk: growth alone keeps them valid
    const QualityReport qr = check(r);
    CHECK(qr.cells_invalid == 0);
    CHECK(qr.conformity.ok);
  }
}

TEST_CASE("layers: growing from a straight wall leaves every element straight") {
  // A long thin rectangle: its sides are straight, its corners convex.
  const Geometry2D geo = body({{0, 0}, {0, 0.5}, {4, 0.5}, {4, 0}}, {0, 1, 2, 3});
  const UniformMetricField<2> metric(Metric<2>::isotropic(0.2));
  const CurvedFront<2> front = mesh_curves(geo, metric, 3);
  layers::LayerParams p;
  p.max_layers = 5;
  const UniformMetricField<2> thin(Metric<2>::isotropic(0.03));
  const LayerResult<2> r = layers::grow_layers(front, thin, p);
  REQUIRE(r.layers.size() == 5);
  CHECK(r.events.empty());  // no cell had to be shrunk: growth alone keeps them valid
  CHECK(r.linear_after == 1);
  const CellBlock& b = r.mesh.cells.at(0);
  for (std::size_t i = 0; i < b.size(); ++i) CHECK_FALSE(is_curved(r.mesh, b, i, 1e-10));
  CHECK(check(r).ok());
}

TEST_CASE("layers: isotropic_stop node stops the nodes where the metric is isotropic, with transition triangles") {
  // An ellipse (a = 1, b = 0.3): the tips' radius of curvature b^2/a = 0.09 gives the size
  // along the wall 0.1 * 0.09 = 0.009, reached by h0 + (g - 1) d at d = 0.04; the flanks'
  // 0.05 (h_wall_max) only at d = 0.245. So the tips stop layers earlier than the flanks.
  std::vector<Vector2d> p;
  for (int i = 0; i < 200; ++i) p.emplace_back(std::cos(-2 * M_PI * i / 200), 0.3 * std::sin(-2 * M_PI * i / 200));
  const Geometry2D geo = body(p, {});
  WallLawParams w;
  w.h0 = 0.001;
  w.h_max = 5;
  w.h_wall_max = 0.05;
  w.curvature_factor = 0.1;
  w.h_corner = 0.05;
  const WallPowerLawField metric({geo.loops[0].loop}, w);
  const CurvedFront<2> front = mesh_curves(geo, metric, 3);
  layers::LayerParams lp;
  lp.max_layers = 30;
  lp.isotropic_stop = layers::IsotropicStop::Node;
  const LayerResult<2> r = layers::grow_layers(front, metric, lp);
  std::size_t transition = 0;
  for (const auto& st : r.layers) transition += st.transition_cells;
  CHECK(transition > 0);
  const QualityReport q = check(r);
  CHECK(q.cells_invalid == 0);
  CHECK(q.conformity.ok);
  // The outer front reaches farther out on the flanks (x ~ 0) than beyond the tips (|y| ~ 0).
  double flank = 0, tip = 0;
  for (const FrontLoop& l : r.outer.loops)
    for (NodeId id : l.elements) {
      const Vector2d x = r.mesh.nodes[id];
      const double d = geo.loops[0].loop.closest_point(x).distance;
      if (std::abs(x.x()) < 0.1) flank = std::max(flank, d);
      if (std::abs(x.y()) < 0.02) tip = std::max(tip, d);
    }
  CHECK(flank > 2 * tip);
}

TEST_CASE("layers: where the front is concave its columns stop short of their focus, the rest growing the whole stack") {
  // A kidney r(theta) = 1 + 0.35 cos(2 theta): at its waists (theta = +-pi/2, r = 0.65) the wall
  // is concave with radius 0.65^3 / 0.4875 = 0.563, and its columns converge there toward a
  // focus outside the body. 13 layers of h0 = 0.02, g = 1.2 stack 0.59 high: beyond the focus. A column's layer may take at most half the distance to its focus (layer_core.h,
  // graded_room), so the waists' columns stop (the stack that fits: the proximity rule's
  // coverage) and the rest grows all 13 layers; turned off, the waists' cells run into the focus
  // and the loop stops growing early, on the failures.
  std::vector<Vector2d> pts;
  const int n = 160;
  for (int i = 0; i < n; ++i) {
    const double t = -2 * M_PI * i / n, r = 1 + 0.35 * std::cos(2 * t);
    pts.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  const Geometry2D geo = body(pts, {});
  WallLawParams w;
  w.h0 = 0.02;
  w.growth = 1.2;
  w.h_max = 100;
  w.h_wall_max = 0.05;
  const WallPowerLawField metric({geo.loops[0].loop}, w);
  for (int q : {1, 3}) {
    CAPTURE(q);
    const CurvedFront<2> front = mesh_curves(geo, metric, q);
    layers::LayerParams p;
    p.max_layers = 13;
    const LayerResult<2> r = layers::grow_layers(front, metric, p);
    CHECK(r.layers.size() == 13);
    CHECK(r.coverage.complete == 1.0);
    CHECK(r.coverage.proximity > 0);
    CHECK(r.coverage.proximity < 0.7);
    const QualityReport qr = check(r);
    CHECK(qr.cells_invalid == 0);
    CHECK(qr.conformity.ok);
    // The waists' stacks end short of their foci (0.65 + 0.563 from the centre along the y axis),
    // the flanks' (theta = 0, pi) reach the whole stack's 0.59.
    double waist = 0, flank = 0;
    for (const FrontLoop& l : r.outer.loops)
      for (NodeId id : l.elements) {
        const Vector2d x = r.mesh.nodes[id];
        if (std::abs(x.x()) < 0.05) waist = std::max(waist, std::abs(x.y()));
        if (std::abs(x.y()) < 0.05) flank = std::max(flank, std::abs(x.x()));
      }
    MESSAGE("outer front at the waists " << waist << ", at the flanks " << flank << "; limited: " << r.coverage.proximity);
    CHECK(waist < 0.65 + 0.563);
    CHECK(flank > 1.35 + 0.58);
    if (q == 3) {
      p.proximity = 0;
      const LayerResult<2> off = layers::grow_layers(front, metric, p);
      CHECK(off.layers.size() < 13);
    }
  }
}

TEST_CASE("layers: close_linear ends a front that is still curved with one valid straight-topped layer") {
  // A coarse circle: 12 order-3 elements, far from linear after 2 layers of h0 = 1e-3.
  std::vector<Vector2d> c;
  for (int i = 0; i < 64; ++i) c.emplace_back(std::cos(-2 * M_PI * i / 64), std::sin(-2 * M_PI * i / 64));
  const Geometry2D geo = body(c, {});
  WallLawParams w;
  w.h0 = 1e-3;
  w.h_max = 10;
  w.h_wall_max = 0.5;
  w.curvature_factor = 0.5;
  const WallPowerLawField metric({geo.loops[0].loop}, w);
  const CurvedFront<2> front = mesh_curves(geo, metric, 3);
  layers::LayerParams p;
  p.max_layers = 2;
  const LayerResult<2> open = layers::grow_layers(front, metric, p);
  REQUIRE(open.layers.size() == 2);
  CHECK(open.linear_after == -1);  // still curved: the case to close
  p.close_linear = true;
  const LayerResult<2> r = layers::grow_layers(front, metric, p);
  REQUIRE(r.layers.size() == 3);
  CHECK(r.layers.back().linear);
  CHECK(r.linear_after == 3);
  const QualityReport q = check(r);
  CHECK(q.cells_invalid == 0);
  CHECK(q.conformity.ok);
  // Every outer element is straight: its interior nodes on the chord at k/Q.
  for (const FrontLoop& l : r.outer.loops)
    for (std::size_t e = 0; e < l.size(); ++e) {
      const NodeId* n = r.outer.element(l, e);
      const Vector2d a = r.mesh.nodes[n[0]], b = r.mesh.nodes[n[1]];
      for (int k = 1; k < 3; ++k) CHECK((r.mesh.nodes[n[k + 1]] - (a + (b - a) * k / 3.0)).norm() < 1e-12);
    }
}

TEST_CASE("layers: fans grow on the first layer only: NLR 7301's blunt trailing edge at h0 1e-5 keeps its cell count and stays valid") {
  PLAF_NEEDS_PUBLISHED("airfoils/nlr7301.dat");
  // Its two 90 degree trailing-edge corners used to fan again at every kite vertex, multiplying
  // kites until layer 5 folded (issue 12).
  BodyContour c = read_body_contour(plaf::test::published("airfoils/nlr7301.dat"));
  const Geometry2D geo = body(c.points, c.corners);
  WallLawParams w;
  w.h0 = 1e-5;
  w.h_max = 2;
  w.h_wall_max = 0.04;
  w.curvature_factor = 0.3;
  w.h_corner = 0.005;
  const WallPowerLawField metric({geo.loops[0].loop}, w);
  const CurvedFront<2> front = mesh_curves(geo, metric, 3);
  layers::LayerParams p;
  p.max_layers = 12;
  const LayerResult<2> r = layers::grow_layers(front, metric, p);
  REQUIRE(r.layers.size() == 12);
  CHECK(r.events.empty());
  // The trailing edge's fans: k kites add k cells to the first layer and 2k elements to its
  // front, so the second layer has k more cells than the first, and every later layer as many.
  const std::size_t kites = r.layers[0].cells - front.loops[0].size();
  CHECK(kites >= 4);  // two corners of about 90 degrees, at most 45 degrees per kite
  CHECK(r.layers[1].cells == r.layers[0].cells + kites);
  for (std::size_t k = 2; k < r.layers.size(); ++k) CHECK(r.layers[k].cells == r.layers[1].cells);
  const QualityReport qr = check(r);
  CHECK(qr.cells_invalid == 0);
  CHECK(qr.conformity.ok);
}

TEST_CASE("layers: at order 1 a layer counts as curved until its chords' sag is within f_atten of its height") {
  // A circle of radius 1 in about 63 straight elements: each chord (L = 0.1) sags 1.2e-3 off the
  // circle the metric is measured from. With h0 = 1e-5 and g = 1.2 the layers go on until
  // h >= sag / f_atten = 6e-3, at about layer 36, instead of stopping after the first (issue 12:
  // a linear front 1e-6 off a wall its chords miss by 1e-5 sent the fill into slivers).
  const CircleCase cc(1.0, 64, 1e-5, 1.2);
  const CurvedFront<2> front = mesh_curves(cc.geo, cc.metric, 1);
  const std::size_t ne = front.loops[0].size();
  layers::LayerParams p;
  p.max_layers = 60;
  p.stop_when_linear = true;
  const LayerResult<2> r = layers::grow_layers(front, cc.metric, p);
  REQUIRE(r.linear_after > 1);
  // The largest sag over height of the first layer is about 1.2e-3 / 1e-5.
  CHECK(r.layers[0].max_clipped_rel > 50);
  // At the layer it stops, the outer chords sag by at most f_atten times the last height.
  const FrontLoop& l = r.outer.loops[0];
  double worst = 0;
  for (std::size_t e = 0; e < l.size(); ++e) {
    const NodeId* n = r.outer.element(l, e);
    const Vector2d a = r.mesh.nodes[n[0]], b = r.mesh.nodes[n[1]];
    // The outer front is a polygon about a circle of radius |a|: its sag over the chord.
    const double rad = 0.5 * (a.norm() + b.norm()), half = 0.5 * (b - a).norm();
    worst = std::max(worst, (rad - std::sqrt(rad * rad - half * half)) / r.layers.back().height_min);
  }
  CHECK(worst <= p.f_atten * 1.05);
  CHECK(r.layers[static_cast<std::size_t>(r.linear_after) - 2].max_clipped_rel > 0);  // the layer before was not
  CHECK(r.linear_after >= 30);
  CHECK(r.linear_after <= 42);
  CHECK(ne > 50);  // chords of about 0.1, the wall size
  CHECK(check(r).ok());
}
