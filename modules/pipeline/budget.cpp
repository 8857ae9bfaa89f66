// SPDX-License-Identifier: MIT
// Implements budget.h.
#include "modules/pipeline/budget.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/geometry/predicates.h"
#include "modules/metric/metric_integrals.h"

namespace plaf {
inline namespace pipeline {

void check_limit(const RunConfig& c, const std::string& key, double estimate, const std::string& what) {
  const double limit = key == "surface_elements" ? c.limits.surface_elements
                       : key == "cells"          ? c.limits.cells
                                                 : c.limits.nodes;
  if (!(estimate > limit)) return;
  const std::string where = c.file.empty() ? std::string() : c.file.string() + ": ";
  std::ostringstream about;  // two digits: an estimate
  about << std::setprecision(2) << estimate;
  throw ConfigError(where + "limits." + key + ": " + what + " would make about " + about.str() +
                    " (budget " + num(limit) + "); coarsen the metric or raise limits." + key);
}

void check_layer_budget(const RunConfig& c, double wall_elements, int max_layers, int dim, bool estimated) {
  const double cells = wall_elements * max_layers, q = c.order;
  const std::string what = "up to " + std::to_string(max_layers) + " layers (layers.max) on " + (estimated ? "about " : "") +
                           std::to_string(static_cast<long>(wall_elements)) + " wall elements";
  check_limit(c, "cells", cells, what);
  check_limit(c, "nodes", cells * (dim == 2 ? q * q : q * q * q / 2), what + " of order " + std::to_string(c.order));
}

namespace {

// The polygon of a loop's interpolation points: inside by the even-odd rule, with its bounding
// box for a quick rejection.
struct LoopPolygon {
  std::vector<Eigen::Vector2d> points;
  Eigen::Vector2d lo, hi;
  explicit LoopPolygon(const SplineLoop& loop) {
    constexpr int per_piece = 4;
    const int n = loop.num_points() * per_piece;
    for (int i = 0; i < n; ++i) points.push_back(loop.point(loop.period() * i / n));
    lo = hi = points.front();
    for (const Eigen::Vector2d& p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  bool contains(const Eigen::Vector2d& x) const {
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) return false;
    return inside_polygon(x, points);
  }
};

}  // namespace

void check_section_budget(const RunState<2>& s, int rows) {
  const RunConfig& c = s.config;
  const MetricField<2>& metric = *s.metric;
  const double q = c.order;
  const double r = rows;
  const std::string times = rows > 1 ? " (the section times its " + std::to_string(rows) + " rows)" : std::string();
  if (s.annulus) {
    // The annulus is meshed whole by its surface stage: quadrilaterals (or triangles) of unit
    // metric size.
    const AnnulusParams& a = *s.annulus;
    const double phi = a.angle_deg * std::numbers::pi / 180.0;
    const double area = metric_measure<2>(
        Eigen::Vector2d(-a.r_outer, -a.r_outer), Eigen::Vector2d(a.r_outer, a.r_outer),
        [&](const Eigen::Vector2d& x) {
          const double rho = x.norm();
          double theta = std::atan2(x.y(), x.x());
          if (theta < 0) theta += 2 * std::numbers::pi;
          return rho >= a.r_inner && rho <= a.r_outer && theta <= phi;
        },
        metric, 20000);
    check_limit(c, "cells", area * (a.triangles ? 2 : 1), "the annulus");  // two triangles per quadrilateral
    check_limit(c, "nodes", area * q * q, "the annulus' order-" + std::to_string(c.order) + " cells");
    return;
  }
  // The loops' curve elements: bodies (walls) and the farfield.
  double curve = 0, wall = 0;
  for (const GeometryLoop& l : s.geometry.loops) {
    const double n = metric_length(l.loop, metric);
    curve += n;
    if (l.kind == BoundaryKind::Wall) wall += n;
  }
  if (rows > 1) {
    // The extruded wall: two order-Q triangles per curve element and row (extrude_front.h).
    check_limit(c, "surface_elements", 2 * wall * r, "the extruded wall's triangles" + times);
    check_limit(c, "nodes", 2 * wall * r * q * q / 2, "the extruded wall's order-" + std::to_string(c.order) + " triangles");
  } else {
    check_limit(c, "surface_elements", curve, "the curves of the bodies and the farfield");
    check_limit(c, "nodes", curve * q, "the order-" + std::to_string(c.order) + " curves");
  }
  // The domain (a fill): inside the farfield, outside the bodies; its layers are counted in it
  // as far as the tree resolves them, and by the layer stage from its columns.
  if (!c.fill.enabled()) return;
  const LoopPolygon* farfield = nullptr;
  std::vector<LoopPolygon> polygons;
  polygons.reserve(s.geometry.loops.size());
  for (const GeometryLoop& l : s.geometry.loops) polygons.emplace_back(l.loop);
  for (std::size_t i = 0; i < polygons.size(); ++i)
    if (s.geometry.loops[i].kind == BoundaryKind::Farfield) farfield = &polygons[i];
  Eigen::Vector2d lo = s.geometry.body_min, hi = s.geometry.body_max;
  if (farfield) {
    lo = farfield->lo;
    hi = farfield->hi;
  }
  const double area = metric_measure<2>(
      lo, hi,
      [&](const Eigen::Vector2d& x) {
        if (farfield && !farfield->contains(x)) return false;
        for (std::size_t i = 0; i < polygons.size(); ++i)
          if (&polygons[i] != farfield && polygons[i].contains(x)) return false;
        return true;
      },
      metric, 20000);
  const double cells = kTrianglesPerMetricArea * area * r;
  check_limit(c, "cells", cells, "the domain's cells" + times);
  check_limit(c, "nodes", cells * q * q / 2 * (rows > 1 ? q : 1.0),
              "the domain's order-" + std::to_string(c.order) + " cells" + times);
}

}  // namespace pipeline
}  // namespace plaf
