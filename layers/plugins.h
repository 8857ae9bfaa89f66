// SPDX-License-Identifier: MIT
// The layer stage's plugins (modules/pipeline/stages.h), registered by register_plugins():
// `extrude`, the prismatic layers grown from the walls (curved quadrilaterals in 2D,
// grow_layers_2d.h; curved prisms in 3D, grow_layers_3d.h; the dimension-generic core,
// layer_core.h). Their keys, types, defaults and descriptions: `plaf keys layers`
// (docs/config.md; the lines in apps/key_notes.cpp). Why a default is what it is: the comments
// at each key in parse_layer_params (plugins.cpp). With a fill after the layers, a loop that
// stops curved gets a closing layer (layer_core.h).
#pragma once

#include "layers/layer_core.h"
#include "modules/pipeline/config.h"

namespace plaf::layers {

// The layer options of a `layers:` section of a run in `dim` dimensions (ConfigError naming the
// key for a bad value).
LayerParams parse_layer_params(const ConfigNode& section, int dim);

void register_plugins();

}  // namespace plaf::layers
