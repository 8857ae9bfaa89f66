// SPDX-License-Identifier: MIT
// CAD slivers in a triangulated body (validate.h, step 8): triangles whose area is below
// max_ratio of their longest edge squared (twice the area over the longest edge squared; 1e-3 is
// about a 0.06 degree angle). CAD tessellations make them where a curve sampled finely meets one
// sampled coarsely: needles, one edge much shorter than the other two (the published Orion
// capsule: 348 of them, 6 long and 0.02 wide, on its back shell), and caps, one vertex nearly on
// the opposite edge.
//
// Why they are repaired before anything else: their normals are noise, so feature detection
// takes their edges for ridges and their ends for corners, which the remesher then keeps; and
// the remesher cannot split their long edges (either half would be as thin, a face no operation
// may make, remesher.h) nor collapse their short edges (the ends are corners). So the wall keeps
// 6-long triangles where it asked for 0.27, and the layers extrude them into cells of aspect ratio
// 5e9, where the columns stop (measured: half of the Orion's lost coverage at order 1 lies
// within 0.1 of such a triangle).
//
// The repair, the thinnest first, until none is left or no operation applies:
// - a needle (shortest edge under a fifth of the longest): its short edge collapsed to one of its
//   ends, the one that moves the surface least (then turns the faces least); the surface moves by the old vertex's
//   distance to the new faces (at most the short edge's length);
// - a cap, or a needle that could not collapse: its longest edge flipped; the surface moves by at
//   most the cap's height over that edge.
// Only slivers that lie in the sheet (within 60 degrees of a good face around their corners; the
// Orion's: 330 of 349, 303 within 5) are repaired: a narrow face of the body's own between sharp
// edges (a blunt trailing edge's base on a long wing, a step: 80-100 degrees) stays. A sliver
// folded back over the sheet (over 90 degrees from the faces across two of its edges, which agree)
// is a fold of the triangulation and is repaired too.
// Every operation is kept only when it moves the surface by at most 5e-4 of the bounding-box
// diagonal (kSliverMaxMoveRel) and no face it changes turns by more than 20 degrees (faces
// thinner than max_ratio, whose normals are noise, only keep within 60 degrees of the good faces
// around them) and no face becomes thinner than it was or max_ratio; vertices on open (symmetry)
// boundaries never move. The caller checks that the repaired surface does not cross itself.
#pragma once

#include <cstddef>

#include "modules/geometry/tri_surface.h"

namespace plaf {

// The largest move an operation may make, over the surface's bounding-box diagonal: half the
// surface stage's default fidelity tolerance (surface.fidelity_tol, 1e-3), so the repaired body
// stays within it of the file's (the Orion's largest: 2.1e-4).
inline constexpr double kSliverMaxMoveRel = 5e-4;

struct SliverRepairReport {
  std::size_t found = 0;       // faces under max_ratio at the start
  std::size_t collapsed = 0;   // short edges collapsed
  std::size_t flipped = 0;     // long edges flipped
  std::size_t left = 0;        // faces still under max_ratio
  double max_moved = 0;        // the largest move of one operation: a removed vertex's distance
                               // to the new faces, or a flipped cap's height
};

inline constexpr double kSliverRatio = 1e-3;

// Twice the area of triangle (a, b, c) over its longest edge squared (0 for a point).
double sliver_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

// Repairs the slivers of s in place (s is garbage-collected at the end when anything changed),
// each operation moving the surface by at most max_move_rel of its bounding-box diagonal.
SliverRepairReport repair_slivers(TriSurface& s, double max_ratio = kSliverRatio, double max_move_rel = kSliverMaxMoveRel);
// The faces of s thinner than max_ratio (what repair_slivers finds).
std::size_t count_slivers(const TriSurface& s, double max_ratio = kSliverRatio);

}  // namespace plaf
