// SPDX-License-Identifier: MIT
#include "modules/mesh/curve_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/base/error.h"

namespace plaf {
inline namespace mesh {

namespace {

// Cumulative metric length along a spline from t0 to t1, tabulated at sub-intervals of each
// spline piece (8 per piece, 3 Gauss points each): the metric may vary faster than the points.
struct LengthTable {
  std::vector<double> t, length;
};

LengthTable metric_length_table(const SplineLoop& loop, const MetricField<2>& metric, double t0, double t1) {
  constexpr int per_piece = 8;
  static const double gx[3] = {0.5 - std::sqrt(0.15), 0.5, 0.5 + std::sqrt(0.15)};
  static const double gw[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  LengthTable tab;
  const int n = std::max(1, static_cast<int>(std::ceil((t1 - t0) * per_piece - 1e-9)));
  tab.t.push_back(t0);
  tab.length.push_back(0);
  for (int k = 0; k < n; ++k) {
    const double a = t0 + (t1 - t0) * k / n, b = t0 + (t1 - t0) * (k + 1) / n;
    double len = 0;
    for (int g = 0; g < 3; ++g) {
      const double t = a + gx[g] * (b - a);
      len += gw[g] * metric.evaluate(loop.point(t)).length(loop.derivative(t)) * (b - a);
    }
    tab.t.push_back(b);
    tab.length.push_back(tab.length.back() + len);
  }
  return tab;
}

// The parameter at cumulative metric length L (linear interpolation in the table).
double parameter_at_length(const LengthTable& tab, double l) {
  const auto it = std::lower_bound(tab.length.begin(), tab.length.end(), l);
  if (it == tab.length.begin()) return tab.t.front();
  if (it == tab.length.end()) return tab.t.back();
  const std::size_t k = static_cast<std::size_t>(it - tab.length.begin());
  const double f = (l - tab.length[k - 1]) / std::max(tab.length[k] - tab.length[k - 1], 1e-300);
  return tab.t[k - 1] + f * (tab.t[k] - tab.t[k - 1]);
}

double wrap(double t, double period) {
  t = std::fmod(t, period);
  return t < 0 ? t + period : t;
}

}  // namespace

CurvedFront<2> mesh_curves(const Geometry2D& geometry, const MetricField<2>& metric, int order) {
  check_order(order);
  CurvedFront<2> front;
  front.order = order;
  for (std::size_t g = 0; g < geometry.loops.size(); ++g) {
    const GeometryLoop& gl = geometry.loops[g];
    const SplineLoop& loop = gl.loop;
    FrontLoop fl;
    fl.tag = gl.tag;
    fl.kind = gl.kind;
    fl.geometry_loop = static_cast<int>(g);

    // 1. Linear nodes: equidistribute the metric length on each corner-to-corner segment.
    std::vector<double> corners(loop.corners().begin(), loop.corners().end());
    const bool periodic = corners.empty();
    if (periodic) corners.push_back(0.0);
    std::vector<double> linear_t;
    std::vector<std::uint8_t> is_corner;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const double t0 = corners[k];
      const double t1 = k + 1 < corners.size() ? corners[k + 1] : corners[0] + loop.period();
      const LengthTable tab = metric_length_table(loop, metric, t0, t1);
      const double total = tab.length.back();
      if (!std::isfinite(total)) throw MesherError("surface mesh: the metric length of " + loop.name() + " is not finite");
      // The rounded metric length, rounded in log space (at sqrt(n (n + 1)) rather than n + 1/2)
      // so that every element's length L/n lies in [1/sqrt 2, sqrt 2] whenever L >= 1/sqrt 2.
      if (total > 5e7) throw MesherError("surface mesh: the metric asks for over 5e7 elements on " + loop.name());
      long n = std::max(1L, static_cast<long>(std::floor(total)));
      if (total > std::sqrt(static_cast<double>(n) * static_cast<double>(n + 1))) ++n;
      for (long e = 0; e < n; ++e) {
        linear_t.push_back(e == 0 ? t0 : parameter_at_length(tab, total * static_cast<double>(e) / static_cast<double>(n)));
        is_corner.push_back(e == 0 && !periodic ? 1 : 0);
      }
    }

    // 2. Nodes: each linear node, then the high-order nodes of the element it starts, placed by
    // uniform arc length between the linear nodes.
    const std::size_t ne = linear_t.size();
    const NodeId first = static_cast<NodeId>(front.nodes.size());
    std::vector<NodeId> linear_id(ne);
    for (std::size_t e = 0; e < ne; ++e) {
      linear_id[e] = static_cast<NodeId>(front.nodes.size());
      front.nodes.push_back(loop.point(wrap(linear_t[e], loop.period())));
      front.params.push_back(wrap(linear_t[e], loop.period()));
      front.normals.push_back(loop.normal(front.params.back()));
    }
    for (std::size_t e = 0; e < ne; ++e) {
      const double ta = linear_t[e];
      double tb = e + 1 < ne ? linear_t[e + 1] : linear_t[0] + loop.period();
      if (tb <= ta) tb += loop.period();
      fl.elements.push_back(linear_id[e]);
      fl.elements.push_back(e + 1 < ne ? linear_id[e + 1] : first);
      const double arc = loop.arc_length(ta, tb);
      for (int j = 1; j < order; ++j) {
        const double t = wrap(loop.parameter_at(ta, arc * j / order), loop.period());
        fl.elements.push_back(static_cast<NodeId>(front.nodes.size()));
        front.nodes.push_back(loop.point(t));
        front.params.push_back(t);
        front.normals.push_back(loop.normal(t));
      }
      fl.corner.push_back(is_corner[e]);
    }
    front.loops.push_back(std::move(fl));
  }
  return front;
}

HybridMesh<2> front_mesh(const CurvedFront<2>& front) {
  HybridMesh<2> mesh;
  mesh.nodes = front.nodes;
  for (const FrontLoop& l : front.loops) {
    const int tag = mesh.add_tag(l.tag, l.kind);
    CellBlock& b = mesh.boundary_block(CellType::Line, front.order, tag);
    b.connectivity.insert(b.connectivity.end(), l.elements.begin(), l.elements.end());
  }
  return mesh;
}

CurveMeshStats curve_mesh_stats(const CurvedFront<2>& front, const Geometry2D& geometry, const MetricField<2>& metric) {
  CurveMeshStats s;
  s.metric_length_min = std::numeric_limits<double>::infinity();
  s.metric_length_max = 0;
  std::size_t total = 0, unit = 0;
  std::vector<double> coords(2 * static_cast<std::size_t>(front.order + 1));
  for (const FrontLoop& l : front.loops) {
    CurveLoopStats ls;
    ls.tag = l.tag;
    ls.elements = l.size();
    ls.nodes = l.size() * static_cast<std::size_t>(front.order);
    ls.metric_length_min = std::numeric_limits<double>::infinity();
    std::size_t run = 0;  // elements of the current corner-to-corner segment
    double run_len = 0;
    for (std::size_t e = 0; e < l.size(); ++e) {
      const NodeId* el = front.element(l, e);
      double len = 0;
      if (l.geometry_loop >= 0) {
        const SplineLoop& loop = geometry.loops[static_cast<std::size_t>(l.geometry_loop)].loop;
        const double ta = front.params[el[0]];
        double tb = front.params[el[1]];
        if (tb <= ta) tb += loop.period();
        len = metric_length_table(loop, metric, ta, tb).length.back();
      } else {
        for (int k = 0; k <= front.order; ++k)
          for (int d = 0; d < 2; ++d) coords[2 * k + d] = front.nodes[el[k]][d];
        len = metric_length_curved<2>(metric, coords.data(), front.order);
      }
      ls.metric_length_min = std::min(ls.metric_length_min, len);
      ls.metric_length_max = std::max(ls.metric_length_max, len);
      ++total;
      if (len >= 1 / std::sqrt(2.0) && len <= std::sqrt(2.0)) ++unit;
      const bool next_corner = e + 1 == l.size() ? l.corner[0] : l.corner[e + 1];
      ++run;
      run_len += len;
      if (next_corner) {
        if (run == 1 && run_len < 1 / std::sqrt(2.0)) ++s.short_segments;
        run = 0;
        run_len = 0;
      }
    }
    s.metric_length_min = std::min(s.metric_length_min, ls.metric_length_min);
    s.metric_length_max = std::max(s.metric_length_max, ls.metric_length_max);
    s.loops.push_back(ls);
  }
  s.unit_fraction = total ? static_cast<double>(unit) / static_cast<double>(total) : 0;
  return s;
}

}  // namespace mesh
}  // namespace plaf
