// SPDX-License-Identifier: MIT
// The registry of output writers, selected by `output.formats`. Each writes <base>.<ext>
// atomically from the mesh, its per-cell quality and the report.
#pragma once

#include <filesystem>
#include <string>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/registry.h"
#include "modules/pipeline/run_config.h"

namespace plaf {
inline namespace io {

struct WriteJob {
  const HybridMesh<2>& mesh;
  const CellQuality& per_cell;
  const QualityReport& report;
  const RunConfig& config;
  std::filesystem::path base;  // output path without extension
};

using Writer2Registry = Registry<void(const WriteJob&)>;
// Built-in: msh (Gmsh 4.1), vtu (VTK Lagrange cells), png (picture), report (JSON).
Writer2Registry& writer_registry();

}  // namespace io
}  // namespace plaf
