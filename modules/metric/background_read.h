// SPDX-License-Identifier: MIT
// What the two background-mesh readers (background_read_msh.cpp, background_read_meshb.cpp)
// share: a tensor read from a file checked as a metric, and the mesh reduced to the nodes its
// triangles use. Internal to modules/metric; the readers are declared in background_metric.h.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "modules/io/text_cursor.h"
#include "modules/metric/background_metric.h"

namespace plaf {
inline namespace metric {

// A 2x2 block read from a file as an SPD metric; the reason names the node and the line.
Metric<2> metric_from_file(TextCursor& in, int line, const Eigen::Matrix2d& m, const std::string& where);

// Keeps only the nodes some triangle uses (high-order and free nodes go), in their order.
// has_value[i] tells whether node i carries a metric; a used node without one is reported.
template <class Missing>
BackgroundMesh compact_background_mesh(std::vector<Eigen::Vector2d> nodes, std::vector<std::array<NodeId, 3>> triangles,
                                       std::vector<Metric<2>> metrics, const std::vector<bool>& has_value,
                                       const Missing& missing) {
  std::vector<NodeId> new_id(nodes.size(), -1);
  for (const auto& t : triangles)
    for (NodeId v : t) new_id[static_cast<std::size_t>(v)] = 0;
  BackgroundMesh out;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (new_id[i] < 0) continue;
    if (!has_value[i]) missing(i);
    new_id[i] = static_cast<NodeId>(out.nodes.size());
    out.nodes.push_back(nodes[i]);
    out.metrics.push_back(metrics[i]);
  }
  out.triangles = std::move(triangles);
  for (auto& t : out.triangles)
    for (NodeId& v : t) v = new_id[static_cast<std::size_t>(v)];
  return out;
}

}  // namespace metric
}  // namespace plaf
