// SPDX-License-Identifier: MIT
// Metric optimisation of a 3D fill (issue 32): the counterpart of optimize_2d.h for TetGen's
// tetrahedra. TetGen refines to an isotropic size interpolated from the front and leaves slivers
// (flat tets of good radius-edge ratio, dihedral angles down to 0 at a front); this pass moves
// the fill toward unit edges in the run's metric and away from slivers, with the surfaces frozen.
//
// Frozen: the first `fixed_nodes` nodes (linear_front.h: the fronts', the farfield's and the
// symmetry planes' nodes) and every node of a boundary triangle (a face of one tet: the fronts,
// listed in fill.boundary or not) never go, and none moves but the Optimize3Params::in_plane
// ones, within their plane (step 5). No boundary triangle is split, merged or swapped: the fronts
// other than those planes stay bit-identical and each boundary triangle keeps exactly one tet, on
// its side. The other nodes are free. Per pass, in this order:
//  1. splits (all passes but the last two; so none with passes <= 2): an edge longer than sqrt 2
//     in the metric that lies on no boundary triangle gets its midpoint as a new free node, each
//     tet around it becoming two; longest first;
//  2. collapses (the same passes): an edge shorter than 1/sqrt 2 with a free end loses that end
//     (merged into the other, under the link condition, no new edge longer than 1.6: the next
//     pass's splits halve an edge between sqrt 2 and 1.6 into two unit ones, but the last
//     collapse sweep's stay);
//  3. swaps, on the tets under 0.5: a face of two tets becomes an edge of three (2-3), and an
//     interior edge of n = 3..7 tets is removed, its ring triangulated by the best fan (3-2, 4-4,
//     5-6, ...), when the worst tet of the set gets better by 1e-4 at least;
//  4. slivers (tets under 0.15 that the swaps left): a free vertex of one moves to the
//     centre of its ball's kernel (the point farthest inside every face around it) if that
//     betters the ball's worst tet, else merges into a neighbour (new tets at least twice the
//     sliver's quality, up to 0.01; edges up to 2.5 units), else an interior edge of the sliver is
//     split and the midpoint put at its ball's kernel centre, kept if the ring's worst tet gets
//     better by 1e-4 and at least doubles (up to 0.01). TetGen leaves such tets at the fronts:
//     flat ones of 1e-10 on the published 717 wing, around a Steiner point it put on a front
//     triangle's edge; at a front triangle of aspect ratio 1e4 (a fan's sector strip) no tet is
//     better than a sliver;
//  5. smoothing, of the free nodes (and the in_plane ones, within their plane) whose ball changed
//     since they were last tried: a node moves
//     toward the mean of the points that would make each tet of its ball regular in its metric
//     (by 1, 1/2 or 1/4 of the way), in a ball under 0.5 then toward its worst tet's own point
//     (by down to 1/100 of the way), kept when the ball's worst tet gets better, or stays and the
//     ball's mean quality rises;
//  6. swaps again.
// The quality is the mean ratio in the metric (12 (3 V_M)^(2/3) / sum of the squared edge
// lengths L_M^2: 1 for a tet regular in the metric, 0 flat), a tet taking the mean of its
// vertices' metric matrices; an edge measures by the mean of its ends'. No collapse of step 2
// makes a tet worse than kSliver, kFloor (0.2) or the worst it replaces, whichever is least of the
// last two but at least kSliver; no split worse than kSliver or than the least of kFloor and half
// the worst of its ring (halving a needle's long edge makes two needles a little worse, which the
// next splits, swaps and moves mend); swaps, moves and step 4 never lower the worst of the tets
// they change (a node's metric, evaluated again once it moved 0.05 metric units, and a split's
// midpoint's, judged by its ends' mean, then evaluated, may shift qualities a little).
// Every new or moved tet is checked with the exact orient3d (predicates.h), so a fill of positive
// tets stays positive, and a flat one (orient3d = 0, TetGen's slivers) can only be replaced,
// never made. New nodes are appended and collapsed ones dropped at the end: the fixed nodes keep
// their ids (linear_front.h). The fill is written back only at the end (an exception leaves it
// as it was).
#pragma once

