// SPDX-License-Identifier: MIT
// The weighted mean of three 2D metrics in closed form, for the background-mesh field
// (background_metric.h): the log-Euclidean mean exp(sum w_i log M_i), or the affine-invariant
// (Karcher) mean. metric.h's log_euclidean_mean and affine_invariant_mean take any number of
// metrics of any dimension through Eigen's eigensolver; evaluating a background metric is a hot
// path with three 2x2 metrics whose logarithms are computed once, so it has its own closed form.
// Internal to modules/metric.
#pragma once

#include <array>

#include "modules/metric/metric.h"

namespace plaf {
inline namespace metric {

// m: the three metrics; logs: their logarithms (Metric::log); w: barycentric weights >= 0
// summing to 1.
Metric<2> metric_mean3(MetricMean mean, const std::array<const Eigen::Matrix2d*, 3>& m,
                       const std::array<const Eigen::Matrix2d*, 3>& logs, const Eigen::Vector3d& w);

}  // namespace metric
}  // namespace plaf
