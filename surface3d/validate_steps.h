// SPDX-License-Identifier: MIT
// Internal to validate_surface (validate.h): the working soup that the steps pass along, and the
// geometric steps that live in their own files: enclosed volumes, inward components and nesting
// (step 6, validate_volumes.cpp) and self-intersections (step 7, self_intersections.cpp). The
// combinatorial steps 0-5 and the assembly are in validate.cpp. Not part of the surface3d API.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "modules/geometry/aabb_tree.h"
#include "modules/geometry/tri_surface.h"
#include "surface3d/validate.h"

namespace plaf::validate_detail {

using Tri = std::array<int, 3>;

inline std::size_t idx(int i) {
  return static_cast<std::size_t>(i);
}

inline std::string fmt_point(const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", p.x(), p.y(), p.z());
  return buf;
}

inline std::string fmt_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

inline std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}
inline std::string plural(std::size_t n, const std::string& one) {
  return plural(n, one, one + "s");
}

// The working soup: triangles (in the input's order, possibly flipped) with their input index.
// An edge is named by its slot 3 t + k: edge k of triangle t, from corner k to corner k + 1.
struct Work {
  const TriangleSoup* soup = nullptr;
  std::vector<Tri> tris;
  std::vector<int> input_index;
  const std::string& source() const { return soup->source; }
  const std::vector<Eigen::Vector3d>& points() const { return soup->points; }
  const Eigen::Vector3d& p(int v) const { return soup->points[idx(v)]; }
  Eigen::Vector3d centroid(int t) const {
    const Tri& x = tris[idx(t)];
    return (p(x[0]) + p(x[1]) + p(x[2])) / 3;
  }
  int slot_from(int s) const { return tris[idx(s / 3)][idx(s % 3)]; }
  int slot_to(int s) const { return tris[idx(s / 3)][idx((s + 1) % 3)]; }
};

// Connected components (step 4): each triangle's component, and each component's triangles (the
// first is where its breadth-first search started).
struct Components {
  std::vector<int> of;
  std::vector<std::vector<int>> tris;
  std::size_t size() const { return tris.size(); }
};

// Boundary loops (step 5), all on symmetry planes.
struct BoundaryLoops {
  std::vector<int> slots;                 // the boundary edges' slots
  std::vector<int> loop_of_slot;          // per boundary edge, its loop
  std::vector<std::vector<char>> planes;  // per loop, the planes its edges lie on
  std::vector<int> comp;                  // per loop, its component
};

// Step 6. The enclosed volume of each component, each boundary loop closed by a fan from an apex
// on the planes it lies on.
std::vector<double> component_volumes(const Work& w, const Components& comps, const BoundaryLoops& loops,
                                      const std::vector<SymmetryPlane>& planes);
// Step 6. A component of (near) zero volume is an error; inward components are flipped (and
// their volumes made positive).
void flip_inward_components(Work& w, const Components& comps, std::vector<double>& volume, SurfaceCheckReport& rep);
// Step 6. Components inside another (ray parity) are an error, or dropped when
// drop_inner_components; returns which triangles are kept (1) and sets rep.components.
std::vector<char> drop_nested_components(const Work& w, const Components& comps, const BoundaryLoops& loops,
                                         const std::vector<SymmetryPlane>& planes, const Eigen::AlignedBox3d& bbox,
                                         const TriangleTree& tree, bool drop_inner_components, SurfaceCheckReport& rep);

// Step 7. The intersecting pairs among the kept triangles are an error naming the first; with
// repair, folded caps among them are flipped first (a repair line).
void check_self_intersections(Work& w, const TriangleTree& tree, const std::vector<char>& alive, bool repair,
                              SurfaceCheckReport& rep);

}  // namespace plaf::validate_detail
