// SPDX-License-Identifier: MIT
// Invariants of the 2D layer stage (layers/grow_layers_2d.h) that must hold whatever its
// implementation:
//  1. scale invariance: a case scaled by s (the geometry and every length of the metric) gives
//     the same layer table and events, and the same nodes times s;
//  2. tiling: the curved cells of layer k cover exactly the region between fronts k-1 and k: their
//     areas (quadrature of det J) sum to the area between the two curved fronts (the boundary
//     integral 1/2 of the loop integral of x dy - y dx), and every cell is certified valid;
//  3. topology: the layers plus the advancing-front fill, assembled as apps/run.cpp does, are a
//     disc with one hole per body, V - E + F = 1 - bodies, and conform;
//  4. heights follow the wall law of modules/metric/wall_metric.h: h0 at the wall, then a
//     geometric series.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "layers/grow_layers_2d.h"
#include "modules/elements/lagrange.h"
#include "modules/elements/validity.h"
#include "modules/io/airfoil_io.h"
#include "modules/mesh/curve_mesh.h"
#include "modules/mesh/hybrid2d.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/wall_metric.h"
#include "tests/layers/layer_test_support.h"
#include "volume/advancing_front_2d.h"

using namespace plaf;
using Eigen::Vector2d;
using test::body;

namespace {

// NACA 4-digit section (max camber m at chord fraction p, thickness t) of chord `chord`, with the
// closed trailing edge (last thickness coefficient -0.1036), n cosine-spaced points per side.
// Abbott and von Doenhoff, Theory of Wing Sections (1959), Sec. 6.4. Clockwise (the body on the
// right): from the trailing edge (point 0, a corner) along the lower side to the leading edge, then
// back along the upper side.
std::vector<Vector2d> naca4(double m, double p, double t, int n, double chord) {
  auto yt = [t](double x) {
    return 5 * t * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x - 0.1036 * x * x * x * x);
  };
  auto side_point = [&](int i, double s) {
    const double x = 0.5 * (1 - std::cos(M_PI * i / n));
    double yc = 0, slope = 0;
    if (m > 0 && x < p) {
      yc = m / (p * p) * (2 * p * x - x * x);
      slope = 2 * m / (p * p) * (p - x);
    } else if (m > 0) {
      yc = m / ((1 - p) * (1 - p)) * (1 - 2 * p + 2 * p * x - x * x);
      slope = 2 * m / ((1 - p) * (1 - p)) * (p - x);
    }
    const double th = std::atan(slope);
    return Vector2d(chord * (x - s * yt(x) * std::sin(th)), chord * (yc + s * yt(x) * std::cos(th)));
  };
  std::vector<Vector2d> pts;
  for (int i = n; i >= 0; --i) pts.push_back(side_point(i, -1));  // lower side, trailing to leading edge
  for (int i = 1; i < n; ++i) pts.push_back(side_point(i, 1));    // upper side back
  return pts;
}

// A clockwise ellipse of semi-axes (a, b) about c, n points.
std::vector<Vector2d> ellipse(const Vector2d& c, double a, double b, int n) {
  std::vector<Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    const double th = -2 * M_PI * i / n;
    pts.push_back(c + Vector2d(a * std::cos(th), b * std::sin(th)));
  }
  return pts;
}

std::vector<SplineLoop> walls_of(const Geometry2D& g) {
  std::vector<SplineLoop> w;
  for (const GeometryLoop& l : g.loops)
    if (l.kind == BoundaryKind::Wall) w.push_back(l.loop);
  return w;
}

// A wall power law whose every length is a multiple of `chord`.
WallLawParams wall_law(double chord) {
  WallLawParams w;
  w.h0 = 1e-3 * chord;
  w.growth = 1.2;
  w.h_max = 1.0 * chord;
  w.h_wall_max = 0.04 * chord;
  w.curvature_factor = 0.3;
  w.h_corner = 0.005 * chord;
  return w;
}

