// SPDX-License-Identifier: MIT
// The 2D geometry of a run: body loops (clockwise) and the farfield loop (counter-clockwise),
// all cubic-spline loops with corners (spline_loop.h), each with its boundary tag. It is the 2D
// reference geometry (reference.h): its curves are the loops, its normals the splines' left
// normals (into the domain).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "modules/geometry/reference.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/io/naca_section.h"
#include "modules/pipeline/config.h"
#include "modules/geometry/spline_loop.h"

namespace plaf {
inline namespace geometry {

// The `airfoils` geometry (its plugin: modules/pipeline/stages.h): bodies from coordinate files
// (airfoil_io.h; data:REL in the data root, modules/pipeline/data_root.h), generated NACA sections
// (modules/pipeline/naca_config.h) or circles, splines with corners, and a circle or rectangle
// farfield. Its keys, types, defaults and descriptions: `plaf keys geometry` (docs/config.md;
// the lines in apps/key_notes.cpp).
struct BodyParams {
  std::string file;  // empty for a circle or a NACA section
  std::string name;
  std::vector<std::array<double, 2>> corners;
  bool circle = false;
  std::array<double, 2> circle_center = {0.0, 0.0};
  double circle_radius = 0;
  std::optional<NacaSection> naca = std::nullopt;  // a generated section instead of a file
};

struct FarfieldParams {
  std::string shape = "circle";
  double radius = 20.0;
  std::array<double, 2> size = {40.0, 40.0};
  bool has_center = false;
  std::array<double, 2> center = {0.0, 0.0};
};

struct AirfoilsParams {
  std::vector<BodyParams> bodies;
  double corner_angle_deg = 30.0;
  FarfieldParams farfield;
};

struct GeometryLoop {
  SplineLoop loop;
  std::string tag;
  BoundaryKind kind;
};

struct Geometry2D final : ReferenceGeometry<2> {
  std::vector<GeometryLoop> loops;  // bodies first, then the farfield (if any)
  // Bounding box of the bodies.
  Eigen::Vector2d body_min{0, 0}, body_max{0, 0};

  // The closest point of any loop (exact on the splines, SplineLoop::closest_point).
  Eigen::Vector2d project(const Eigen::Vector2d& p) const override;
  Eigen::Vector2d project(const Eigen::Vector2d& p, Eigen::Vector2d& normal_out) const override;
  // The left normal of the loop closest to x, at its closest point.
  Eigen::Vector2d normal(const Eigen::Vector2d& x) const override;
  Eigen::Vector2d project_to_curve(const Eigen::Vector2d& p, int curve) const override;
  int num_curves() const override { return static_cast<int>(loops.size()); }
  // The diagonal of the bounding box of every loop's points (1 without loops).
  double scale() const override;
};

// Reads the body files, checks they are simple and disjoint, finds corners (turning angle above
// the threshold, the trailing-edge corners of the reader, and the configured extra corners), and
// adds the farfield circle or rectangle. InputError for bad files, ConfigError for a farfield
// that does not enclose the bodies.
Geometry2D build_airfoils_geometry(const AirfoilsParams& params);

// The airfoils keys of a geometry section (ConfigError naming the key); paths relative to the
// config file's folder.
AirfoilsParams parse_airfoils_params(const ConfigNode& geometry);

// A circle (periodic spline through `points` points) or an axis-aligned rectangle (4 corners),
// counter-clockwise, tagged "farfield".
SplineLoop farfield_circle(const Eigen::Vector2d& center, double radius, int points = 256);
SplineLoop farfield_rectangle(const Eigen::Vector2d& center, double width, double height);

}  // namespace geometry
}  // namespace plaf
