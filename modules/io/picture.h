// SPDX-License-Identifier: MIT
// PNG pictures of 2D meshes (cairo): curved edges drawn as curves (each Lagrange edge sampled
// finely), straight cells light blue, curved cells light orange, invalid cells filled red,
// boundary facets drawn thicker. Zoom boxes (in model coordinates) add inset panels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"

namespace plaf {
inline namespace io {

struct ZoomBox {
  std::string label;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
};

struct PictureOptions {
  int width = 1600;
  int height = 1200;
  std::vector<ZoomBox> zooms;  // each gets a panel below the main view
  std::string title;
};

// valid: one flag per cell in block order (empty: all valid). Written atomically.
void write_png(const HybridMesh<2>& mesh, const std::vector<std::uint8_t>& valid, const std::filesystem::path& path,
               const PictureOptions& options);


}  // namespace io
}  // namespace plaf
