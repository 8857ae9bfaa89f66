// SPDX-License-Identifier: MIT
// The `naca:` key, accepted wherever an airfoil section file is (a 2D body, a 3D wing), in place
// of `file:` (modules/io/naca_section.h):
//   naca: "2412"                  the designation (quoted, so YAML keeps its leading zeros)
//   naca:                         or a map:
//     digits: "23012"             4 or 5 digits                                  (required)
//     trailing_edge: sharp|blunt  closed (a4 = -0.1036) or the standard open one  default: sharp
//     intervals: <4..100000>      cosine-spaced intervals per surface            default: 100
#pragma once

#include <optional>
#include <string>

#include "modules/io/naca_section.h"
#include "modules/pipeline/config.h"

namespace plaf {
inline namespace pipeline {

// The section of `n`'s `naca:` key, or nothing when absent. ConfigError naming the key for a bad
// designation or option.
std::optional<NacaSection> parse_naca(const ConfigNode& n);

}  // namespace pipeline
}  // namespace plaf
