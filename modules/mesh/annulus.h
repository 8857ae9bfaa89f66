// SPDX-License-Identifier: MIT
// A first real case: curved order-Q quadrilaterals (or triangles) filling an annulus sector,
// placed by the exact polar map x = r (cos t, sin t), so every high-order node lies on the
// true circles. Element counts are the rounded metric lengths of the mid-radius arc and of a
// radial line (at least 1; at least 3 around a full annulus).
//
// Boundary tags: "wall" (inner circle, Wall), "farfield" (outer circle, Farfield) and, for a
// sector, "side" (the two radial lines, Symmetry). Loops run with the domain on their left.
#pragma once

#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"
#include "modules/pipeline/run_config.h"

namespace plaf {
inline namespace mesh {

HybridMesh<2> mesh_annulus(const AnnulusParams& params, int order, const MetricField<2>& metric);

}  // namespace mesh
}  // namespace plaf
