// SPDX-License-Identifier: MIT
// The per-layer table and events of a layer stage as the report's `layers` section, in either
// dimension: per layer its cells, curved cells, the largest attenuation move still needed over
// the height, min certified scaled Jacobian and max aspect ratio (from the quality stage's
// per-cell results), shrinks and transition cells; then the events, layers.count and
// layers.linear_after. The same keys in 2D and 3D.
#pragma once

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/stage_report.h"

namespace plaf {
inline namespace pipeline {

// The layer cells are mesh.cells[0] from LayerStats::first_cell on (the layer stage's block 0).
template <int Dim>
void report_layer_table(const LayerResult<Dim>& layers, const HybridMesh<Dim>& mesh, const CellQuality& per_cell,
                        StageReport& report);

}  // namespace pipeline
}  // namespace plaf
