// SPDX-License-Identifier: MIT
// The `naca:` key (naca_config.h).
#include "modules/pipeline/naca_config.h"

#include "modules/base/error.h"

namespace plaf {
inline namespace pipeline {

std::optional<NacaSection> parse_naca(const ConfigNode& n) {
  if (!n.has("naca")) return std::nullopt;
  NacaSection s;
  std::string where = n.where("naca");
  if (n.is_map("naca")) {
    const ConfigNode m = n.child("naca");
    if (!m.has("digits")) throw ConfigError(m.where() + ": digits is required (e.g. digits: \"0012\")");
    s.digits = m.get_string("digits", s.digits);
    where = m.where("digits");
    s.sharp = m.get_choice("trailing_edge", "sharp", {"sharp", "blunt"}) == "sharp";
    s.intervals = m.get_int("intervals", s.intervals, 4, 100000);
  } else {
    s.digits = n.get_string("naca", s.digits);
  }
  try {
    check_naca(s);
  } catch (const InputError& e) {
    throw ConfigError(where + ": " + e.what());
  }
  return s;
}

}  // namespace pipeline
}  // namespace plaf
