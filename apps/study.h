// SPDX-License-Identifier: MIT
// `plaf compare-attenuation STUDY.yaml`: how curvature attenuates in 2D and in 3D (paper Sec. II.B,
// f_atten = 0.2, "after three layers the elements are no longer curved"; Sec. II.E in 3D).
//
// A study holds cases; each case is a 2D section (geometry type airfoils), a metric and layer
// keys, and its 3D partners:
//   - extrusion: the section extruded between two symmetry planes (the run config's `extrude:`
//     key, modules/mesh/extrude_front.h), measured at its mid-span station;
//   - sphere: for a section that is one circle body, the sphere of the same centre and radius
//     (geometry type sphere) with the same metric keys.
// Every case runs over the sweep points (f_atten, h0): each f_atten of the study at the case's
// own h0, and each h0 factor at the case's own f_atten. At every point the 2D run and each
// partner run are ordinary `plaf run`s of generated configurations (written to
// OUT/configs/, re-runnable by hand) that share, by construction, the metric section (h0 set
// alike), the layers section (f_atten set alike; high_order_heights: interpolated in both
// unless the case names the rule) and the order; the study checks the pairing on the results
// too (extrusion: the mid-span wall nodes are the section's; sphere: the same radius, and no
// 2D-only metric key may change the sizes of one side).
//
// Study keys (strict, as run configurations): name, order, the sweeps f_atten and h0_factors, and
// cases, each a name, the run sections geometry (type airfoils), metric (type wall_power_law) and
// layers, its partners (extrude, sphere), its own h0_factors and output.zooms. Types, defaults and
// descriptions: `plaf keys study` (docs/config.md; the lines in apps/key_notes.cpp).
//
// Outputs in OUT (the --out folder, default out/<name>):
//   <name>.md           the runs' table, the pairs' table and, per case, the per-layer table of
//                       its base runs (2D beside 3D);
//   <name>_runs.csv, <name>_layers.csv, <name>_pairs.csv, <name>.json;
//   <case>_clip.png     max clip / h against layer, 2D and 3D curves per f_atten, per pair;
//   linear_after_f_atten.png, linear_after_h0.png;
//   <case>_<partner>_side_by_side.png   the 2D mesh and the 3D mid-span cut (base runs);
//   runs/               every run's report (and mesh, VTU and picture for the base runs);
//   configs/            every run's configuration.
// Exit code: 0 when every run exits 0 with 0 invalid cells and every pairing holds, 2 otherwise
// (the tables are written either way); 1 for a bad study file (nothing is run or written).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace plaf {

// Reads and checks a study file's text as compare-attenuation does, running nothing (ConfigError
// naming the key); `file` places its relative paths. For the key reference (apps/keys.h).
void check_study(const std::string& yaml_text, const std::filesystem::path& file);

int compare_attenuation_command(const std::filesystem::path& study, const std::optional<std::filesystem::path>& out_dir);

}  // namespace plaf
