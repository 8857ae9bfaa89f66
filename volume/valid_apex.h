// SPDX-License-Identifier: MIT
// The tests a candidate triangle of the 2D advancing front (advancing_front_2d.h, step 6) must
// pass before it is emitted, and the clearance of a new point from the front. Internal to volume/.
#pragma once

#include <Eigen/Core>

#include "volume/occurrence_front.h"

namespace plaf::volume {

// Is (a, b, c) a valid triangle on the front edge o: a -> b, with c the apex (an existing front
// occurrence, or a new point)? Counter-clockwise, inside the free angle at a, b and c, crossing
// and touching no front edge, with no front node inside or on it; with min_quality > 0, of at
// least that shape quality in the metric of a; with max_length > 0, no new edge longer than
// max_length (or than the edge a -> b) in the metric integrated along it.
bool valid_apex(const OccurrenceFront& front, int o, const Apex& c, double min_quality, double max_length = 0);

// Is the new point x at least `clearance` (in the metric m) from every front edge?
bool clear_of_front(const OccurrenceFront& front, const Eigen::Vector2d& x, const NodeMetric& m, double clearance);

}  // namespace plaf::volume