// Gauss-Legendre rule on [0, 1].
struct Gauss {
  explicit Gauss(int n) : x(static_cast<std::size_t>(n)), w(static_cast<std::size_t>(n)) {
    gauss_legendre_01(n, x.data(), w.data());
  }
  std::vector<double> x, w;
};

// Area of a curved 2D cell: the integral of det J over its reference cell. det J of an order-Q
// quadrilateral has degree 2Q - 1 in each variable and that of a triangle total degree 2Q - 2 (one
// more in t after the collapse u = s (1 - t), v = t, whose Jacobian is 1 - t): Q + 1 Gauss points
// per direction integrate both exactly.
double cell_area(const std::vector<Vector2d>& nodes, const CellBlock& b, std::size_t i) {
  const LagrangeElement& el = lagrange_element(b.type, b.order);
  const Gauss g(b.order + 1);
  const NodeId* c = b.cell(i);
  const Vector2d origin = nodes[static_cast<std::size_t>(c[0])];
  std::vector<double> dphi(static_cast<std::size_t>(2 * el.size()));
  double area = 0;
  for (std::size_t a = 0; a < g.x.size(); ++a)
    for (std::size_t bb = 0; bb < g.x.size(); ++bb) {
      double xi[2], w = g.w[a] * g.w[bb];
      if (b.type == CellType::Quadrilateral) {
        xi[0] = g.x[a];
        xi[1] = g.x[bb];
      } else {
        xi[0] = g.x[a] * (1 - g.x[bb]);
        xi[1] = g.x[bb];
        w *= 1 - g.x[bb];
      }
      el.eval_grad(xi, dphi.data());
      Eigen::Matrix2d j = Eigen::Matrix2d::Zero();
      for (int k = 0; k < el.size(); ++k)
        for (int d = 0; d < 2; ++d)
          j.col(d) += (nodes[static_cast<std::size_t>(c[k])] - origin) * dphi[static_cast<std::size_t>(2 * k + d)];
      area += w * j.determinant();
    }
  return area;
}

// Signed area (> 0 counter-clockwise) enclosed by a closed loop of order-q Lagrange edges (Gmsh
// line order): 1/2 of the loop integral of (x dy - y dx), taken about `origin`. Along an edge x(u)
// has degree q, so the integrand has degree 2q - 1: q Gauss points are exact, q + 1 are used.
double enclosed_area(const std::vector<Vector2d>& nodes, const FrontLoop& l, int q, const Vector2d& origin) {
  const LagrangeElement& line = lagrange_element(CellType::Line, q);
  const Gauss g(q + 1);
  std::vector<double> phi(static_cast<std::size_t>(q + 1)), dphi(static_cast<std::size_t>(q + 1));
  double twice = 0;
  for (std::size_t e = 0; e < l.size(); ++e) {
    const NodeId* n = l.elements.data() + e * static_cast<std::size_t>(q + 1);
    for (std::size_t k = 0; k < g.x.size(); ++k) {
      line.eval(&g.x[k], phi.data());
      line.eval_grad(&g.x[k], dphi.data());
      Vector2d x = Vector2d::Zero(), dx = Vector2d::Zero();
      for (int i = 0; i <= q; ++i) {
        const Vector2d p = nodes[static_cast<std::size_t>(n[i])] - origin;
        x += phi[static_cast<std::size_t>(i)] * p;
        dx += dphi[static_cast<std::size_t>(i)] * p;
      }
      twice += g.w[k] * (x.x() * dx.y() - x.y() * dx.x());
    }
  }
  return twice / 2;
}

// The sum of the signed enclosed areas of a front's wall loops.
double enclosed_area(const std::vector<Vector2d>& nodes, const std::vector<FrontLoop>& loops, int q,
                     const Vector2d& origin) {
  double a = 0;
  for (const FrontLoop& l : loops)
    if (l.kind == BoundaryKind::Wall) a += enclosed_area(nodes, l, q, origin);
  return a;
}

const CellBlock* find_block(const HybridMesh<2>& m, CellType type) {
  for (const CellBlock& b : m.cells)
    if (b.type == type) return &b;
  return nullptr;
}

