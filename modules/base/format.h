// SPDX-License-Identifier: MIT
// Numbers and points in messages: a number in the shortest form a stream gives (6 significant
// digits, as `<<`), so an error names a key's value as the user wrote it or close to it; a point
// as "(x, y)" or "(x, y, z)" with 9 significant digits, enough to find the node in a mesh viewer.
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

// Any fixed-size Eigen vector (2D or 3D point).
template <class Vec>
std::string point_text(const Vec& x, int digits = 9) {
  std::ostringstream s;
  s.precision(digits);
  s << "(";
  for (int d = 0; d < static_cast<int>(x.size()); ++d) s << (d ? ", " : "") << x[d];
  s << ")";
  return s.str();
}

}  // namespace base
}  // namespace plaf
