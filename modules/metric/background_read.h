// SPDX-License-Identifier: MIT
// What the two background-mesh readers (background_read_msh.cpp, background_read_meshb.cpp)
// share, in 2D and 3D: a tensor read from a file checked as a metric, the packed symmetric
// tensor of libMeshb, and the mesh reduced to the nodes its simplices use. Internal to
// modules/metric; the readers are declared in background_metric.h.
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

// A Dim x Dim tensor read from a file as an SPD metric; the reason names the node and the line.
template <int Dim>
Metric<Dim> metric_from_file(TextCursor& in, int line, const Eigen::Matrix<double, Dim, Dim>& m,
                             const std::string& where);

// The symmetric matrix of Dim (Dim + 1) / 2 packed components in libMeshb's SymMat order, the
// lower triangle row by row: 2D xx xy yy, 3D xx xy yy xz yz zz. Sources: libMeshb
// (LoicMarechal/libMeshb, sources/libmeshb7.c: a GmfSymMat field holds dim (dim + 1) / 2 reals)
// and MMG, which reads these files (MmgTools/mmg, src/common/inout.c, MMG5_readDoubleSol3D:
// it swaps the file's values 2 and 3 into its own row-wise upper triangle xx xy xz yy yz zz).
// The search tool's docs corpus holds no page of the format itself.
template <int Dim>
Eigen::Matrix<double, Dim, Dim> symmetric_from_packed(const std::array<double, Dim*(Dim + 1) / 2>& v);

// Keeps only the nodes some simplex uses (high-order and free nodes go), in their order.
// has_value[i] tells whether node i carries a metric; a used node without one is reported.
template <int Dim, class Missing>
BackgroundMesh<Dim> compact_background_mesh(std::vector<typename BackgroundMesh<Dim>::Point> nodes,
                                            std::vector<typename BackgroundMesh<Dim>::Simplex> simplices,
                                            std::vector<Metric<Dim>> metrics, const std::vector<bool>& has_value,
                                            const Missing& missing) {
  std::vector<NodeId> new_id(nodes.size(), -1);
  for (const auto& s : simplices)
    for (NodeId v : s) new_id[static_cast<std::size_t>(v)] = 0;
  BackgroundMesh<Dim> out;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (new_id[i] < 0) continue;
    if (!has_value[i]) missing(i);
    new_id[i] = static_cast<NodeId>(out.nodes.size());
    out.nodes.push_back(nodes[i]);
    out.metrics.push_back(metrics[i]);
  }
  out.simplices = std::move(simplices);
  for (auto& s : out.simplices)
    for (NodeId& v : s) v = new_id[static_cast<std::size_t>(v)];
  return out;
}

}  // namespace metric
}  // namespace plaf
