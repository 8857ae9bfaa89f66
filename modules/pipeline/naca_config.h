// SPDX-License-Identifier: MIT
// The `naca:` key, accepted wherever an airfoil section file is (a 2D body, a 3D wing), in place
// of `file:` (modules/io/naca_section.h): a designation (`naca: "2412"`, quoted so YAML keeps its
// leading zeros) or a map of digits, trailing_edge and intervals. Types, defaults and
// descriptions: `plaf keys geometry` (docs/config.md; the lines in apps/key_notes.cpp).
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
