// SPDX-License-Identifier: MIT
// The per-layer table and events of a layer stage as the report's `layers` section, in either
// dimension: per layer its cells, curved cells, the largest attenuation move still needed over
// the height, min certified scaled Jacobian and max aspect ratio (from the quality stage's
// per-cell results), shrinks, transition cells and the layer heights (LayerStats::height_*, min /
// mean / max over the measured columns); then the events, layers.count and
// layers.linear_after. The same keys in 2D and 3D.
#pragma once

#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/progress.h"
#include "modules/pipeline/stage_report.h"

namespace plaf {
inline namespace pipeline {

// One row of the table: the layer core's stats and what the quality stage measured on the
// layer's cells. measured is false where the assembly changed the layer blocks (2D split_quads):
// curved, min_scaled_jacobian and max_aspect_ratio are then not measured (null in the JSON).
struct LayerRow {
  LayerStats stats;
  bool measured = false;
  std::size_t curved = 0;
  std::size_t measured_cells = 0;  // the cells curved and the quality columns were measured on
  // curved / measured_cells (NaN when none was measured).
  double curved_fraction() const;
  double min_scaled_jacobian = 0, max_aspect_ratio = 0;
};

// The layer cells are mesh.cells[0] from LayerStats::first_cell on (the layer stage's block 0),
// and the transition cells mesh.cells[1] from LayerStats::first_transition_cell on.
template <int Dim>
std::vector<LayerRow> layer_rows(const LayerResult<Dim>& layers, const HybridMesh<Dim>& mesh, const CellQuality& per_cell);

// The rows (layer_rows) and the layer result's events and counts as the report's section.
template <int Dim>
void report_layer_table(const LayerResult<Dim>& layers, const std::vector<LayerRow>& rows, StageReport& report);

// A layer accepted by the layer stage, as a step of the run's progress: its row of the table as
// far as it is known then (cells, transition cells, max_clip/h, heights, coverage; the quality
// columns come with the table), its fraction layer / max_layers.
void layer_progress(const LayerStats& accepted, int max_layers, Progress& progress);

}  // namespace pipeline
}  // namespace plaf
