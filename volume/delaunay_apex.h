// SPDX-License-Identifier: MIT
// The fallback of the 2D advancing front (advancing_front_2d.h) where the greedy step finds no
// valid triangle for an edge: the constrained-Delaunay apex in the metric of the edge's start.
// Internal to volume/.
#pragma once

#include <optional>

#include "volume/occurrence_front.h"

namespace plaf::volume {

// The constrained-Delaunay apex of the edge o in the metric of its start: among the front nodes
// left of the edge, those whose circumcircle with the edge reaches least far to the left first,
// the first that makes a valid triangle (of params' min_quality and max_length, then of any
// shape); failing those, a new point below the edge's metric-equilateral apex. The search box
// doubles until one is found; nullopt when none is (the front is no valid polygon).
std::optional<Apex> delaunay_apex(const OccurrenceFront& front, int o, const AdvancingFrontParams& params);

}  // namespace plaf::volume
