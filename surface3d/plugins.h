// SPDX-License-Identifier: MIT
// The 3D surface stages' plugins (modules/pipeline/stages.h), registered by register_plugins():
//   geometry: sphere, ellipsoid, box, wing (analytic.h) and surface_file (read_surface.h,
//             validate.h, features.h; the discrete reference) — keys in modules/pipeline/run_config.h;
//   surface:  remesh — metric-conforming remeshing with features kept (remesh.h), sizes optionally
//             following the curvature (curvature_metric.h), order-Q nodes on the reference, every
//             triangle certified (high_order.h). A folded or invalid surface fails the run.
#pragma once

namespace plaf {

void register_surface3d_plugins();

}  // namespace plaf
