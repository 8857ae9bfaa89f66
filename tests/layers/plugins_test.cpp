// SPDX-License-Identifier: MIT
// The layers section's defaults (layers/plugins.cpp) that differ between 2D and 3D.
#include "layers/plugins.h"

#include <doctest/doctest.h>

#include "modules/pipeline/config.h"

using namespace plaf;
using layers::IsotropicStop;

namespace {
IsotropicStop stop_of(const std::string& yaml, int dim) {
  return layers::parse_layer_params(ConfigNode::load_string(yaml), dim).isotropic_stop;
}
}  // namespace

TEST_CASE("layers section: isotropic_stop defaults to node in 3D, to off (all with stop_when_linear) in 2D") {
  CHECK(stop_of("max: 40", 3) == IsotropicStop::Node);
  CHECK(stop_of("{max: 40, stop_when_linear: true}", 3) == IsotropicStop::Node);
  CHECK(stop_of("max: 40", 2) == IsotropicStop::Off);
  CHECK(stop_of("{max: 40, stop_when_linear: true}", 2) == IsotropicStop::All);
  // Given, it is kept in either dimension.
  for (const int dim : {2, 3}) {
    CHECK(stop_of("isotropic_stop: off", dim) == IsotropicStop::Off);
    CHECK(stop_of("isotropic_stop: all", dim) == IsotropicStop::All);
    CHECK(stop_of("isotropic_stop: any", dim) == IsotropicStop::Any);
    CHECK(stop_of("isotropic_stop: node", dim) == IsotropicStop::Node);
  }
}

TEST_CASE("layers section: fan_fades is a 3D option, off by default") {
  CHECK_FALSE(layers::parse_layer_params(ConfigNode::load_string("max: 40"), 3).fan_fades);
  CHECK(layers::parse_layer_params(ConfigNode::load_string("fan_fades: true"), 3).fan_fades);
  // 2D does not read it (a 2D section naming it is refused as an unknown key by the run's check).
  CHECK_FALSE(layers::parse_layer_params(ConfigNode::load_string("fan_fades: true"), 2).fan_fades);
}

TEST_CASE("layers section: smooth_normals defaults to on in 3D, off in 2D, and is kept when given") {
  auto smooth = [](const std::string& yaml, int dim) {
    return layers::parse_layer_params(ConfigNode::load_string(yaml), dim).smooth_normals;
  };
  CHECK(smooth("max: 40", 3));
  CHECK_FALSE(smooth("max: 40", 2));
  for (const int dim : {2, 3}) {
    CHECK(smooth("smooth_normals: true", dim));
    CHECK_FALSE(smooth("smooth_normals: false", dim));
  }
}