// What the tiling check saw on one case: cells, transition cells, and cells not certified valid.
struct Tiling {
  std::size_t cells = 0, transition_cells = 0, invalid = 0;
};

// Grows the layers of `front`, then for every layer k compares the area of its cells with the area
// between fronts k-1 and k. Front k is the outer front of the same growth stopped after k layers
// (max_layers = k, no closing layer), whose nodes must be the first nodes of the full growth (no
// step looks ahead); the last front is the full growth's own outer front (it may be a closing
// layer's).
Tiling check_tiling(const CurvedFront<2>& front, const MetricField<2>& metric, const layers::LayerParams& p) {
  Tiling t;
  const LayerResult<2> full = layers::grow_layers(front, metric, p);
  REQUIRE(!full.layers.empty());
  const int q = front.order;
  const Vector2d origin = front.nodes[0];
  const CellBlock* quads = find_block(full.mesh, CellType::Quadrilateral);
  const CellBlock* tris = find_block(full.mesh, CellType::Triangle);
  std::vector<double> area(full.layers.size() + 1);
  area[0] = enclosed_area(front.nodes, front.loops, q, origin);
  for (std::size_t k = 1; k < full.layers.size(); ++k) {
    layers::LayerParams pk = p;
    pk.max_layers = static_cast<int>(k);
    pk.close_linear = false;
    const LayerResult<2> prefix = layers::grow_layers(front, metric, pk);
    REQUIRE(prefix.layers.size() == k);
    REQUIRE(prefix.mesh.nodes.size() <= full.mesh.nodes.size());
    CHECK(std::equal(prefix.mesh.nodes.begin(), prefix.mesh.nodes.end(), full.mesh.nodes.begin()));
    area[k] = enclosed_area(prefix.outer.nodes, prefix.outer.loops, q, origin);
  }
  area.back() = enclosed_area(full.outer.nodes, full.outer.loops, q, origin);

  JacobianCertifier certifier;
  std::vector<double> coords;
  std::size_t first_transition = 0;
  for (std::size_t k = 0; k < full.layers.size(); ++k) {
    const LayerStats& st = full.layers[k];
    double cells_area = 0;
    auto add = [&](const CellBlock& b, std::size_t first, std::size_t count) {
      REQUIRE(first + count <= b.size());
      coords.resize(static_cast<std::size_t>(2 * b.nodes_per_cell()));
      for (std::size_t c = first; c < first + count; ++c) {
        cells_area += cell_area(full.mesh.nodes, b, c);
        gather_coords<2>(full.mesh, b, c, coords.data());
        if (!certifier.certify(b.type, b.order, coords.data()).valid) ++t.invalid;
      }
    };
    if (st.cells > 0) {
      REQUIRE(quads != nullptr);
      add(*quads, st.first_cell, st.cells);
    }
    if (st.transition_cells > 0) {
      REQUIRE(tris != nullptr);
      add(*tris, first_transition, st.transition_cells);
    }
    first_transition += st.transition_cells;
    t.cells += st.cells;
    t.transition_cells += st.transition_cells;
    // Walls run clockwise: each front encloses a more negative signed area than the one before.
    const double between = area[k] - area[k + 1];
    INFO("layer ", k + 1, ": cells ", cells_area, ", between the fronts ", between);
    CHECK(between > 0);
    CHECK(std::abs(cells_area - between) < 1e-9 * between);
  }
  // The table accounts for every cell of the mesh.
  CHECK(t.cells == (quads ? quads->size() : 0));
  CHECK(t.transition_cells == (tris ? tris->size() : 0));
  return t;
}

// A case grown at any scale: the geometry and the wall law at chord c, and the layer parameters.
struct ScaledCase {
  const char* name;
  int q_first, q_last;
  std::function<Geometry2D(double)> geometry;
  std::function<WallLawParams(double)> law;
  layers::LayerParams params;
};

