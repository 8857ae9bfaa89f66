// SPDX-License-Identifier: MIT
// Metric post-optimisation of a 2D fill (issue 12; the PLAF paper's Sec. II.C lets the advancing
// front be followed by any improvement that keeps the fronts): edge swaps and node smoothing in
// the metric, on the triangles of a FillResult<2>, its first `fixed_nodes` nodes (the front's,
// linear_front.h) never moved and its boundary edges (the fronts: edges of one triangle) never
// swapped. Per pass:
//  0. splits and collapses (all passes but the last two): an interior edge longer than sqrt 2 gets
//     its midpoint as a new free node, its two triangles becoming four (the advancing front leaves
//     edges of 1.4-2 units where its fronts meet in a graded metric, and longer ones across
//     features thinner than its steps; a long edge is split again in the next pass; not one
//     longer than 16 units by its ends' metrics, which marks a region left unresolved); an edge
//     shorter than 1/sqrt 2 with a free end loses that end (merged into the other, under the link
//     condition, with no new edge longer than sqrt 2). Here an edge's length samples the metric
//     at its midpoint too (Simpson's rule), so an edge across a thin shock band is long. No
//     split or collapse makes a triangle worse than the fill's worst at the start; the sweeps
//     stop once a pass changes fewer than 1 in 1000 triangles;
//  1. swaps: an interior edge whose two triangles form a strictly convex quadrilateral is
//     swapped when the smaller metric shape quality of the pair rises (quality
//     4 sqrt(3) A_M / sum l_M^2 with the mean of the three vertex metrics: 1 for a triangle
//     equilateral in the metric, 0 for a flat one);
//  2. smoothing: every free node moves toward the mean of the points at unit metric length from
//     its neighbours along its edges (the edge metric the mean of its ends'; a node within 0.02
//     metric units of that target stays), by half the way,
//     and the move is kept only if every triangle around the node stays counter-clockwise
//     (exact orient2d) and the least quality around it does not drop (else a quarter of the way
//     is tried);
// then swaps once more. Every triangle stays counter-clockwise throughout (a split, collapse and
// swap are checked with exact orient2d, a move too), so a valid fill stays valid; new nodes are
// appended and collapsed ones dropped at the end (the front's nodes stay first and unchanged,
// linear_front.h). The metric is evaluated once per node (and per sampled midpoint); a triangle
// takes the mean of its vertices' metrics.
#pragma once

#include <cstddef>

#include "modules/mesh/linear_front.h"
#include "modules/metric/metric.h"

namespace plaf::volume {

struct OptimizeParams {
  int passes = 10;  // swap + smooth rounds; 0: nothing
};

struct OptimizeStats {
  std::size_t splits = 0;
  std::size_t collapses = 0;
  std::size_t swaps = 0;
  std::size_t moves = 0;
  double quality_min_before = 0, quality_min_after = 0;
  double unit_fraction_before = 0, unit_fraction_after = 0;  // edges of metric length in [1/sqrt2, sqrt2]
};

OptimizeStats optimize_fill(FillResult<2>& fill, std::size_t fixed_nodes, const MetricField<2>& metric,
                            const OptimizeParams& params = {});

}  // namespace plaf::volume
