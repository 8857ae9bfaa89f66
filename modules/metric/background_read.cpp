// SPDX-License-Identifier: MIT
// Implements the tensor check shared by the background-mesh readers (background_read.h).
#include "modules/metric/background_read.h"

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {

Metric<2> metric_from_file(TextCursor& in, int line, const Eigen::Matrix2d& m, const std::string& where) {
  try {
    return Metric<2>::from_matrix(m);
  } catch (const InputError& e) {
    in.fail_at(line, "the tensor at " + where + " (xx " + std::to_string(m(0, 0)) + ", xy " + std::to_string(m(0, 1)) +
                         ", yx " + std::to_string(m(1, 0)) + ", yy " + std::to_string(m(1, 1)) + "): " + e.what());
  }
}

}  // namespace metric
}  // namespace plaf
