// SPDX-License-Identifier: MIT
// Validation of a triangle soup into a TriSurface: every problem is either repaired (and
// reported) or an InputError whose one line names the source, the count and the first example.
//
// In this order:
//  1. degenerate triangles: a repeated vertex -> dropped (repair); zero area with three distinct
//     vertices (exact collinearity test) -> error;
//  2. duplicate triangles (the same three vertices, either orientation) -> all but the first
//     dropped (repair);
//  3. non-manifold edges (used by more than two triangles) -> error; non-manifold vertices (their
//     triangles form more than one fan) -> error;
//  4. inconsistent orientation -> fixed per connected component by flipping triangles to agree
//     with the component's first triangle (a non-orientable component -> error);
//  5. open boundaries: every boundary loop must lie on a declared symmetry plane (all its
//     vertices within plane_tol_rel x bbox diagonal); those edges get the tag "symmetry" (kind
//     Symmetry) and EdgeFeature::Boundary; any other open loop -> error naming its edge count
//     and a point on it;
//  6. inward orientation -> fixed per component by the sign of its enclosed volume (closed by the
//     symmetry planes, so an open half model counts too); a component with (near) zero volume ->
//     error; components nested inside another (a point of one inside the other, by ray parity)
//     -> dropped (a repair line: inside a closed body they never meet the flow; CAD exports and
//     scans carry such pieces, e.g. the published Orion capsule's two), or an error when
//     drop_inner_components is false (geometry.inner_components: error);
//  7. self-intersections: triangle pairs from the AABB tree's overlapping boxes tested exactly
//     (predicates.h); pairs sharing a vertex or an edge count only if they overlap beyond it.
//     Folded caps among them (slivers with an angle over 170 degrees whose tip lies across their
//     long edge, folding them over their neighbours: CAD tessellations make them) get their long
//     edge flipped (repair_folded_caps, a repair line with how far the surface moved), and so are,
//     first, folded caps back to back with the surface all around that cross nothing (the sheet
//     around them not flat; its own repair line); the pairs left -> error naming the count and
//     the first pair with a point;
//  8. CAD slivers (slivers.h: needles and caps thinner than 1e-3 of their longest edge) ->
//     needles' short edges collapsed, caps' long edges flipped (repair_slivers, a repair line with
//     how far the surface moved and how many are left); undone, with a line saying so, if the
//     repaired surface would cross itself.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "modules/geometry/tri_surface.h"

namespace plaf {

struct SymmetryPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit normal
  double offset = 0;                                  // plane: normal . x = offset
};

struct SurfaceCheckOptions {
  std::vector<SymmetryPlane> symmetry_planes;
  double plane_tol_rel = 1e-6;
  bool check_self_intersections = true;
  bool repair_folded_caps = true;  // step 7's repair
  bool repair_slivers = true;      // step 8
  bool drop_inner_components = true;
  std::string wall_tag = "wall";
};

struct SurfaceCheckReport {
  std::size_t input_triangles = 0;
  std::size_t dropped_degenerate = 0;
  std::size_t dropped_duplicate = 0;
  std::size_t flipped_inconsistent = 0;  // triangles flipped to agree with their component
  std::size_t flipped_inward = 0;        // triangles flipped because their component was inward
  std::size_t dropped_inner = 0;         // triangles of dropped nested components
  std::size_t components = 0;
  std::size_t boundary_loops = 0;        // all on symmetry planes
  std::size_t symmetry_edges = 0;
  std::size_t self_intersection_pairs_tested = 0;
  std::size_t slivers_found = 0;         // step 8: faces thinner than kSliverRatio
  std::size_t slivers_left = 0;          //   and after the repair
  double volume = 0;                     // enclosed volume after the fixes (> 0)
  long euler_characteristic = 0;
  std::vector<std::string> repairs;      // one line per repair made, for the report and stderr
};

TriSurface validate_surface(const TriangleSoup& soup, const SurfaceCheckOptions& options,
                            SurfaceCheckReport* report = nullptr);

// The self-intersection test alone (step 7), on any surface; returns the number of intersecting
// pairs and describes the first in *first (if given).
std::size_t count_self_intersections(const TriSurface& s, std::string* first = nullptr);
// The intersecting pairs themselves (face indices, deleted faces skipped).
std::vector<std::pair<int, int>> self_intersecting_pairs(const TriSurface& s);

}  // namespace plaf
