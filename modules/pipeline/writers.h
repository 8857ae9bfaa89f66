// SPDX-License-Identifier: MIT
// The registries of output writers (one per dimension), selected by `output.formats`. Each writes <base>.<ext>
// atomically from the mesh, its per-cell quality and the report.
#pragma once

#include <filesystem>
#include <string>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/layer_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/registry.h"
#include "modules/pipeline/run_config.h"

namespace plaf {
inline namespace pipeline {

template <int Dim>
struct WriteJob {
  const HybridMesh<Dim>& mesh;
  const CellQuality& per_cell;
  const QualityReport& report;
  const RunConfig& config;
  std::filesystem::path base;  // output path without extension
  // The layer stage's coverage and its layer count (null, 0: no layers), for the 3D picture.
  const LayerCoverage* coverage = nullptr;
  int layers = 0;
};

template <int Dim>
using WriterRegistry = Registry<void(const WriteJob<Dim>&)>;
// Built-in: msh (Gmsh 4.1), msh22 (Gmsh 2.2, NAME_msh22.msh), cgns (NAME.cgns), vtu (VTK Lagrange
// cells), report (JSON), png (picture).
template <int Dim>
WriterRegistry<Dim>& writer_registry();
// Explicitly specialised in writers.cpp; declared here so that no translation unit instantiates
// the primary template first ([temp.expl.spec]: a use before the specialisation's declaration is
// ill-formed, which a unity build exposes).
template <>
WriterRegistry<2>& writer_registry<2>();
template <>
WriterRegistry<3>& writer_registry<3>();

}  // namespace pipeline
}  // namespace plaf
