// SPDX-License-Identifier: MIT
// Stage plugins: every stage of the pipeline is chosen by name from a registry, one registry per
// stage kind and dimension. A factory receives its configuration section, parses and checks its
// own keys there, before anything runs, and returns the configured stage: a function of the run
// state that fills its part and its StageReport (the run's core keys reach it through
// RunState::config when it runs).
//
// Registration: each library registers its own plugins in one function the driver calls at start
// (core: register_core_plugins below; surface3d/plugins.h, layers/plugins.h, volume/plugins.h).
// Types (kind: 2D | 3D):
//   geometry: annulus, airfoils | sphere, ellipsoid, box, wing, surface_file
//   metric:   uniform, wall_power_law, background | uniform, wall_power_law, background
//   surface:  annulus, curves (by the geometry) | remesh (surface.type)
//   layers:   none, extrude | none
//   fill:     none, advancing_front | none
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "modules/pipeline/config.h"
#include "modules/pipeline/registry.h"
#include "modules/pipeline/run_config.h"
#include "modules/pipeline/stage_report.h"

namespace plaf {
inline namespace pipeline {

template <int Dim>
struct RunState;

template <int Dim>
using Stage = std::function<void(RunState<Dim>&, StageReport&)>;

enum class StageKind { Geometry, Metric, Surface, Layers, Fill };
constexpr StageKind all_stage_kinds[] = {StageKind::Geometry, StageKind::Metric, StageKind::Surface,
                                         StageKind::Layers, StageKind::Fill};
const char* stage_kind_name(StageKind kind);  // "geometry", ... (also the config section and report key)

// section: the stage's config section (empty when absent).
template <int Dim>
using StageRegistry = Registry<Stage<Dim>(const ConfigNode& section)>;

template <int Dim>
StageRegistry<Dim>& stage_registry(StageKind kind);

// Registers core's stages: 2D geometries, metrics and surface meshes, the 3D metrics, and the
// "none" layers and fill of both dimensions. Idempotent.
void register_core_plugins();

// The metric stage of `metric: {type: ..., intersect: [{type: ...}, ...]}` (run_config.h): runs
// `first`, then each of `more` on the same state, and leaves there the intersection of their
// fields (IntersectedMetricField, metric.h); in 3D also of their sizes along the wall, where
// any of them gave such sizes (RunState<3>::surface_sizes; the others' own metric stands for them).
template <int Dim>
Stage<Dim> intersect_metric_stages(Stage<Dim> first, std::vector<Stage<Dim>> more);

// One line per stage kind and dimension with its registered types, and the output formats.
std::string plugin_listing();

}  // namespace pipeline
}  // namespace plaf
