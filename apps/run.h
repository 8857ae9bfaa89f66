// SPDX-License-Identifier: MIT
// The `plaf run` and `plaf check` commands: compose the stages from a run configuration.
#pragma once

#include <filesystem>
#include <optional>

namespace plaf {

// Runs a configuration; returns the process exit code (0: a valid, conforming mesh was written;
// 2: the mesh was written but a stage failed, e.g. a folded surface, or it has invalid cells or
// is not conforming). Throws plaf::Error on bad input before any output is written.
int run_command(const std::filesystem::path& config, const std::optional<std::filesystem::path>& out_dir);

// Registers every library's stage plugins (idempotent).
void register_all_plugins();

// Prints every stage's registered types; returns 0.
int plugins_command();

// Re-reads a Gmsh MSH 4.1 file and reports validity and quality; 0 when valid and conforming.
// With metric_config, the edges are also measured in that run configuration's metric (its
// geometry is built when the metric needs it), so meshes of other tools are judged by the same
// measure; with report, the JSON report is written there.
int check_command(const std::filesystem::path& mesh, const std::optional<std::filesystem::path>& metric_config = {},
                  const std::optional<std::filesystem::path>& report = {});

}  // namespace plaf
