// SPDX-License-Identifier: MIT
// LayerResult<Dim>: the product of the layer stage (layers/), which crosses to the fill stage
// (volume/, through its fill_front) and to the assembly of the hybrid mesh and the report (its
// per-layer table and events). The algorithms live in layers/layer_core.h.
#pragma once

#include <array>

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "modules/mesh/curved_front.h"
#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/linear_front.h"

namespace plaf {
inline namespace mesh {

struct LayerStats {
  int layer = 0;                     // 1-based
  std::size_t cells = 0;             // main cells (2D quadrilaterals, 3D prisms)
  // Cells of the transition block (LayerResult::mesh.cells[1]): 2D the triangles next to stopped
  // nodes (isotropic_stop: node); 3D the tetrahedra (a first layer with fans, corner fans).
  std::size_t transition_cells = 0;
  std::size_t first_transition_cell = 0;  // this layer's cells in the transition block
  // Largest attenuation move still needed / height (0 if linear); in a 3D layer with stops (no
  // attenuation) the base's largest offset from its chord / height.
  double max_clipped_rel = 0;
  // The attenuation fraction the layer used: LayerParams::f_atten, less where a part's layer was
  // rebuilt with it halved (layer_core.cpp), infinite for a closing layer (straight tops).
  double f_atten = 0;
  bool linear = false;               // the new front is linear
  std::size_t shrinks = 0;           // invalid cells and front crossings that made heights halve
  bool shrunk = false;               // the accepted build has heights halved somewhere (not the closing layer's scale)
  std::size_t first_cell = 0;        // this layer's cells in the main block (LayerResult::mesh.cells[0])
  // The layer's height |top - base| over its vertex columns grown along a normal, where
  // LayerParams::height_probe accepts the base (all columns by default; an extruded section's
  // run: mid-span): smallest, mean and largest, and how many columns (0: none measured).
  double height_min = 0, height_mean = 0, height_max = 0;
  std::size_t height_columns = 0;
  // The same, NaN when no column was measured (null in reports).
  // The fraction of the wall (its area in 3D, length in 2D) whose columns grew this layer.
  double coverage = 0;
  double min_height() const { return height_columns ? height_min : std::numeric_limits<double>::quiet_NaN(); }
  double mean_height() const { return height_columns ? height_mean : std::numeric_limits<double>::quiet_NaN(); }
  double max_height() const { return height_columns ? height_max : std::numeric_limits<double>::quiet_NaN(); }
};

// How much of the boundary layer that was asked for is there (layers/layer_core.h, step 4). A
// column is a wall stop point's stack (3D: a vertex of the wall's triangles; 2D: a loop vertex),
// weighed by the wall measure it stands for (a third of its triangles' areas; half its edges).
struct LayerCoverage {
  double wall = 0;       // the wall's measure (area in 3D, length in 2D) over the grown parts
  // Fraction of the wall whose columns ended by a stop rule (max layers, a linear front, the
  // metric isotropic), not by a failure: the requested stack is there.
  double complete = 0;
  std::size_t columns = 0, columns_complete = 0;  // the same by columns
  // Of the complete ones, the columns (and their wall fraction) whose stacks ended by the proximity
  // rule (LayerParams::proximity): where a facing wall, or a concave front's focus, leaves no
  // room for the stack the metric asks for, the stack that fits is the stop rule.
  double proximity = 0;
  std::size_t columns_proximity = 0;
  // The first layer each column grew (a closing layer where layer 1 failed) against the metric's
  // height there along the column: height / metric height, over the columns grown along a normal.
  double first_min = 0, first_mean = 0, first_max = 0;
  std::size_t first_columns = 0;
  std::size_t first_over_4 = 0;  // of them, those taller than 4 times the metric's height
  // Where columns stopped early: one line per part and layer (the stop points, their wall
  // measure and a point), as the events say it.
  std::vector<std::string> stopped_early;
  // The same stops as points with the wall measure they stand for, and a part that stopped whole
  // (its failing stop points' centre, standing for the wall it lost): where a failed run's
  // picture looks. Only fronts that map failures to stop points record them (3D; the 2D loops do
  // not, so a 2D run's picture looks at its worst invalid cell alone).
  struct Site {
    std::array<double, 3> point{};
    double measure = 0;
    int layer = 0;          // the layer where they stopped
    bool crossing = false;  // the failures included front crossings (else invalid cells only)
  };
  std::vector<Site> sites;
  // Every column that ended short of its stop rule, one by one: where it stands on the wall (its
  // stop point before the first layer; where the first layer's fans changed the stop points, that
  // layer's, one wall spacing off the wall) and the layer it ended in (it has layer - 1 layers);
  // a part that failed whole ends each of its growing columns so. The 3D picture colours the wall
  // by them (picture3d.h).
  struct Column {
    std::array<double, 3> point{};
    int layer = 0;
  };
  std::vector<Column> short_columns;
};

// The stops of a coverage grouped by region: each site joins the first region (largest first)
// whose point lies within `radius` of its own, else starts one. A region's point is its largest
// site's; its measure their sum; its layers their range; its causes their union.
struct StopRegion {
  std::array<double, 3> point{};
  double measure = 0;
  int first_layer = 0, last_layer = 0;
  std::size_t groups = 0;
  bool invalid = false, crossing = false;
};
std::vector<StopRegion> stop_regions(const LayerCoverage& coverage, double radius);

// The layer stage's product. Node-numbering contract: mesh.nodes starts with the input
// CurvedFront's nodes, same ids, then the nodes the layers added; fill_front (linear_front.h)
// refers to mesh.nodes.
template <int Dim>
struct LayerResult {
  HybridMesh<Dim> mesh;    // main cells (block 0) and transition cells (block 1, if any) of order
                           // Q; boundary: the wall facets the layers grew from, tagged
  CurvedFront<Dim> outer;  // the outermost front of the grown parts (same orientation as the input)
  LinearFront<Dim> fill_front;  // the boundary of the region left to fill: the outer fronts of the
                                // grown parts, then every part of the input that did not grow
  std::vector<LayerStats> layers;
  int linear_after = -1;            // 1-based index of the first layer with a linear front, -1 if none
  std::vector<std::string> events;  // what stopped or shrank growth, one line each
  LayerCoverage coverage;
  // What the front's specifics counted, for the report (3D: the classes of the first front's
  // nodes, concave merges, symmetry nodes).
  std::vector<std::pair<std::string, std::size_t>> counts;
};

// The 2D front's loop `l` by its vertices, as a loop of a linear front.
LinearLoop linear_loop(const CurvedFront<2>& front, const FrontLoop& l, bool layered, int source_loop);

// The layer stage's result without layers: the front's nodes, and every loop of the front bounding
// the fill (layers type `none`).
LayerResult<2> unlayered(const CurvedFront<2>& front);

}  // namespace mesh
}  // namespace plaf
