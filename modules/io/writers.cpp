// SPDX-License-Identifier: MIT
#include "modules/io/writers.h"

#include <algorithm>
#include <limits>

#include "modules/io/atomic_file.h"
#include "modules/io/msh_io.h"
#include "modules/io/picture.h"
#include "modules/io/vtu_writer.h"

namespace plaf {
inline namespace io {

namespace {

void write_msh(const WriteJob& j) {
  write_msh41(j.mesh, j.base.string() + ".msh");
}

void write_vtu_file(const WriteJob& j) {
  // VTK 9.1 reads "-inf" as +inf: fully inverted cells (scaled Jacobian -inf) and degenerate
  // ones (aspect ratio inf) are written as the most extreme finite values.
  auto finite = [](std::vector<double> v) {
    for (double& x : v) x = std::clamp(x, std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max());
    return v;
  };
  if (j.mesh.cells.empty()) {  // a surface mesh alone: its lines, no per-cell quality
    write_vtu(j.mesh, j.base.string() + ".vtu");
    return;
  }
  const std::vector<double> valid(j.per_cell.valid.begin(), j.per_cell.valid.end());
  write_vtu(j.mesh, j.base.string() + ".vtu",
            {{"valid", valid},
             {"scaled_jacobian", finite(j.per_cell.scaled_jacobian)},
             {"aspect_ratio", finite(j.per_cell.aspect_ratio)}});
}

void write_picture(const WriteJob& j) {
  PictureOptions po;
  po.width = j.config.output.picture_width;
  po.height = j.config.output.picture_height;
  po.title = j.config.name + " (Q=" + std::to_string(j.config.order) + ")";
  for (const auto& z : j.config.output.zooms) po.zooms.push_back({z.label, z.box[0], z.box[1], z.box[2], z.box[3]});
  write_png(j.mesh, j.per_cell.valid, j.base.string() + ".png", po);
}

void write_report(const WriteJob& j) {
  AtomicFile f(j.base.string() + ".report.json");
  f.write(report_json(j.report));
  f.commit();
}

}  // namespace

Writer2Registry& writer_registry() {
  static Writer2Registry registry = [] {
    Writer2Registry r("output format");
    r.add("msh", write_msh);
    r.add("vtu", write_vtu_file);
    r.add("png", write_picture);
    r.add("report", write_report);
    return r;
  }();
  return registry;
}

}  // namespace io
}  // namespace plaf
