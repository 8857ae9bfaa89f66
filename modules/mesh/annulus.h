// SPDX-License-Identifier: MIT
// A first real case: curved order-Q quadrilaterals (or triangles) filling an annulus sector,
// placed by the exact polar map x = r (cos t, sin t), so every high-order node lies on the
// true circles. Element counts are the rounded metric lengths of the mid-radius arc and of a
// radial line (at least 1; at least 3 around a full annulus).
//
// Boundary tags: "wall" (inner circle, Wall), "farfield" (outer circle, Farfield) and, for a
// sector, "side" (the two radial lines, Symmetry). Loops run with the domain on their left.
//
// Its geometry section (`type: annulus`, the plugin in modules/pipeline/stages.h): r_inner,
// r_outer, angle_deg, cells; types, defaults and descriptions: `plaf keys geometry`
// (docs/config.md; the lines in apps/key_notes.cpp).
#pragma once

#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"
#include "modules/pipeline/config.h"

namespace plaf {
inline namespace mesh {

struct AnnulusParams {
  double r_inner = 1.0;
  double r_outer = 2.0;
  double angle_deg = 360.0;
  bool triangles = false;
};

// The annulus keys of a geometry section (ConfigError naming the key).
AnnulusParams parse_annulus_params(const ConfigNode& geometry);

HybridMesh<2> mesh_annulus(const AnnulusParams& params, int order, const MetricField<2>& metric);

}  // namespace mesh
}  // namespace plaf