layers::LayerParams layer_params(int max_layers, bool close_linear, layers::IsotropicStop stop) {
  layers::LayerParams p;
  p.max_layers = max_layers;
  p.close_linear = close_linear;
  p.isotropic_stop = stop;
  return p;
}

// The ellipse of grow_layers_2d_test.cpp's isotropic_stop case at chord 2c: its tips stop growing
// before its flanks, so the layers end in transition triangles.
WallLawParams ellipse_law(double c) {
  WallLawParams w;
  w.h0 = 1e-3 * c;
  w.h_max = 5 * c;
  w.h_wall_max = 0.05 * c;
  w.curvature_factor = 0.1;
  w.h_corner = 0.05 * c;
  return w;
}

// A coarse circle of radius c in a wall law too fine for its curvature: still curved after two
// layers, so close_linear adds a closing layer.
WallLawParams coarse_circle_law(double c) {
  WallLawParams w;
  w.h0 = 1e-3 * c;
  w.h_max = 10 * c;
  w.h_wall_max = 0.5 * c;
  w.curvature_factor = 0.5;
  return w;
}

const std::vector<ScaledCase>& scaled_cases() {
  static const std::vector<ScaledCase> cases = {
      // With the default corner angle (30 degrees, below the fan angle) the trailing-edge fan's
      // nodes fan again on the next layer; there the layers shrink and stop: events to compare.
      {"NACA 2412 with its trailing-edge fan", 1, 4,
       [](double c) { return body(naca4(0.02, 0.4, 0.12, 80, c), {0}); }, wall_law,
       layer_params(12, true, layers::IsotropicStop::Off)},
      {"ellipse, isotropic_stop node (transition triangles)", 3, 3,
       [](double c) { return body(ellipse({0, 0}, c, 0.3 * c, 200), {}); }, ellipse_law,
       layer_params(30, false, layers::IsotropicStop::Node)},
      {"coarse circle, closing layer", 2, 3, [](double c) { return body(ellipse({0, 0}, c, c, 64), {}); },
       coarse_circle_law, layer_params(2, true, layers::IsotropicStop::Off)},
  };
  return cases;
}

// Vertices, edges and faces of the cells (linear: a quadrilateral is one face with 4 edges).
struct EulerCount {
  std::size_t v = 0, e = 0, f = 0;
  long long chi() const { return static_cast<long long>(v) - static_cast<long long>(e) + static_cast<long long>(f); }
};

EulerCount euler_count(const HybridMesh<2>& m) {
  std::set<NodeId> v;
  std::set<std::pair<NodeId, NodeId>> e;
  EulerCount out;
  for (const CellBlock& b : m.cells) {
    const CellTopology& topo = topology(b.type);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (int k = 0; k < num_vertices(b.type); ++k) v.insert(c[k]);
      for (const auto& ed : topo.edges) e.insert(std::minmax(c[ed[0]], c[ed[1]]));
      ++out.f;
    }
  }
  out.v = v.size();
  out.e = e.size();
  return out;
}

// Layers and the advancing-front fill joined by the driver's assembly (assemble_hybrid_2d) at
// uniform order: the fill's triangles at order Q sharing the layers' outer edges, and the boundary
// lines of the loops the fill meets directly (the farfield) at order Q.
struct Hybrid {
  LayerResult<2> layers;
  HybridMesh<2> mesh;
};

Hybrid layers_and_fill(const CurvedFront<2>& front, const MetricField<2>& metric, const layers::LayerParams& p) {
  Hybrid h;
  h.layers = layers::grow_layers(front, metric, p);
  volume::AdvancingFrontResult fill = volume::advancing_front_fill(h.layers.fill_front, metric);
  const FillResult<2>& f = fill;
  AssemblyOptions o;
  o.order = front.order;
  h.mesh = assemble_hybrid_2d(front, h.layers, &f, o).mesh;
  return h;
}

