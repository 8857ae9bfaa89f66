// SPDX-License-Identifier: MIT
// The size budget (issue 17): before a stage meshes, it predicts how many elements and nodes it
// will make from the metric (modules/metric/metric_integrals.h: an element per unit of metric
// length, area or volume) and stops with a ConfigError naming the config, the estimate and the
// `limits:` key to raise (RunConfig::limits, run_config.h) when the prediction exceeds it. So a
// run sized beyond the machine fails early instead of running for minutes into gigabytes: the 2D
// checks and the 3D surface's before anything is meshed, the 3D layers' and fill's once the
// stages before them (within their own budgets) are done; the fill's counts the layers too.
// Where the stages check:
//   - 2D (and an extruded section, times its rows): after the metric, before the surface mesh
//     (check_section_budget): the loops' curve elements, and the cells of the domain inside the
//     farfield and outside the bodies (or of the annulus);
//   - 3D surface (surface3d/plugins.cpp): an analytic body's metric area on a coarse copy before
//     its initial triangulation is built, then the input or initial triangulation's, with the
//     curvature sizes; each of these also checks the layers' cells on the triangles to come when
//     layers.max is given (RunConfig::layers_max), so a metric too fine for the layers is refused
//     before the surface is meshed;
//   - 3D layers (layers/plugins.cpp): the wall triangles times the layers' maximum count;
//   - 3D fill (volume/plugins.cpp): the metric volume inside the farfield (sizes no coarser than
//     the farfield's h, tets no larger than fill.max_volume: what TetGen makes), plus the layers' cells.
// An estimate that comes out NaN (a metric without a value somewhere) is not checked.
// Nodes are counted with the high-order ones, per cell of order q: q^2/2 per triangle, q^2 per
// quadrilateral, q^3/6 per tetrahedron, q^3/2 per prism, q per curve element.
#pragma once

#include <string>

#include "modules/pipeline/run_config.h"
#include "modules/pipeline/run_state.h"

namespace plaf {
inline namespace pipeline {

// Throws ConfigError "CONFIG: limits.KEY: WHAT would make about ESTIMATE (budget LIMIT); coarsen
// the metric or raise limits.KEY" when estimate > the limit of `key` ("surface_elements",
// "cells" or "nodes").
void check_limit(const RunConfig& c, const std::string& key, double estimate, const std::string& what);

// The 2D estimate of a run's section (the whole run in 2D; rows > 1: a section extruded in rows,
// each row a copy of the section's cells in 3D, prisms and tetrahedra alike counted as its
// triangles and quads times rows).
void check_section_budget(const RunState<2>& s, int rows);

// The layers' estimate: every wall element's column at most max_layers high (an upper bound:
// most runs stop earlier, at the isotropic size), quadrilaterals of q^2 nodes in 2D, prisms of
// q^3/2 in 3D. Called by the layer stage on its wall, and by the 3D surface stage on its estimate
// of the triangles to come (estimated: the message says "about").
void check_layer_budget(const RunConfig& c, double wall_elements, int max_layers, int dim, bool estimated = false);

}  // namespace pipeline
}  // namespace plaf
