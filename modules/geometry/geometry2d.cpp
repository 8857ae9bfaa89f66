// SPDX-License-Identifier: MIT
#include "modules/geometry/geometry2d.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/io/airfoil_io.h"
#include "modules/base/coordinates.h"
#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/pipeline/naca_config.h"

namespace plaf {
inline namespace geometry {

namespace {

std::array<double, 2> get_pair(const ConfigNode& n, const std::string& key, std::array<double, 2> fallback) {
  const std::vector<double> v = n.get_double_list(key, {fallback[0], fallback[1]});
  if (v.size() != 2) throw ConfigError(n.where(key) + ": expected two numbers [a, b]");
  return {v[0], v[1]};
}

// A circle body: 256 points clockwise (the body convention), no corner.
BodyContour circle_contour(const BodyParams& b) {
  BodyContour c;
  c.file = "circle";
  c.title = "circle of radius " + std::to_string(b.circle_radius);
  constexpr int n = 256;
  for (int i = 0; i < n; ++i) {
    const double a = -2 * M_PI * i / n;
    c.points.emplace_back(b.circle_center[0] + b.circle_radius * std::cos(a),
                          b.circle_center[1] + b.circle_radius * std::sin(a));
    c.lines.push_back(0);
  }
  return c;
}

}  // namespace

AirfoilsParams parse_airfoils_params(const ConfigNode& g) {
  AirfoilsParams a;
  const std::vector<ConfigNode> bodies = g.child_list("bodies");
  if (bodies.empty()) throw ConfigError(g.where("bodies") + ": give at least one body: [{file: contour.dat}]");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ConfigNode& b = bodies[i];
    BodyParams body;
    body.file = b.get_path("file", "");
    body.naca = parse_naca(b);
    body.circle = b.has("circle");
    if (!body.file.empty() + body.circle + body.naca.has_value() > 1)
      throw ConfigError(b.where() + ": give a body one of file, naca or circle");
    if (body.circle) {
      const ConfigNode c = b.child("circle");
      body.circle_center = get_pair(c, "center", body.circle_center);
      if (!c.has("radius")) throw ConfigError(c.where() + ": radius is required");
      body.circle_radius = c.get_positive("radius", 1.0);
    } else if (body.file.empty() && !body.naca) {
      throw ConfigError(b.where() + ": file, naca or circle is required");
    }
    body.name = b.get_string("name", i == 0 ? "wall" : "wall_" + std::to_string(i + 1));
    // A body tagged "farfield" would merge with the farfield loop's tag (and make it a wall).
    if (body.name.empty() || body.name == "farfield")
      throw ConfigError(b.where("name") + ": '" + body.name +
                        "' cannot tag a body (\"farfield\" is the farfield's tag)");
    body.corners = b.get_point_list("corners");
    a.bodies.push_back(body);
  }
  a.corner_angle_deg = g.get_in_range("corner_angle_deg", a.corner_angle_deg, 0.0, 180.0);
  const ConfigNode f = g.child("farfield");
  FarfieldParams& ff = a.farfield;
  ff.shape = f.get_choice("shape", ff.shape, {"circle", "rectangle"});
  // Within the readers' coordinate range (modules/base/coordinates.h), so plaf reads back what it writes.
  ff.radius = f.get_in_range("radius", ff.radius, 0.0, kMaxCoordinate / 2, Bounds::OpenLow);
  ff.size = get_pair(f, "size", ff.size);
  if (!(ff.size[0] > 0 && ff.size[1] > 0 && ff.size[0] <= kMaxCoordinate && ff.size[1] <= kMaxCoordinate))
    throw ConfigError(f.where("size") + ": sizes must be positive and at most " + num(kMaxCoordinate));
  ff.has_center = f.has("center");
  ff.center = get_pair(f, "center", ff.center);
  if (!(std::abs(ff.center[0]) <= kMaxCoordinate / 2 && std::abs(ff.center[1]) <= kMaxCoordinate / 2))
    throw ConfigError(f.where("center") + ": coordinates must be within +-" + num(kMaxCoordinate / 2));
  return a;
}

SplineLoop farfield_circle(const Eigen::Vector2d& center, double radius, int points) {
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < points; ++i) {
    const double a = 2 * M_PI * i / points;
    p.push_back(center + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return SplineLoop(std::move(p), {}, "farfield");
}

SplineLoop farfield_rectangle(const Eigen::Vector2d& center, double width, double height) {
  const Eigen::Vector2d h(width / 2, height / 2);
  std::vector<Eigen::Vector2d> p = {center + Eigen::Vector2d(-h[0], -h[1]), center + Eigen::Vector2d(h[0], -h[1]),
                                    center + Eigen::Vector2d(h[0], h[1]), center + Eigen::Vector2d(-h[0], h[1])};
  return SplineLoop(std::move(p), {0, 1, 2, 3}, "farfield");
}

Geometry2D build_airfoils_geometry(const AirfoilsParams& params) {
  // 1. Contours: read, check, and find their corners.
  std::vector<BodyContour> contours;
  for (const BodyParams& b : params.bodies) contours.push_back(b.circle ? circle_contour(b) : b.naca ? naca_contour(*b.naca) : read_body_contour(b.file));
  check_disjoint(contours);
  Geometry2D g;
  g.body_min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  g.body_max = -g.body_min;
  for (std::size_t k = 0; k < contours.size(); ++k) {
    const BodyContour& c = contours[k];
    std::vector<int> corners = detect_corners(c.points, params.corner_angle_deg);
    corners.insert(corners.end(), c.corners.begin(), c.corners.end());
    for (const auto& xy : params.bodies[k].corners) {
      const Eigen::Vector2d x(xy[0], xy[1]);
      int best = 0;
      for (int i = 1; i < static_cast<int>(c.points.size()); ++i)
        if ((c.points[i] - x).norm() < (c.points[best] - x).norm()) best = i;
      corners.push_back(best);
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    for (const auto& p : c.points) {
      g.body_min = g.body_min.cwiseMin(p);
      g.body_max = g.body_max.cwiseMax(p);
    }
    g.loops.push_back({SplineLoop(c.points, corners, c.file), params.bodies[k].name, BoundaryKind::Wall});
  }

  // 2. Farfield around the bodies.
  const FarfieldParams& f = params.farfield;
  const Eigen::Vector2d center =
      f.has_center ? Eigen::Vector2d(f.center[0], f.center[1]) : Eigen::Vector2d(0.5 * (g.body_min + g.body_max));
  SplineLoop far = f.shape == "circle" ? farfield_circle(center, f.radius)
                                       : farfield_rectangle(center, f.size[0], f.size[1]);
  // The farfield must enclose every body point with a margin.
  for (const GeometryLoop& b : g.loops)
    for (const auto& p : b.loop.points()) {
      const Eigen::Vector2d d = p - center;
      const bool inside = f.shape == "circle" ? d.norm() < f.radius
                                              : std::abs(d[0]) < f.size[0] / 2 && std::abs(d[1]) < f.size[1] / 2;
      if (!inside)
        throw ConfigError("geometry.farfield: the " + f.shape + " does not enclose the body " + b.loop.name() +
                          " (point " + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ")");
    }
  g.loops.push_back({std::move(far), "farfield", BoundaryKind::Farfield});
  return g;
}

Eigen::Vector2d Geometry2D::project(const Eigen::Vector2d& p, Eigen::Vector2d& normal_out) const {
  if (loops.empty()) throw Error("geometry: no loop to project onto");
  const GeometryLoop* best = nullptr;
  SplineLoop::Closest c{0, p, std::numeric_limits<double>::infinity()};
  for (const GeometryLoop& l : loops) {
    const SplineLoop::Closest k = l.loop.closest_point(p);
    if (k.distance < c.distance) {
      c = k;
      best = &l;
    }
  }
  normal_out = best->loop.normal(c.t);
  return c.point;
}

Eigen::Vector2d Geometry2D::project(const Eigen::Vector2d& p) const {
  Eigen::Vector2d n;
  return project(p, n);
}

Eigen::Vector2d Geometry2D::normal(const Eigen::Vector2d& x) const {
  Eigen::Vector2d n;
  project(x, n);
  return n;
}

Eigen::Vector2d Geometry2D::project_to_curve(const Eigen::Vector2d& p, int curve) const {
  if (curve < 0 || curve >= num_curves()) throw Error("geometry: no loop " + std::to_string(curve));
  return loops[static_cast<std::size_t>(curve)].loop.closest_point(p).point;
}

double Geometry2D::scale() const {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const GeometryLoop& l : loops)
    for (const Eigen::Vector2d& x : l.loop.points()) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  return loops.empty() ? 1.0 : (hi - lo).norm();
}

}  // namespace geometry
}  // namespace plaf