// Two clockwise ellipses (semi-axes 0.5 and 0.15) one above the other, `gap` apart.
Geometry2D two_bodies(double gap) {
  Geometry2D g = body(ellipse({0, 0}, 0.5, 0.15, 120), {});
  g.loops.push_back({SplineLoop(ellipse({0, 0.3 + gap}, 0.5, 0.15, 120), {}, "upper"), "upper", BoundaryKind::Wall});
  return g;
}

Geometry2D with_farfield(Geometry2D g, const Vector2d& center, double radius) {
  g.loops.push_back({farfield_circle(center, radius), "farfield", BoundaryKind::Farfield});
  return g;
}

}  // namespace

TEST_CASE("layers: a case scaled by 1e-8 to 1e8 gives the same layer table and events and the nodes scaled") {
  struct Run {
    CurvedFront<2> front;
    LayerResult<2> r;
  };
  for (const ScaledCase& sc : scaled_cases())
    for (int q = sc.q_first; q <= sc.q_last; ++q) {
      auto run = [&](double chord) {
        const Geometry2D geo = sc.geometry(chord);
        const WallPowerLawField metric(walls_of(geo), sc.law(chord));
        Run out;
        out.front = mesh_curves(geo, metric, q);
        out.r = layers::grow_layers(out.front, metric, sc.params);
        return out;
      };
      const Run one = run(1.0);
      REQUIRE(!one.r.layers.empty());
      for (double s : {1e-8, 1e-6, 1e6, 1e8}) {
        INFO(std::string(sc.name), ", Q = ", q, ", chord ", s);
        const Run scaled = run(s);
        // The surface mesh the layers start from is the same (else nothing after it can compare).
        REQUIRE(scaled.front.nodes.size() == one.front.nodes.size());
        REQUIRE(scaled.front.loops.size() == one.front.loops.size());
        for (std::size_t l = 0; l < one.front.loops.size(); ++l)
          REQUIRE(scaled.front.loops[l].elements == one.front.loops[l].elements);
        // The layer table and the events.
        const LayerResult<2>& a = one.r;
        const LayerResult<2>& b = scaled.r;
        REQUIRE(b.layers.size() == a.layers.size());
        for (std::size_t k = 0; k < a.layers.size(); ++k) {
          INFO("layer ", k + 1);
          CHECK(b.layers[k].cells == a.layers[k].cells);
          CHECK(b.layers[k].transition_cells == a.layers[k].transition_cells);
          CHECK(b.layers[k].first_cell == a.layers[k].first_cell);
          CHECK(b.layers[k].linear == a.layers[k].linear);
          CHECK(b.layers[k].shrinks == a.layers[k].shrinks);
          CHECK(b.layers[k].max_clipped_rel == doctest::Approx(a.layers[k].max_clipped_rel).epsilon(1e-9));
        }
        CHECK(b.linear_after == a.linear_after);
        CHECK(b.events.size() == a.events.size());
        // The mesh: the same cells and fronts, the nodes scaled (to 1e-9 of the chord).
        REQUIRE(b.mesh.nodes.size() == a.mesh.nodes.size());
        REQUIRE(b.mesh.cells.size() == a.mesh.cells.size());
        for (std::size_t k = 0; k < a.mesh.cells.size(); ++k)
          CHECK(b.mesh.cells[k].connectivity == a.mesh.cells[k].connectivity);
        REQUIRE(b.outer.loops.size() == a.outer.loops.size());
        for (std::size_t l = 0; l < a.outer.loops.size(); ++l)
          CHECK(b.outer.loops[l].elements == a.outer.loops[l].elements);
        REQUIRE(b.fill_front.loops.size() == a.fill_front.loops.size());
        for (std::size_t l = 0; l < a.fill_front.loops.size(); ++l)
          CHECK(b.fill_front.loops[l].nodes == a.fill_front.loops[l].nodes);
        double err = 0;
        for (std::size_t i = 0; i < a.mesh.nodes.size(); ++i)
          err = std::max(err, (b.mesh.nodes[i] / s - a.mesh.nodes[i]).norm());
        CHECK(err < 1e-9);
      }
    }
}

