// SPDX-License-Identifier: MIT
#include "modules/pipeline/layer_table.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace plaf {
inline namespace pipeline {

double LayerRow::curved_fraction() const {
  return measured_cells > 0 ? static_cast<double>(curved) / static_cast<double>(measured_cells)
                            : std::numeric_limits<double>::quiet_NaN();
}

template <int Dim>
std::vector<LayerRow> layer_rows(const LayerResult<Dim>& lr, const HybridMesh<Dim>& mesh, const CellQuality& pc) {
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
  std::vector<LayerRow> rows;
  for (const LayerStats& st : lr.layers) {
    LayerRow row;
    row.stats = st;
    row.measured = main_ok;
    row.min_scaled_jacobian = std::numeric_limits<double>::infinity();
    for (std::size_t c = st.first_cell; main_ok && c < st.first_cell + st.cells; ++c) {
      if (is_curved(mesh, mesh.cells[0], c)) ++row.curved;
      ++row.measured_cells;
      row.min_scaled_jacobian = std::min(row.min_scaled_jacobian, pc.scaled_jacobian[c]);
      row.max_aspect_ratio = std::max(row.max_aspect_ratio, pc.aspect_ratio[c]);
    }
    for (std::size_t c = st.first_transition_cell; trans_ok && c < st.first_transition_cell + st.transition_cells; ++c) {
      if (is_curved(mesh, mesh.cells[1], c)) ++row.curved;
      ++row.measured_cells;
      row.min_scaled_jacobian = std::min(row.min_scaled_jacobian, pc.scaled_jacobian[offset + c]);
      row.max_aspect_ratio = std::max(row.max_aspect_ratio, pc.aspect_ratio[offset + c]);
    }
    if (!main_ok) row.max_aspect_ratio = row.min_scaled_jacobian = std::numeric_limits<double>::quiet_NaN();
    rows.push_back(row);
  }
  return rows;
}

template <int Dim>
void report_layer_table(const LayerResult<Dim>& lr, const std::vector<LayerRow>& rows, StageReport& report) {
  std::vector<std::string> json;
  report.line("layer  cells  trans  curved  max_clip/h  min_scaled_J  max_aspect    height_min    height_max  coverage");
  for (const LayerRow& row : rows) {
    const LayerStats& st = row.stats;
    const std::string curved_json = row.measured ? std::to_string(row.curved) : "null";
    json.push_back("{\"layer\": " + std::to_string(st.layer) + ", \"cells\": " + std::to_string(st.cells) +
                   ", \"curved_cells\": " + curved_json +
                   ", \"max_clipped_over_height\": " + json_number(st.max_clipped_rel) +
                   ", \"f_atten\": " + json_number(st.f_atten) +
                   ", \"linear\": " + (st.linear ? "true" : "false") + ", \"min_scaled_jacobian\": " +
                   json_number(row.min_scaled_jacobian) + ", \"max_aspect_ratio\": " + json_number(row.max_aspect_ratio) +
                   ", \"shrinks\": " + std::to_string(st.shrinks) + ", \"shrunk\": " + (st.shrunk ? "true" : "false") +
                   ", \"transition_cells\": " + std::to_string(st.transition_cells) +
                   ", \"height_min\": " + json_number(st.min_height()) +
                   ", \"height_mean\": " + json_number(st.mean_height()) +
                   ", \"height_max\": " + json_number(st.max_height()) +
                   ", \"height_columns\": " + std::to_string(st.height_columns) +
                   ", \"coverage\": " + json_number(st.coverage) + "}");
    std::ostringstream o;
    o << std::setw(5) << st.layer << std::setw(7) << st.cells << std::setw(7) << st.transition_cells << std::setw(8)
      << curved_json << std::setw(12) << std::setprecision(3) << st.max_clipped_rel << std::setw(14)
      << row.min_scaled_jacobian << std::setw(12) << row.max_aspect_ratio << std::setw(14) << std::setprecision(4)
      << st.min_height() << std::setw(14) << st.max_height()  // nan: no column measured
      << std::setw(9) << std::fixed << std::setprecision(1) << 100 * st.coverage << " %";
    report.line(o.str());
  }
  std::vector<std::string> events;
  for (const std::string& e : lr.events) {
    events.push_back(json_string(e));
    report.line("layers: " + e);
  }
  report.add("count", lr.layers.size());
  report.add("linear_after", lr.linear_after);
  report.add_json("table", json_array(json));
  report.add_json("events", json_array(events));
  report.line("layers: " + std::to_string(lr.layers.size()) + ", front linear after layer " +
              std::to_string(lr.linear_after));
}

void layer_progress(const LayerStats& st, int max_layers, Progress& progress) {
  // The table's columns (report_layer_table), under the report's key names in the JSON.
  const bool closing = !std::isfinite(st.f_atten);
  std::ostringstream o;
  o << std::setprecision(3) << (closing ? "closing layer " : "layer ") << st.layer << " of " << max_layers
    << " accepted: " << st.cells << " cells, " << st.transition_cells << " trans, max_clip/h " << st.max_clipped_rel
    << ", height " << st.min_height() << " - " << st.max_height() << ", coverage " << std::fixed
    << std::setprecision(1) << 100 * st.coverage << " %";
  const std::string fields =
      "\"layer\": " + std::to_string(st.layer) + ", \"max_layers\": " + std::to_string(max_layers) +
      ", \"cells\": " + std::to_string(st.cells) + ", \"transition_cells\": " + std::to_string(st.transition_cells) +
      ", \"max_clipped_over_height\": " + json_number(st.max_clipped_rel) + ", \"f_atten\": " +
      json_number(st.f_atten) + ", \"linear\": " + (st.linear ? "true" : "false") +
      ", \"shrinks\": " + std::to_string(st.shrinks) + ", \"height_min\": " + json_number(st.min_height()) +
      ", \"height_mean\": " + json_number(st.mean_height()) + ", \"height_max\": " + json_number(st.max_height()) +
      ", \"coverage\": " + json_number(st.coverage);
  progress.step("layers", max_layers > 0 ? static_cast<double>(st.layer) / max_layers : 1.0, o.str(), fields);
}

template std::vector<LayerRow> layer_rows<2>(const LayerResult<2>&, const HybridMesh<2>&, const CellQuality&);
template std::vector<LayerRow> layer_rows<3>(const LayerResult<3>&, const HybridMesh<3>&, const CellQuality&);
template void report_layer_table<2>(const LayerResult<2>&, const std::vector<LayerRow>&, StageReport&);
template void report_layer_table<3>(const LayerResult<3>&, const std::vector<LayerRow>&, StageReport&);

}  // namespace pipeline
}  // namespace plaf
