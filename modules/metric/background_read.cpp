// SPDX-License-Identifier: MIT
// Implements the tensor helpers shared by the background-mesh readers (background_read.h).
#include "modules/metric/background_read.h"

#include "modules/base/error.h"

namespace plaf {
inline namespace metric {

template <int Dim>
Metric<Dim> metric_from_file(TextCursor& in, int line, const Eigen::Matrix<double, Dim, Dim>& m,
                             const std::string& where) {
  try {
    return Metric<Dim>::from_matrix(m);
  } catch (const InputError& e) {
    // The components by name, row by row: (xx 1, xy 0, yx 0, yy 2).
    static constexpr char axis[] = {'x', 'y', 'z'};
    std::string components;
    for (int i = 0; i < Dim; ++i)
      for (int j = 0; j < Dim; ++j)
        components += std::string(components.empty() ? "" : ", ") + axis[i] + axis[j] + " " + std::to_string(m(i, j));
    in.fail_at(line, "the tensor at " + where + " (" + components + "): " + e.what());
  }
}
template Metric<2> metric_from_file<2>(TextCursor&, int, const Eigen::Matrix2d&, const std::string&);
template Metric<3> metric_from_file<3>(TextCursor&, int, const Eigen::Matrix3d&, const std::string&);

template <int Dim>
Eigen::Matrix<double, Dim, Dim> symmetric_from_packed(const std::array<double, Dim*(Dim + 1) / 2>& v) {
  Eigen::Matrix<double, Dim, Dim> m;
  std::size_t k = 0;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j <= i; ++j) m(i, j) = m(j, i) = v[k++];
  return m;
}
template Eigen::Matrix2d symmetric_from_packed<2>(const std::array<double, 3>&);
template Eigen::Matrix3d symmetric_from_packed<3>(const std::array<double, 6>&);

}  // namespace metric
}  // namespace plaf
