// SPDX-License-Identifier: MIT
// `plaf picture` (see picture.h).
#include "apps/picture.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "modules/base/error.h"
#include "modules/base/format.h"
#include "modules/io/cgns_io.h"
#include "modules/io/msh_io.h"
#include "modules/io/picture.h"
#include "modules/io/picture3d.h"
#include "modules/mesh/quality.h"

namespace plaf {

namespace {

// The cell of the smallest certified scaled Jacobian (an invalid one first; among equals, e.g.
// the straight cells of an order-1 mesh, whose scaled Jacobian is 1, the largest aspect ratio):
// its centre (the mean of its nodes) and half its largest extent; false for a mesh without cells.
template <int Dim>
bool worst_cell(const HybridMesh<Dim>& mesh, const CellQuality& q, Eigen::Matrix<double, Dim, 1>& centre,
                double& radius, double& value, double& ratio_out) {
  std::size_t flat = 0, best = std::numeric_limits<std::size_t>::max();
  const CellBlock* best_block = nullptr;
  std::size_t best_cell = 0;
  value = std::numeric_limits<double>::infinity();
  double best_ratio = 0;
  for (const CellBlock& b : mesh.cells)
    for (std::size_t c = 0; c < b.size(); ++c, ++flat) {
      const double sj = flat < q.scaled_jacobian.size() ? q.scaled_jacobian[flat] : value;
      const double ratio = flat < q.aspect_ratio.size() ? q.aspect_ratio[flat] : 0.0;
      const bool invalid = flat < q.valid.size() && !q.valid[flat];
      // An invalid cell ranks below every valid one (its bound may not be finite).
      const double key = invalid ? -std::numeric_limits<double>::infinity() : sj;
      if (best_block == nullptr || key < value || (key == value && ratio > best_ratio)) {
        value = key;
        best_ratio = ratio;
        best = flat;
        best_block = &b;
        best_cell = c;
      }
    }
  if (best_block == nullptr) return false;
  using Vec = Eigen::Matrix<double, Dim, 1>;
  Vec lo = Vec::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  centre.setZero();
  const int n = best_block->nodes_per_cell();
  for (int k = 0; k < n; ++k) {
    const Vec& x = mesh.nodes[static_cast<std::size_t>(best_block->cell(best_cell)[k])];
    centre += x;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  centre /= n;
  radius = 0.5 * (hi - lo).maxCoeff();
  value = best < q.scaled_jacobian.size() ? q.scaled_jacobian[best] : value;
  ratio_out = best_ratio;
  return true;
}

std::string where_text(const double* x, int dim) {
  std::ostringstream w;
  w << "(";
  for (int d = 0; d < dim; ++d) w << (d ? ", " : "") << x[d];
  w << ")";
  return w.str();
}

}  // namespace

std::vector<double> parse_numbers(const std::string& option, const std::string& value, std::size_t min_count,
                                  std::size_t max_count) {
  std::vector<double> out;
  std::stringstream in(value);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (item.empty() || used != item.size() || !std::isfinite(x))
      throw InputError(option + ": '" + value + "' is not a list of numbers separated by commas");
    out.push_back(x);
  }
  if (out.size() < min_count || out.size() > max_count)
    throw InputError(option + ": '" + value + "' has " + std::to_string(out.size()) + " numbers, expected " +
                     (min_count == max_count ? std::to_string(min_count)
                                             : std::to_string(min_count) + " to " + std::to_string(max_count)));
  return out;
}

int picture_command(const PictureRequest& r) {
  std::filesystem::path out = r.out ? *r.out : r.mesh.parent_path() / (r.mesh.stem().string() + ".picture.png");
  if (out.extension() != ".png") throw InputError("--out " + out.string() + ": the picture is a .png file");
  const MshMesh m = read_mesh_file(r.mesh);
  for (const auto& z : r.zooms)
    if (z.size() != static_cast<std::size_t>(m.dim + 1))
      throw InputError("--at: a " + std::to_string(m.dim) + "D mesh's zoom is " + (m.dim == 2 ? "X,Y,R" : "X,Y,Z,R") +
                       ", got " + std::to_string(z.size()) + " numbers");
  if (m.dim == 2 && (r.cut || r.view)) throw InputError("--cut and --view are for 3D meshes; " + r.mesh.string() + " is 2D");
  for (const auto& z : r.zooms)
    if (!(z.back() > 0)) throw InputError("--at: the half-width must be positive, got " + std::to_string(z.back()));
  QualityOptions qo;
  CellQuality per_cell;
  QualityReport report;
  if (m.dim == 2)
    report = assess_quality<2>(m.mesh2, nullptr, qo, &per_cell);
  else
    report = assess_quality<3>(m.mesh3, nullptr, qo, &per_cell);
  report.name = r.mesh.string();
  std::cout << report_summary(report);
  const std::string title = r.mesh.filename().string();
  std::string worst_label;
  if (m.dim == 2) {
    PictureOptions po;
    po.width = r.width;
    po.height = r.height;
    po.title = title;
    Eigen::Vector2d c;
    double radius = 0, sj = 0, ratio = 0;
    if (worst_cell<2>(m.mesh2, per_cell, c, radius, sj, ratio)) {
      const double h = std::max(4 * radius, 1e-12);
      worst_label = "worst cell, scaled Jacobian " + num(sj) + ", aspect ratio " + num(ratio) + " at " +
                    where_text(c.data(), 2);
      po.zooms.push_back({worst_label, c.x() - h, c.x() + h, c.y() - h, c.y() + h});
    }
    for (const auto& z : r.zooms)
      po.zooms.push_back({"at " + where_text(z.data(), 2), z[0] - z[2], z[0] + z[2], z[1] - z[2], z[1] + z[2]});
    write_png(m.mesh2, per_cell.valid, out, po);
  } else {
    Picture3Options po;
    po.width = r.width;
    po.height = r.height;
    po.title = title;
    default_cut(m.mesh3, po.cut_point, po.cut_normal);
    if (r.cut) {
      po.cut_point = Eigen::Vector3d((*r.cut)[0], (*r.cut)[1], (*r.cut)[2]);
      po.cut_normal = Eigen::Vector3d((*r.cut)[3], (*r.cut)[4], (*r.cut)[5]);
      if (!(po.cut_normal.norm() > 0)) throw InputError("--cut: the plane's normal is zero");
    }
    if (r.view) po.view = Eigen::Vector3d((*r.view)[0], (*r.view)[1], (*r.view)[2]);
    if (!(po.view.norm() > 0)) throw InputError("--view: the direction is zero");
    Eigen::Vector3d c;
    double radius = 0, sj = 0, ratio = 0;
    if (worst_cell<3>(m.mesh3, per_cell, c, radius, sj, ratio)) {
      po.focus = c;
      po.focus_radius = std::max(4 * radius, 1e-12);
      worst_label = "worst cell, scaled Jacobian " + num(sj) + ", aspect ratio " + num(ratio) + " at " +
                    where_text(c.data(), 3);
      po.focus_label = worst_label;
      if (!r.cut) po.cut_point = c;  // the default plane moved through it
    }
    for (const auto& z : r.zooms) {
      const Eigen::Vector2d uv = cut_plane_uv(po.cut_normal, Eigen::Vector3d(z[0], z[1], z[2]));
      po.zooms.push_back({"at " + where_text(z.data(), 3), uv.x() - z[3], uv.x() + z[3], uv.y() - z[3], uv.y() + z[3]});
    }
    write_png(m.mesh3, per_cell.valid, out, po);
  }
  std::cout << "picture: " << out.string() << (worst_label.empty() ? "" : " (first zoom: " + worst_label + ")") << '\n';
  if (!report.ok()) {
    std::cerr << "plaf: error: " << r.mesh.string() << " is NOT valid: " << report.cells_invalid
              << " invalid cells (drawn red)\n";
    return 2;
  }
  return 0;
}

}  // namespace plaf
