// SPDX-License-Identifier: MIT
// What the 2D and 3D pictures (picture.h, picture3d.h) share: the model-to-pixel view of a panel,
// and the PNG encoding of a cairo surface.
#pragma once

#include <cairo.h>

#include <algorithm>
#include <string>

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

}  // namespace io
}  // namespace plaf
