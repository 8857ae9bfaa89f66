// SPDX-License-Identifier: MIT
// The layer stage's plugins (modules/pipeline/stages.h), registered by register_plugins():
//   layers:                 prismatic layers grown from the walls (grow_layers_2d.h)
//     type: extrude         2D: curved quadrilaterals along the normals    default type
//     max: <0..10000>       number of layers (0: none, the surface mesh alone)   default: 24
//     stop_when_linear: <bool>  stop after the first linear front  default: false
//     f_atten: <0..1>       curvature attenuation fraction (Fig. 5)   default: 0.2
//     corner_angle_deg: <1..179>  turning angle of a corner       default: 30
//     fan_angle_deg: <5..90>  largest angle between fan normals   default: 45
//     fan_fades: <bool>     3D: a ridge fan may end where its ridge fades (a trailing edge into
//                           a rounded tip), narrowing and closing there; false: that ridge keeps
//                           one merged normal along its length (grow_layers_3d.h, step 6)
//                                                                      default: false
//     height: size|integrate  metric size along the normal, or unit metric length   default: size
//     smooth_normals: <bool>  smooth the normals of each layer (2D: one Laplacian pass; 3D: the
//                           relaxation of grow_layers_3d.h, step 2)   default: false
//     high_order_heights: default|own|interpolated  a high-order node's height: its own metric
//                           height, or its element's vertex heights interpolated (layer_core.h)
//                           default: interpolated (2D and 3D)
//     isotropic_stop: off|node|any|all  stop a node where the metric is isotropic there, or the
//                           loop when it is so at any/all nodes
//                           default: 3D node; 2D all with stop_when_linear, else off
//     local_stops: <bool>   3D: where a cell cannot be valid even at 1/16 of the metric's height,
//                           stop its columns there and grow the rest (false: stop the whole
//                           surface, as 2D does)                      default: true
//     proximity: <0..1>     3D: the share of its half of the gap to a facing wall (along its
//                           column) a column's stack may fill; there the stack that fits is its
//                           stop rule (reported as coverage.proximity; 0: off)   default: 0.8
//     min_coverage: <0..1>  the fraction of the wall whose columns must reach their stop rule
//                           (not end on a failure); below it, or with the first layer taller
//                           than 4 times the metric's height on over 1 % of the wall's columns,
//                           the run fails (exit 2; layers.coverage in the report, with the early
//                           stops grouped by region)                  default: 0.95
// With a fill after the layers, a loop that stops curved gets a closing layer (layer_core.h).
#pragma once

#include "layers/layer_core.h"
#include "modules/pipeline/config.h"

namespace plaf::layers {

// The layer options of a `layers:` section of a run in `dim` dimensions (ConfigError naming the
// key for a bad value).
LayerParams parse_layer_params(const ConfigNode& section, int dim);

void register_plugins();

}  // namespace plaf::layers
