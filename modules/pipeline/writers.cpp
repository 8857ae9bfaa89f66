// SPDX-License-Identifier: MIT
#include "modules/pipeline/writers.h"

#include <algorithm>
#include <limits>

#include "modules/io/atomic_file.h"
#include "modules/io/cgns_io.h"
#include "modules/io/msh_io.h"
#include "modules/io/picture.h"
#include "modules/io/picture3d.h"
#include "modules/io/vtu_writer.h"

namespace plaf {
inline namespace pipeline {

namespace {

// output.msh / output.vtu: "binary", "ascii", or "auto": binary above OutputParams::kBinaryNodes.
template <int Dim>
bool binary(const std::string& encoding, const HybridMesh<Dim>& mesh) {
  return encoding == "binary" || (encoding == "auto" && mesh.nodes.size() > OutputParams::kBinaryNodes);
}

template <int Dim>
void write_msh(const WriteJob<Dim>& j) {
  write_msh41(j.mesh, j.base.string() + ".msh",
              binary(j.config.output.msh, j.mesh) ? MshEncoding::binary : MshEncoding::ascii);
}

// Gmsh's legacy MSH 2.2 beside the 4.1 file, as NAME_msh22.msh, in output.msh's encoding.
template <int Dim>
void write_msh22_file(const WriteJob<Dim>& j) {
  write_msh22(j.mesh, j.base.string() + "_msh22.msh",
              binary(j.config.output.msh, j.mesh) ? MshEncoding::binary : MshEncoding::ascii);
}

// CGNS (cgns_io.h) as NAME.cgns.
template <int Dim>
void write_cgns_file(const WriteJob<Dim>& j) {
  write_cgns(j.mesh, j.base.string() + ".cgns");
}

template <int Dim>
void write_vtu_file(const WriteJob<Dim>& j) {
  // VTK 9.1 reads "-inf" as +inf: fully inverted cells (scaled Jacobian -inf) and degenerate
  // ones (aspect ratio inf) are written as the most extreme finite values.
  auto finite = [](std::vector<double> v) {
    for (double& x : v) x = std::clamp(x, std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max());
    return v;
  };
  const VtuEncoding encoding = binary(j.config.output.vtu, j.mesh) ? VtuEncoding::binary : VtuEncoding::ascii;
  if (j.per_cell.valid.empty()) {  // a 2D surface mesh alone: its lines, no per-cell quality
    write_vtu(j.mesh, j.base.string() + ".vtu", {}, encoding);
  } else {
    const std::vector<double> valid(j.per_cell.valid.begin(), j.per_cell.valid.end());
    write_vtu(j.mesh, j.base.string() + ".vtu",
              {{"valid", valid},
               {"scaled_jacobian", finite(j.per_cell.scaled_jacobian)},
               {"aspect_ratio", finite(j.per_cell.aspect_ratio)}},
              encoding);
  }
  // The boundary in a file of its own (one dimension per file: vtu_writer.h).
  write_boundary_vtu(j.mesh, j.base.string() + "_boundary.vtu", encoding);
}

// The options both pictures share: size, title, zoom boxes.
template <class Options, int Dim>
Options picture_options(const WriteJob<Dim>& j) {
  Options po;
  po.width = j.config.output.picture_width;
  po.height = j.config.output.picture_height;
  po.title = j.config.name + " (Q=" + std::to_string(j.config.order) + ")";
  for (const auto& z : j.config.output.zooms) po.zooms.push_back({z.label, z.box[0], z.box[1], z.box[2], z.box[3]});
  return po;
}

// A failed run's focus (QualityReport::focus) as one more zoom panel, first.
std::string focus_label(const QualityReport& r) { return "where it failed: " + r.focus_label; }

void write_picture(const WriteJob<2>& j) {
  PictureOptions po = picture_options<PictureOptions>(j);
  const QualityReport& r = j.report;
  if (r.focus.size() == 2)
    po.zooms.insert(po.zooms.begin(), ZoomBox{focus_label(r), r.focus[0] - r.focus_radius, r.focus[0] + r.focus_radius,
                                              r.focus[1] - r.focus_radius, r.focus[1] + r.focus_radius});
  write_png(j.mesh, j.per_cell.valid, j.base.string() + ".png", po);
}

void write_picture_3d(const WriteJob<3>& j) {
  Picture3Options po = picture_options<Picture3Options>(j);
  const auto& o = j.config.output;
  if (o.has_cut) {
    po.cut_point = Eigen::Vector3d(o.cut_point[0], o.cut_point[1], o.cut_point[2]);
    po.cut_normal = Eigen::Vector3d(o.cut_normal[0], o.cut_normal[1], o.cut_normal[2]);
  } else {
    default_cut(j.mesh, po.cut_point, po.cut_normal);
  }
  const QualityReport& r = j.report;
  if (r.focus.size() == 3) {  // the cut through the focus (the configured plane's normal kept)
    po.focus = Eigen::Vector3d(r.focus[0], r.focus[1], r.focus[2]);
    po.focus_radius = r.focus_radius;
    po.focus_label = focus_label(r);
    po.cut_point = *po.focus;
  }
  po.view = Eigen::Vector3d(o.view[0], o.view[1], o.view[2]);
  if (j.coverage) {
    for (const LayerCoverage::Column& c : j.coverage->short_columns)
      po.short_columns.push_back({Eigen::Vector3d(c.point[0], c.point[1], c.point[2]), c.layer});
    po.layers = j.layers;
  }
  // A surface run's flags are its facets' (no cells): the picture draws them all valid.
  const bool cells = j.per_cell.valid.size() == j.mesh.num_cells();
  static const std::vector<std::uint8_t> none;
  const std::vector<std::uint8_t>& valid = cells ? j.per_cell.valid : none;
  write_png(j.mesh, valid, j.base.string() + ".png", po);
  // output.cuts: a picture each, its plane through its point, zoomed on the point with a radius
  // (the failure's focus is the main picture's).
  for (std::size_t k = 0; k < o.cuts.size(); ++k) {
    const OutputParams::Cut& c = o.cuts[k];
    Picture3Options pk = po;
    pk.title = po.title + ", cut " + std::to_string(k + 1) + (c.label.empty() ? "" : ": " + c.label);
    pk.cut_point = Eigen::Vector3d(c.point[0], c.point[1], c.point[2]);
    pk.cut_normal = Eigen::Vector3d(c.normal[0], c.normal[1], c.normal[2]);
    pk.focus.reset();
    pk.zooms.clear();  // output.zooms are boxes in the main cut's plane
    if (c.radius > 0) {
      pk.focus = pk.cut_point;
      pk.focus_radius = c.radius;
      pk.focus_label = c.label.empty() ? "around the cut's point" : c.label;
    }
    write_png(j.mesh, valid, j.base.string() + ".cut" + std::to_string(k + 1) + ".png", pk);
  }
}

template <int Dim>
void write_report(const WriteJob<Dim>& j) {
  AtomicFile f(j.base.string() + ".report.json");
  f.write(report_json(j.report));
  f.commit();
}

}  // namespace

template <>
WriterRegistry<2>& writer_registry<2>() {
  static WriterRegistry<2> registry = [] {
    WriterRegistry<2> r("output format");
    r.add("msh", write_msh<2>);
    r.add("msh22", write_msh22_file<2>);
    r.add("cgns", write_cgns_file<2>);
    r.add("vtu", write_vtu_file<2>);
    r.add("png", write_picture);
    r.add("report", write_report<2>);
    return r;
  }();
  return registry;
}

template <>
WriterRegistry<3>& writer_registry<3>() {
  static WriterRegistry<3> registry = [] {
    WriterRegistry<3> r("output format");
    r.add("msh", write_msh<3>);
    r.add("msh22", write_msh22_file<3>);
    r.add("cgns", write_cgns_file<3>);
    r.add("vtu", write_vtu_file<3>);
    r.add("png", write_picture_3d);
    r.add("report", write_report<3>);
    return r;
  }();
  return registry;
}

}  // namespace pipeline
}  // namespace plaf
