// SPDX-License-Identifier: MIT
// The fill stage's plugins (modules/pipeline/stages.h), registered by register_plugins():
//   fill:                   the domain between the layers' outer front (or the surface mesh of
//                           bodies without layers) and the farfield, with linear cells
//     type: advancing_front 2D: the metric advancing front (advancing_front_2d.h)   default type
//     max_triangles: <n>    give up (an error) beyond this many triangles   default: 20000000
#pragma once

namespace plaf::volume {

void register_plugins();

}  // namespace plaf::volume
