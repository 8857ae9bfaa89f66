// SPDX-License-Identifier: MIT
// The `plaf run` and `plaf check` commands: compose the stages from a run configuration.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/mesh/quality.h"
#include "modules/pipeline/layer_table.h"
#include "modules/pipeline/progress.h"
#include "modules/pipeline/run_config.h"

namespace plaf {

// What one run produced, beyond its files: for commands that run several configurations and
// compare them (apps/study.h).
struct RunOutcome {
  int code = 0;                       // the exit code plaf run gives it (0 or 2)
  std::vector<std::string> failures;  // the stages' failure lines and the invalid-mesh verdict
  QualityReport report;               // what <name>.report.json holds
  std::filesystem::path base;         // output.dir / name: the files are base + ".msh", ...
  std::vector<LayerRow> layers;       // the per-layer table's rows (empty without layers)
  int linear_after = -1;
  // The nodes of the surface front the layers grew from and of the layers' outer front (2D: z = 0).
  std::vector<Eigen::Vector3d> wall_nodes, outer_nodes;
  // The largest offset of a wall element's high-order node from its position on the linear
  // element (the element's chord in 2D, its flat triangle in 3D): what attenuation has to remove.
  double max_chord_offset = 0;
  // The mean length of the wall elements' edges between their vertices (2D: the elements' chords;
  // 3D: the triangles' edges, each counted per triangle): the size along the wall.
  double wall_edge_mean = 0;
  // The mesh itself (the one of the run's dimension; null for the other), for callers that use
  // it in memory (the Python module).
  std::shared_ptr<const HybridMesh<2>> mesh2;
  std::shared_ptr<const HybridMesh<3>> mesh3;
};

// Runs a validated configuration and writes its outputs; quiet: no stage lines on stdout and no
// progress on stderr (failures are still printed). Throws plaf::Error on bad input.
RunOutcome run_config(const RunConfig& config, bool quiet = false);
// The same, its stages reporting to `progress` (modules/pipeline/progress.h): in its Quiet mode
// stdout has only the verdict line (no stage lines, no summary); in Json mode the verdict is the
// last JSON line on stderr too.
RunOutcome run_config(const RunConfig& config, Progress& progress);

// Runs a configuration; returns the process exit code (0: a valid, conforming mesh was written;
// 2: the mesh was written but a stage failed, e.g. a folded surface, or it has invalid cells or
// is not conforming). Throws plaf::Error on bad input before any output is written.
// keep_invalid: a failed run's mesh is written too (into DIR/NAME.failed/, with its report).
// progress: where the stages report (`--quiet`, `--progress=json`; null: text on stderr).
int run_command(const std::filesystem::path& config, const std::optional<std::filesystem::path>& out_dir,
                bool keep_invalid = false, Progress* progress = nullptr);

// Registers every library's stage plugins (idempotent).
void register_all_plugins();

// Prints every stage's registered types; returns 0.
int plugins_command();

// `plaf data`: without files, the data roots in the order they are tried (modules/pipeline/
// data_root.h); with files (REL or data:REL), the path where each is found, one per line; a
// missing one throws MissingDataError (exit 1) naming the roots and its source.
int data_command(const std::vector<std::string>& files);

// Re-reads a Gmsh MSH 4.1 file and reports validity and quality; 0 when valid and conforming.
// With metric_config, the edges are also measured in that run configuration's metric (its
// geometry is built when the metric needs it), so meshes of other tools are judged by the same
// measure; with report, the JSON report is written there.
int check_command(const std::filesystem::path& mesh, const std::optional<std::filesystem::path>& metric_config = {},
                  const std::optional<std::filesystem::path>& report = {});

}  // namespace plaf
