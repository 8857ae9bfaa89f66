// SPDX-License-Identifier: MIT
// Analytic bodies: an exact reference geometry (closest-point projection, normals, feature curves)
// and an initial triangulation on it whose features and tags are already set (edge_curve numbered
// as the reference's curves, edge_feature, vertex_feature; faces tagged "wall", open edges on
// symmetry planes tagged "symmetry"). The initial triangulation is coarse but valid and roughly
// uniform at about `h` (the remesher then conforms it to the metric).
//
// - sphere: centre, radius (an icosahedron refined and projected);
// - ellipsoid: centre, semi-axes (a, b, c) along x, y, z (closest point by Newton on the
//   Lagrange-multiplier equation);
// - box: axis-aligned, corners lo and hi; 12 convex ridge curves, 8 convex corners;
// - wing: a straight wing along +z from z = 0 to z = span, its section a 2D airfoil file or a NACA section (chord
//   along x, thickness along y, as read by airfoil_io.h with the spline loop and corners of
//   spline_loop.h) scaled by chord; each end is a flat tip (a planar cap, ridge curve along the
//   section contour), a rounded tip (a half body of revolution about the section's camber line:
//   at chord station x the cap's cross-section is a half circle through the upper and lower
//   surface points, tangent-continuous with the wing) or a symmetry plane (open, the section
//   contour tagged "symmetry"). Trailing-edge corners of the section give ridge curves along the
//   span.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "modules/geometry/tri_surface.h"
#include "modules/io/naca_section.h"
#include "surface3d/discrete_reference.h"

namespace plaf {

struct AnalyticBody {
  std::unique_ptr<ReferenceGeometry<3>> reference;
  TriSurface initial;
};

AnalyticBody make_sphere(const Eigen::Vector3d& center, double radius, double h);
AnalyticBody make_ellipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& semi_axes, double h);
AnalyticBody make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h);

enum class WingEnd { Flat, Rounded, Symmetry };
struct WingParams {
  std::filesystem::path file;        // airfoil coordinates (Selig or Lednicer), or
  std::optional<NacaSection> naca;   // a generated NACA section (modules/io/naca_section.h)
  double chord = 1;
  double span = 1;
  WingEnd root = WingEnd::Symmetry;  // at z = 0
  WingEnd tip = WingEnd::Flat;       // at z = span
  double corner_angle_deg = 30;      // section corners (trailing edge), as in 2D
};
AnalyticBody make_wing(const WingParams& params, double h);

}  // namespace plaf
