// SPDX-License-Identifier: MIT
// Numbers in messages: the shortest form a stream gives (6 significant digits, as `<<`), so an
// error names a key's value as the user wrote it or close to it.
#pragma once

#include <sstream>
#include <string>

namespace plaf {
inline namespace base {

inline std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace base
}  // namespace plaf
