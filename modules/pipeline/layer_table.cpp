// SPDX-License-Identifier: MIT
#include "modules/pipeline/layer_table.h"

#include <algorithm>
#include <iomanip>
#include <limits>
#include <sstream>

namespace plaf {
inline namespace pipeline {

template <int Dim>
void report_layer_table(const LayerResult<Dim>& lr, const HybridMesh<Dim>& mesh, const CellQuality& pc,
                        StageReport& report) {
  std::vector<std::string> rows;
  report.line("layer  cells  trans  curved  max_clip/h  min_scaled_J  max_aspect");
  // The layers' cells are the mesh's first blocks: main cells (2D quadrilaterals, 3D prisms) in
  // cells[0], transition cells (2D triangles, 3D tetrahedra) in cells[1], numbered in that order
  // (the per-cell quality follows it). Where the assembly changed them (2D split_quads cuts the
  // quadrilaterals into triangles) the table gives no quality columns for them.
  std::size_t main_total = 0, trans_total = 0;
  for (const LayerStats& st : lr.layers) main_total += st.cells, trans_total += st.transition_cells;
  const CellType main_type = Dim == 2 ? CellType::Quadrilateral : CellType::Prism;
  const CellType trans_type = Dim == 2 ? CellType::Triangle : CellType::Tetrahedron;
  const bool main_ok = !mesh.cells.empty() && mesh.cells[0].type == main_type && main_total <= mesh.cells[0].size();
  const bool trans_ok = main_ok && mesh.cells.size() > 1 && mesh.cells[1].type == trans_type &&
                        trans_total <= mesh.cells[1].size();
  const std::size_t offset = main_ok ? mesh.cells[0].size() : 0;
  for (const LayerStats& st : lr.layers) {
    std::size_t curved = 0;
    double min_sj = std::numeric_limits<double>::infinity(), max_ar = 0;
    for (std::size_t c = st.first_cell; main_ok && c < st.first_cell + st.cells; ++c) {
      if (is_curved(mesh, mesh.cells[0], c)) ++curved;
      min_sj = std::min(min_sj, pc.scaled_jacobian[c]);
      max_ar = std::max(max_ar, pc.aspect_ratio[c]);
    }
    for (std::size_t c = st.first_transition_cell; trans_ok && c < st.first_transition_cell + st.transition_cells; ++c) {
      if (is_curved(mesh, mesh.cells[1], c)) ++curved;
      min_sj = std::min(min_sj, pc.scaled_jacobian[offset + c]);
      max_ar = std::max(max_ar, pc.aspect_ratio[offset + c]);
    }
    if (!main_ok) max_ar = std::numeric_limits<double>::quiet_NaN();  // not measured: null
    const std::string curved_json = main_ok ? std::to_string(curved) : "null";
    rows.push_back("{\"layer\": " + std::to_string(st.layer) + ", \"cells\": " + std::to_string(st.cells) +
                   ", \"curved_cells\": " + curved_json +
                   ", \"max_clipped_over_height\": " + json_number(st.max_clipped_rel) +
                   ", \"linear\": " + (st.linear ? "true" : "false") + ", \"min_scaled_jacobian\": " +
                   json_number(min_sj) + ", \"max_aspect_ratio\": " + json_number(max_ar) +
                   ", \"shrinks\": " + std::to_string(st.shrinks) +
                   ", \"transition_cells\": " + std::to_string(st.transition_cells) + "}");
    std::ostringstream o;
    o << std::setw(5) << st.layer << std::setw(7) << st.cells << std::setw(7) << st.transition_cells << std::setw(8) << curved_json << std::setw(12)
      << std::setprecision(3) << st.max_clipped_rel << std::setw(14) << min_sj << std::setw(12) << max_ar;
    report.line(o.str());
  }
  std::vector<std::string> events;
  for (const std::string& e : lr.events) {
    events.push_back(json_string(e));
    report.line("layers: " + e);
  }
  report.add("count", lr.layers.size());
  report.add("linear_after", lr.linear_after);
  report.add_json("table", json_array(rows));
  report.add_json("events", json_array(events));
  report.line("layers: " + std::to_string(lr.layers.size()) + ", front linear after layer " +
              std::to_string(lr.linear_after));
}

template void report_layer_table<2>(const LayerResult<2>&, const HybridMesh<2>&, const CellQuality&, StageReport&);
template void report_layer_table<3>(const LayerResult<3>&, const HybridMesh<3>&, const CellQuality&, StageReport&);

}  // namespace pipeline
}  // namespace plaf
