// SPDX-License-Identifier: MIT
// Internal to surface3d: triangulation of a simple planar polygon, for the flat ends of wings and
// the half disc closing a blunt trailing edge under a rounded end (analytic.h), and for the
// concave polygons of OBJ, OFF and PLY files in their plane (read_surface.cpp). Ear
// clipping with exact orientation tests (predicates.h), then Lawson flips until every interior
// edge is locally Delaunay: the constrained Delaunay triangulation of the polygon, with no small
// angles that the polygon does not force.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace plaf::analytic_detail {

// Triangles (indices into pts, counter-clockwise) of the simple polygon pts (either
// orientation). MesherError naming `name` for fewer than 3 points or a polygon that is not simple.
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Eigen::Vector2d>& pts, const std::string& name);

// Whether the closed polygon is simple (no two non-adjacent edges meet; exact tests).
bool polygon_is_simple(const std::vector<Eigen::Vector2d>& p);

}  // namespace plaf::analytic_detail
