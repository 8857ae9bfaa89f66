// SPDX-License-Identifier: MIT
// 3D volume fill with TetGen (H. Si, "TetGen, a Delaunay-based quality tetrahedral mesh
// generator", ACM TOMS 41, 2015): linear tetrahedra in the region a LinearFront<3> bounds, with
// the front preserved exactly (no Steiner point on it, switch Y) and the inside of every body
// left empty (its hole point, switch p with a hole list).
//
// The result follows the node-numbering contract of linear_front.h: front.nodes first, unchanged
// and with the same ids (also the nodes no front triangle uses: they are not given to TetGen and
// no tet uses them), then TetGen's new interior nodes. Tets are in plaf's order (lagrange.h,
// hybrid_mesh.h): det [b - a, c - a, d - a] > 0, checked with the exact orient3d.
//
// Contract checked on the result: every front triangle is a face of exactly one tet, and that tet
// lies on the side of the triangle's right-hand normal (linear_front.h: normals into the region to
// fill). A triangle of no tet means TetGen split it or carved the region next to it away (a
// MesherError); a triangle of two tets, or of one tet behind it, means the front or its holes do
// not describe the region (an InputError: most often a body without a hole point, whose inside
// TetGen then fills too).
//
// TetGen runs in a child process (fork, POSIX): TetGen 1.5.0 crashes with a double free on every
// error it reports (tetgen_fill.cpp, run_tetgen), and in a child that crash becomes a MesherError
// carrying the switches and TetGen's last printed lines instead of ending plaf.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/linear_front.h"

namespace plaf::volume {

struct TetFillParams {
  double max_radius_edge = 1.5;  // quality bound (switch q): circumradius / shortest edge; 0 disables refinement
  double max_volume = 0;         // volume bound (switch a), in the front's length unit cubed; 0: none
  // Edge length wanted at each front node (one per front.nodes entry, the unused ones ignored;
  // switch m): TetGen refines until its tets' edges are under the sizes it interpolates from
  // these over its first tetrahedralisation. Empty: no sizing (the front's sizes grade alone).
  std::vector<double> node_sizes;
};

// Measured on the returned tets, not taken from TetGen's log.
struct TetFillStats {
  std::size_t tets = 0;
  std::size_t new_points = 0;          // nodes after front.nodes (TetGen's interior Steiner points)
  double min_dihedral_deg = 0;         // smallest dihedral angle of any tet, degrees
  double max_radius_edge = 0;          // largest circumradius / shortest edge (regular tet: sqrt(6)/4)
  std::string switches;                // the TetGen switches used, e.g. "pYQzJM0/1q1.5"
};

// The fill (linear_front.h's FillResult: front.nodes, same ids, then the new ones; order-1
// tetrahedra of positive volume) and what it did.
struct TetFillResult : FillResult<3> {
  TetFillStats stats;
};

// Fills the region bounded by `front` (linear_front.h: closed, non-crossing surfaces, normals into
// the region, one hole point inside every body). Throws InputError at entry for a node id out of
// range, a triangle repeating a node, fewer than 4 triangles, a non-finite coordinate or hole
// point, a triangle_tag out of range of tags, a triangle listed twice, or node_sizes of the wrong
// count or not positive at a used node; MesherError (with
// TetGen's code or signal, its switches and its last printed lines) if TetGen fails or a front triangle is a face of no tet; InputError
// if one is a face of two tets or of one tet behind it (the contract above).
TetFillResult tetgen_fill(const LinearFront<3>& front, const TetFillParams& params = {});

// Smallest dihedral angle (radians) and circumradius / shortest edge of the tet p[0..3] (either
// orientation; a flat tet has angle 0).
std::pair<double, double> tet_shape(const std::array<Eigen::Vector3d, 4>& p);

}  // namespace plaf::volume