#include <cstddef>
#include <functional>

#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"

namespace plaf::volume {

struct Optimize3Params {
  int passes = 6;  // 0: nothing
  // Nodes that step 5 may move within their plane (the symmetry planes' own nodes, inside their
  // loops): node id and the axis the plane is normal to (the node keeps that coordinate exactly).
  // Fixed or on boundary triangles, they are frozen for every other step. Every boundary triangle
  // at such a node must lie in its plane (InputError otherwise: sliding would dent the other
  // surface).
  std::vector<std::pair<NodeId, int>> in_plane;
  std::function<void(int pass, int passes)> on_pass;  // after each pass (the run's progress); may be empty
  // fill.max_volume: no step makes a tetrahedron larger than this (0: no bound). TetGen meets it
  // (switch a); without it here the collapses toward the metric's sizes undid it (issue 37, item 3).
  double max_volume = 0;
};

// The fill's shape, measured (measure_fill_3d).
struct FillShape3 {
  std::size_t tets = 0;
  double quality_min = 0;                // mean ratio in the metric (negative: inverted)
  double quality_min_inner = 0;          // the same over the tets with no fixed node (1 when there is none)
  double unit_fraction = 0;              // edges of metric length in [1/sqrt2, sqrt2]
  double length_min = 0, length_max = 0;  // metric edge lengths
  double length_max_free = 0;            // the longest with a free end (the others join fixed nodes)
  double min_dihedral_deg = 0;           // every tet
  double min_dihedral_inner_deg = 0;     // tets with no fixed node (180 when there is none)
  std::size_t below_5deg = 0, below_10deg = 0;  // tets with a dihedral angle under 5 / 10 degrees
  // The same angles in the metric (the tet mapped by M^(1/2) of its mean metric, where edges
  // measure their metric length): equal to the above where the metric is isotropic; where it
  // is stretched, a tet stretched along it has the angles of its image, regular or not.
  double metric_min_dihedral_deg = 0, metric_min_dihedral_inner_deg = 0;
  std::size_t metric_below_5deg = 0, metric_below_10deg = 0;
  std::size_t flat = 0;                  // tets whose exact orient3d is not positive
  double volume_max = 0;                 // the largest tetrahedron's volume
  // Where: the centroid of the tet with the smallest dihedral angle in the metric, and the
  // midpoint of the longest edge (in the metric).
  Eigen::Vector3d metric_min_dihedral_at = Eigen::Vector3d::Zero(), length_max_at = Eigen::Vector3d::Zero();
  // The tets where the metric is stretched 10:1 or more (its largest size over its smallest, of
  // the mean of the tet's node metrics), and the tets' own stretch there: the largest over the
  // smallest size of the metric in which the tet is regular (the affine map from a regular unit
  // tet: its largest singular value over its smallest). Percentiles over those tets; 0 without.
  struct Stretched {
    std::size_t tets = 0;
    double metric_p50 = 0;                                     // the metric's stretch
    double stretch_p10 = 0, stretch_p50 = 0, stretch_p90 = 0;  // the tets' own
    double at_least_10 = 0;                                    // share of them stretched >= 10:1
    double quality_p50 = 0;                                    // mean ratio in the metric
  } stretched;
};

struct Optimize3Stats {
  std::size_t splits = 0, collapses = 0, swaps = 0, moves = 0;
  std::size_t repairs = 0;  // slivers mended by step 5
  FillShape3 before, after;
};

FillShape3 measure_fill_3d(const FillResult<3>& fill, std::size_t fixed_nodes, const MetricField<3>& metric);

// Throws InputError if a tet uses a node out of range.
Optimize3Stats optimize_fill_3d(FillResult<3>& fill, std::size_t fixed_nodes, const MetricField<3>& metric,
                                const Optimize3Params& params = {});

}  // namespace plaf::volume
