// SPDX-License-Identifier: MIT
#include "modules/io/picture.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "modules/io/atomic_file.h"
#include "modules/io/picture_canvas.h"
#include "modules/base/error.h"

namespace plaf {
inline namespace io {

namespace {

// Point of cell `c` at reference xi.
Eigen::Vector2d map_point(const HybridMesh<2>& mesh, const LagrangeElement& e, const NodeId* c, const double* xi,
                          double* phi) {
  e.eval(xi, phi);
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int k = 0; k < e.size(); ++k) x += phi[k] * mesh.nodes[c[k]];
  return x;
}

// Trace the cell outline (curved edges, in order) as a closed cairo path.
void outline(cairo_t* cr, const View& v, const HybridMesh<2>& mesh, const CellBlock& b, std::size_t i, double* phi) {
  const LagrangeElement& e = lagrange_element(b.type, b.order);
  const NodeId* c = b.cell(i);
  const int nv = num_vertices(b.type);
  const int samples = b.order == 1 ? 1 : 12;
  bool first = true;
  for (int k = 0; k < nv; ++k) {
    const auto a = e.ref_node(k), z = e.ref_node((k + 1) % nv);
    for (int s = 0; s < samples; ++s) {
      const double t = static_cast<double>(s) / samples;
      const double xi[3] = {a[0] + t * (z[0] - a[0]), a[1] + t * (z[1] - a[1]), 0};
      const Eigen::Vector2d x = map_point(mesh, e, c, xi, phi);
      if (first)
        cairo_move_to(cr, v.px(x[0]), v.py(x[1]));
      else
        cairo_line_to(cr, v.px(x[0]), v.py(x[1]));
      first = false;
    }
  }
  cairo_close_path(cr);
}

void draw_mesh(cairo_t* cr, const View& v, const HybridMesh<2>& mesh, const std::vector<std::uint8_t>& valid,
               double line_width) {
  double phi[64];
  std::size_t index = 0;
  for (const CellBlock& b : mesh.cells)
    for (std::size_t i = 0; i < b.size(); ++i, ++index) {
      outline(cr, v, mesh, b, i, phi);
      const bool ok = valid.empty() || valid[index];
      fill_cell(cr, ok, ok && is_curved(mesh, b, i), line_width);
    }
  // Boundary facets, thicker, one colour per kind.
  for (const CellBlock& b : mesh.boundary) {
    const LagrangeElement& e = lagrange_element(b.type, b.order);
    const BoundaryKind kind = b.tag >= 0 ? mesh.tags[b.tag].kind : BoundaryKind::Named;
    switch (kind) {
      case BoundaryKind::Wall:
        cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
        break;
      case BoundaryKind::Farfield:
        cairo_set_source_rgb(cr, 0.1, 0.3, 0.8);
        break;
      case BoundaryKind::Symmetry:
        cairo_set_source_rgb(cr, 0.1, 0.6, 0.2);
        break;
      case BoundaryKind::Named:
        cairo_set_source_rgb(cr, 0.5, 0.2, 0.6);
        break;
    }
    cairo_set_line_width(cr, 2.5 * line_width);
    for (std::size_t i = 0; i < b.size(); ++i) {
      const NodeId* c = b.cell(i);
      for (int s = 0; s <= 12; ++s) {
        const double xi[3] = {s / 12.0, 0, 0};
        const Eigen::Vector2d x = map_point(mesh, e, c, xi, phi);
        if (s == 0)
          cairo_move_to(cr, v.px(x[0]), v.py(x[1]));
        else
          cairo_line_to(cr, v.px(x[0]), v.py(x[1]));
      }
      cairo_stroke(cr);
      // A surface mesh alone (no cells): show its nodes, linear ones larger than high-order ones.
      if (mesh.cells.empty())
        for (int k = 0; k < b.nodes_per_cell(); ++k) {
          const Eigen::Vector2d& x = mesh.nodes[c[k]];
          cairo_arc(cr, v.px(x[0]), v.py(x[1]), (k < 2 ? 3.0 : 1.8) * line_width, 0, 2 * M_PI);
          cairo_fill(cr);
        }
    }
  }
}

}  // namespace

void write_png(const HybridMesh<2>& mesh, const std::vector<std::uint8_t>& valid, const std::filesystem::path& path,
               const PictureOptions& options) {
  if (!valid.empty() && valid.size() != mesh.num_cells())
    throw InputError(path.string() + ": " + std::to_string(valid.size()) + " validity flags for " +
                     std::to_string(mesh.num_cells()) + " cells");
  double x_min = std::numeric_limits<double>::infinity(), y_min = x_min, x_max = -x_min, y_max = -x_min;
  for (const auto& p : mesh.nodes) {
    x_min = std::min(x_min, p[0]);
    x_max = std::max(x_max, p[0]);
    y_min = std::min(y_min, p[1]);
    y_max = std::max(y_max, p[1]);
  }
  if (mesh.nodes.empty()) x_min = y_min = 0, x_max = y_max = 1;
  const int w = options.width, h = options.height;
  const int panels = static_cast<int>(options.zooms.size());
  const int main_h = panels ? h * 2 / 3 : h;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  const double lw = std::max(0.4, w / 2400.0);
  draw_mesh(cr, fit(x_min, x_max, y_min, y_max, 0, 0, w, main_h), mesh, valid, lw);
  zoom_panels(cr, options.zooms, w, h, main_h, [&](const View& v) { draw_mesh(cr, v, mesh, valid, lw); });
  draw_title(cr, options.title);
  finish_png(cr, surface, path);
}

}  // namespace io
}  // namespace plaf