TEST_CASE("layers: the cells of each layer tile the region between its two fronts") {
  {
    const Geometry2D geo = body(naca4(0.02, 0.4, 0.12, 80, 1.0), {0});
    const WallPowerLawField metric(walls_of(geo), wall_law(1.0));
    for (int q = 1; q <= 4; ++q) {
      INFO("NACA 2412, Q = ", q);
      layers::LayerParams p = layer_params(8, true, layers::IsotropicStop::Off);
      p.corner_angle_deg = 60;  // the trailing-edge fan's nodes (about 41 degrees each) do not fan again
      CHECK(check_tiling(mesh_curves(geo, metric, q), metric, p).invalid == 0);
    }
  }
  {
    INFO("L-shaped body: concave and convex corners");
    const Geometry2D geo = body({{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}}, {0, 1, 2, 3, 4, 5});
    const UniformMetricField<2> surface(Metric<2>::isotropic(0.1));
    const UniformMetricField<2> thin(Metric<2>::isotropic(0.02));
    const layers::LayerParams p = layer_params(4, false, layers::IsotropicStop::Off);
    CHECK(check_tiling(mesh_curves(geo, surface, 3), thin, p).invalid == 0);
  }
  for (const ScaledCase& sc : scaled_cases()) {
    INFO(std::string(sc.name));
    const Geometry2D geo = sc.geometry(1.0);
    const WallPowerLawField metric(walls_of(geo), sc.law(1.0));
    const Tiling t = check_tiling(mesh_curves(geo, metric, sc.q_last), metric, sc.params);
    CHECK(t.invalid == 0);
    if (sc.params.isotropic_stop == layers::IsotropicStop::Node) CHECK(t.transition_cells > 0);  // covered
  }
  {
    INFO("two ellipses 0.02 apart: their fronts collide");
    const layers::LayerParams p = layer_params(14, false, layers::IsotropicStop::Off);
    const Geometry2D geo = two_bodies(0.02);
    const WallPowerLawField metric(walls_of(geo), wall_law(1.0));
    CHECK(check_tiling(mesh_curves(geo, metric, 2), metric, p).invalid == 0);
  }
}

TEST_CASE("layers: layers plus fill have the Euler characteristic 1 - bodies and conform") {
  struct HybridCase {
    std::string name;
    Geometry2D geometry;
    WallLawParams law;
    int q_first, q_last;
    layers::IsotropicStop stop;  // Node: layers until the metric is isotropic, ending in transitions
  };
  const std::vector<HybridCase> cases = {
      {"NACA 2412", with_farfield(body(naca4(0.02, 0.4, 0.12, 80, 1.0), {0}), {0.5, 0}, 8), wall_law(1.0), 1, 4,
       layers::IsotropicStop::Off},
      {"ellipse, isotropic_stop node", with_farfield(body(ellipse({0, 0}, 1, 0.3, 200), {}), {0, 0}, 8),
       ellipse_law(1.0), 3, 3, layers::IsotropicStop::Node},
      {"two ellipses 0.1 apart", with_farfield(two_bodies(0.1), {0, 0.2}, 8), wall_law(1.0), 2, 2,
       layers::IsotropicStop::Off},
  };
  for (const HybridCase& hc : cases) {
    const WallPowerLawField metric(walls_of(hc.geometry), hc.law);
    const long long bodies = static_cast<long long>(walls_of(hc.geometry).size());
    for (int q = hc.q_first; q <= hc.q_last; ++q) {
      INFO(hc.name, ", Q = ", q);
      // As apps/run.cpp with a fill: the front closed linear; layers until linear, or with
      // isotropic_stop node until the metric is isotropic.
      layers::LayerParams p = layer_params(40, true, hc.stop);
      p.stop_when_linear = hc.stop == layers::IsotropicStop::Off;
      p.corner_angle_deg = 60;
      const Hybrid h = layers_and_fill(mesh_curves(hc.geometry, metric, q), metric, p);
      REQUIRE(!h.layers.layers.empty());
      std::size_t transition = 0;
      for (const LayerStats& st : h.layers.layers) transition += st.transition_cells;
      if (hc.stop == layers::IsotropicStop::Node) CHECK(transition > 0);  // the case covers them
      // The layers alone are one annulus per body (chi = 0), unless stopped nodes cut them.
      if (hc.stop == layers::IsotropicStop::Off) CHECK(euler_count(h.layers.mesh).chi() == 0);
      const EulerCount n = euler_count(h.mesh);
      INFO("V = ", n.v, ", E = ", n.e, ", F = ", n.f);
      CHECK(n.chi() == 1 - bodies);
      const ConformityReport c = check_conformity(h.mesh);
      INFO(c.first_problem);
      CHECK(c.ok);
    }
  }
}

