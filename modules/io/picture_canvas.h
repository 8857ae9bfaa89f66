// SPDX-License-Identifier: MIT
// What the 2D and 3D pictures (picture.h, picture3d.h) share: the model-to-pixel view of a panel,
// and the PNG encoding of a cairo surface.
#pragma once

#include <cairo.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/io/atomic_file.h"
#include "modules/io/picture.h"

namespace plaf {
inline namespace io {

// Model (x, y) -> pixel: ox + (x - x_min) * scale, oy + height - (y - y_min) * scale.
struct View {
  double x_min, y_min, scale, ox, oy, height;
  double px(double x) const { return ox + (x - x_min) * scale; }
  double py(double y) const { return oy + height - (y - y_min) * scale; }
};

// The view that fits the box [x_min, x_max] x [y_min, y_max] centred in the w x h panel at
// (ox, oy), with a 4 % margin.
inline View fit(double x_min, double x_max, double y_min, double y_max, double ox, double oy, double w, double h) {
  const double margin = 0.04;
  const double dx = std::max(x_max - x_min, 1e-300), dy = std::max(y_max - y_min, 1e-300);
  const double scale = std::min(w / dx, h / dy) * (1 - 2 * margin);
  View v{x_min, y_min, scale, 0, 0, h};
  v.ox = ox + 0.5 * (w - dx * scale);
  v.oy = oy - 0.5 * (h - dy * scale);
  return v;
}

// The PNG bytes of a surface, or an empty string when cairo fails (no exception may cross cairo's
// C frames: the chunks are collected in memory).
inline std::string png_bytes(cairo_surface_t* surface) {
  std::string png;
  cairo_surface_flush(surface);
  auto chunk = [](void* closure, const unsigned char* data, unsigned int length) {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
  };
  if (cairo_surface_write_to_png_stream(surface, chunk, &png) != CAIRO_STATUS_SUCCESS) return {};
  return png;
}

// Fills the current path in the cell colours of the pictures (invalid red, curved light orange,
// straight light blue) and strokes its outline dark, line width lw.
inline void fill_cell(cairo_t* cr, bool valid, bool curved, double lw) {
  if (!valid)
    cairo_set_source_rgb(cr, 0.95, 0.1, 0.1);
  else if (curved)
    cairo_set_source_rgb(cr, 1.0, 0.85, 0.6);
  else
    cairo_set_source_rgb(cr, 0.78, 0.87, 0.97);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.15, 0.15, 0.2);
  cairo_set_line_width(cr, lw);
  cairo_stroke(cr);
}

// The zoom panels below the main view (rows main_h .. h of a w-wide picture), each cleared,
// drawn by draw(view of its box) inside its clip, framed and labelled.
inline void zoom_panels(cairo_t* cr, const std::vector<ZoomBox>& zooms, int w, int h, int main_h,
                        const std::function<void(const View&)>& draw) {
  const int panels = static_cast<int>(zooms.size());
  for (int k = 0; k < panels; ++k) {
    const ZoomBox& z = zooms[static_cast<std::size_t>(k)];
    const double pw = static_cast<double>(w) / panels, ph = h - main_h;
    cairo_save(cr);
    cairo_rectangle(cr, k * pw, main_h, pw, ph);
    cairo_clip(cr);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    draw(fit(z.x_min, z.x_max, z.y_min, z.y_max, k * pw, main_h, pw, ph));
    cairo_restore(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, k * pw + 0.5, main_h + 0.5, pw - 1, ph - 1);
    cairo_stroke(cr);
    cairo_move_to(cr, k * pw + 8, main_h + 20);
    cairo_set_font_size(cr, 16);
    cairo_show_text(cr, z.label.c_str());
  }
}

// The title at the top left (nothing for an empty one).
inline void draw_title(cairo_t* cr, const std::string& title) {
  if (title.empty()) return;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_font_size(cr, 18);
  cairo_move_to(cr, 10, 24);
  cairo_show_text(cr, title.c_str());
}

// Encodes the picture, releases cairo's objects, and writes the file atomically (plaf::Error when
// the encoding fails; the file is then not written).
inline void finish_png(cairo_t* cr, cairo_surface_t* surface, const std::filesystem::path& path) {
  const std::string png = png_bytes(surface);
  cairo_destroy(cr);
  cairo_surface_destroy(surface);
  if (png.empty()) throw Error(path.string() + ": cannot encode the PNG picture");
  AtomicFile file(path);
  file.write(png);
  file.commit();
}

}  // namespace io
}  // namespace plaf
