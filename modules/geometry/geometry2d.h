// SPDX-License-Identifier: MIT
// The 2D geometry of a run: body loops (clockwise) and the farfield loop (counter-clockwise),
// all cubic-spline loops with corners (spline_loop.h), each with its boundary tag.
#pragma once

#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/pipeline/run_config.h"
#include "modules/geometry/spline_loop.h"

namespace plaf {
inline namespace geometry {

struct GeometryLoop {
  SplineLoop loop;
  std::string tag;
  BoundaryKind kind;
};

struct Geometry2D {
  std::vector<GeometryLoop> loops;  // bodies first, then the farfield (if any)
  // Bounding box of the bodies.
  Eigen::Vector2d body_min{0, 0}, body_max{0, 0};
};

// Reads the body files, checks they are simple and disjoint, finds corners (turning angle above
// the threshold, the trailing-edge corners of the reader, and the configured extra corners), and
// adds the farfield circle or rectangle. InputError for bad files, ConfigError for a farfield
// that does not enclose the bodies.
Geometry2D build_airfoils_geometry(const AirfoilsParams& params);

// A circle (periodic spline through `points` points) or an axis-aligned rectangle (4 corners),
// counter-clockwise, tagged "farfield".
SplineLoop farfield_circle(const Eigen::Vector2d& center, double radius, int points = 256);
SplineLoop farfield_rectangle(const Eigen::Vector2d& center, double width, double height);

}  // namespace geometry
}  // namespace plaf