TEST_CASE("layers: on a flat wall the heights are h0 at the wall and grow geometrically as the wall law says") {
  // The wall law h(d) = h0 + (g - 1) d (wall_metric.h), along the wall normal:
  // - the size (integrate_height off): layer k starts at d_(k-1) and is h(d_(k-1)) high; with
  //   d_0 = 0 that is h_k = h0 g^(k-1), d_k = h0 (g^k - 1) / (g - 1);
  // - unit metric length (integrate_height on): the integral of ds / h(d + s) from 0 to h_k is 1,
  //   so h_k = h(d) (r - 1) / (g - 1) with r = e^(g-1), and h(d + h_k) = r h(d): h_k = h_1 r^(k-1),
  //   h_1 = h0 (r - 1) / (g - 1), d_k = h_1 (r^k - 1) / (r - 1).
  // layer_height integrates with 3-point Gauss: on 1/h over one layer the rule is off by
  // (3!)^4 / (7 (6!)^3) f^(6) with f^(6) <= 6! (r - 1)^6, a relative 5e-8 for g = 1.2, which
  // accumulates in d over the layers: the integrated rows' tolerance is 1e-6.
  const double h0 = 1e-3, g = 1.2, r_int = std::exp(g - 1);
  struct Row {
    bool integrate;
    double first, ratio, tol_rel;
  };
  const Row rows[] = {{false, h0, g, 1e-12}, {true, h0 * (r_int - 1) / (g - 1), r_int, 1e-6}};
  // A 4 x 0.5 rectangle (clockwise): its top side y = 0.5 is the flat wall.
  const double top = 0.5, len = 4;
  const Geometry2D geo = body({{0, 0}, {0, top}, {len, top}, {len, 0}}, {0, 1, 2, 3});
  WallLawParams w;
  w.h0 = h0;
  w.growth = g;
  w.h_max = 1;
  w.h_wall_max = 0.05;
  w.h_corner = 0.01;
  const WallPowerLawField metric(walls_of(geo), w);
  const int max_layers = 10;
  for (const Row& row : rows)
    for (int q = 1; q <= 4; ++q) {
      INFO("integrate_height ", row.integrate, ", Q = ", q);
      layers::LayerParams p = layer_params(max_layers, false, layers::IsotropicStop::Off);
      p.integrate_height = row.integrate;
      p.corner_angle_deg = 60;  // the corner fans' nodes (45 degrees each) do not fan again
      const LayerResult<2> r = layers::grow_layers(mesh_curves(geo, metric, q), metric, p);
      REQUIRE(r.layers.size() == static_cast<std::size_t>(max_layers));
      REQUIRE(r.events.empty());  // no height was halved: the law alone sets them
      const CellBlock* quads = find_block(r.mesh, CellType::Quadrilateral);
      REQUIRE(quads != nullptr);
      for (std::size_t k = 0; k < r.layers.size(); ++k) {
        INFO("layer ", k + 1);
        const double expected_h = row.first * std::pow(row.ratio, static_cast<double>(k));
        const double expected_d = row.first * (std::pow(row.ratio, static_cast<double>(k)) - 1) / (row.ratio - 1);
        std::size_t columns = 0;
        for (std::size_t c = r.layers[k].first_cell; c < r.layers[k].first_cell + r.layers[k].cells; ++c) {
          // Quadrilateral vertices (lagrange.h): 0 and 1 on the base, 3 above 0 and 2 above 1. Only
          // the columns on the middle half of the top side, away from the corners' fans.
          const NodeId* n = quads->cell(c);
          for (const auto& [base, tip] : {std::pair{n[0], n[3]}, std::pair{n[1], n[2]}}) {
            const Vector2d x = r.mesh.nodes[static_cast<std::size_t>(base)];
            const Vector2d y = r.mesh.nodes[static_cast<std::size_t>(tip)];
            if (x.y() < top - 1e-9 || x.x() < len / 4 || x.x() > 3 * len / 4) continue;
            ++columns;
            CHECK(std::abs(x.y() - top - expected_d) < row.tol_rel * expected_h);
            CHECK(std::abs((y - x).norm() - expected_h) < row.tol_rel * expected_h);
            CHECK(std::abs(y.x() - x.x()) < 1e-9 * expected_h);  // along the wall normal
          }
        }
        CHECK(columns > 0);
      }
    }
}

TEST_CASE("layers: on a circle the first layer is h0 high and the layers grow by g") {
  // A circle of radius r0 in the wall law h(d) = h0 + (g - 1) d with a constant tangential size:
  // a uniform surface mesh, so the fronts stay circles and every vertex normal is radial. Layer
  // k's vertices then sit at wall distance d_(k-1), d_k = h0 (g^k - 1) / (g - 1), and are
  // h0 g^(k-1) high (as on a flat wall), to round-off: the metric measures d from the wall, the
  // cubic spline the vertices start on. That spline runs through 512 points of the circle and
  // is off it by up to (5/384) (2 pi / 512)^4 r0 = 3e-10 r0 (the interpolation bound), 3e-7 h0:
  // the vertices' radius is r0 + d_(k-1) to 1e-6 h0 only, and their normal radial to 1e-6.
  const double r0 = 1, h0 = 1e-3, g = 1.2;
  const Geometry2D geo = body(ellipse({0, 0}, r0, r0, 512), {});
  WallLawParams w;
  w.h0 = h0;
  w.growth = g;
  w.h_max = 10;
  w.h_wall_max = 0.05;
  w.curvature_factor = 0.5;
  const WallPowerLawField metric(walls_of(geo), w);
  const int max_layers = 10;
  for (int q = 1; q <= 4; ++q) {
    INFO("Q = ", q);
    const layers::LayerParams p = layer_params(max_layers, false, layers::IsotropicStop::Off);
    const LayerResult<2> r = layers::grow_layers(mesh_curves(geo, metric, q), metric, p);
    REQUIRE(r.layers.size() == static_cast<std::size_t>(max_layers));
    REQUIRE(r.events.empty());  // no height was halved: the law alone sets them
    const CellBlock* quads = find_block(r.mesh, CellType::Quadrilateral);
    REQUIRE(quads != nullptr);
    for (std::size_t k = 0; k < r.layers.size(); ++k) {
      INFO("layer ", k + 1);
      const double expected_h = h0 * std::pow(g, static_cast<double>(k));
      const double expected_d = h0 * (std::pow(g, static_cast<double>(k)) - 1) / (g - 1);
      for (std::size_t c = r.layers[k].first_cell; c < r.layers[k].first_cell + r.layers[k].cells; ++c) {
        const NodeId* n = quads->cell(c);  // vertex 3 is above vertex 0
        const Vector2d x = r.mesh.nodes[static_cast<std::size_t>(n[0])];
        const Vector2d y = r.mesh.nodes[static_cast<std::size_t>(n[3])];
        CHECK(std::abs((y - x).norm() - expected_h) < 1e-9 * expected_h);
        CHECK(std::abs(x.norm() - r0 - expected_d) < 1e-6 * expected_h);
        // Radial: the sine of the column's angle to x.
        CHECK(std::abs(x.x() * y.y() - x.y() * y.x()) < 1e-6 * x.norm() * (y - x).norm());
      }
    }
  }
}
