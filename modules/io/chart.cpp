// SPDX-License-Identifier: MIT
#include "modules/io/chart.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "modules/base/error.h"
#include "modules/io/picture_canvas.h"

namespace plaf {
inline namespace io {

namespace {

constexpr double palette[10][3] = {{0.12, 0.47, 0.71}, {1.00, 0.50, 0.05}, {0.17, 0.63, 0.17}, {0.84, 0.15, 0.16},
                                   {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50},
                                   {0.74, 0.74, 0.13}, {0.09, 0.75, 0.81}};

// One axis: its range (in log10 for a log axis) and its tick positions.
struct Axis {
  bool log = false;
  double lo = 0, hi = 1;
  std::vector<double> ticks;  // in axis units (log10 for a log axis)

  double unit(double v) const { return log ? std::log10(v) : v; }
  bool drawable(double v) const { return std::isfinite(v) && (!log || v > 0); }
};

// A step of 1, 2 or 5 times a power of ten giving at most about 8 ticks over [lo, hi].
double nice_step(double span) {
  const double raw = span / 8;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

Axis make_axis(const std::vector<double>& values, bool log) {
  Axis a;
  a.log = log;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (a.drawable(v)) {
      lo = std::min(lo, a.unit(v));
      hi = std::max(hi, a.unit(v));
    }
  if (!(lo <= hi)) return a;  // nothing drawable: the caller refuses the chart
  if (log) {
    lo = std::floor(lo);
    hi = std::max(std::ceil(hi), lo + 1);
    for (double t = lo; t <= hi + 1e-9; t += 1) a.ticks.push_back(t);
  } else {
    if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {  // one value: a unit span around it
      lo -= 0.5 * std::max(1.0, std::abs(lo));
      hi += 0.5 * std::max(1.0, std::abs(hi));
    }
    const double step = nice_step(hi - lo);
    lo = std::floor(lo / step + 1e-9) * step;
    hi = std::ceil(hi / step - 1e-9) * step;
    for (double t = lo; t <= hi + 0.5 * step; t += step) a.ticks.push_back(std::abs(t) < 1e-12 * step ? 0 : t);
  }
  a.lo = lo;
  a.hi = hi;
  return a;
}

std::string tick_text(const Axis& a, double t) {
  char buf[32];
  if (a.log)
    std::snprintf(buf, sizeof buf, "1e%d", static_cast<int>(std::lround(t)));
  else
    std::snprintf(buf, sizeof buf, "%g", t);
  return buf;
}

}  // namespace

void write_chart_png(const std::vector<ChartSeries>& series, const std::filesystem::path& path,
                     const ChartOptions& o) {
  std::vector<double> xs, ys;
  for (const ChartSeries& s : series) {
    if (s.x.size() != s.y.size()) throw Error(path.string() + ": chart series '" + s.label + "' has unequal x and y");
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (std::isfinite(s.x[k]) && std::isfinite(s.y[k]) && (!o.log_x || s.x[k] > 0) && (!o.log_y || s.y[k] > 0)) {
        xs.push_back(s.x[k]);
        ys.push_back(s.y[k]);
      }
  }
  if (xs.empty()) throw Error(path.string() + ": the chart has no point to draw");
  const Axis ax = make_axis(xs, o.log_x), ay = make_axis(ys, o.log_y);

  const int w = o.width, h = o.height;
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  draw_title(cr, o.title);
  // The plot area, leaving room for tick labels, axis labels and the legend on the right.
  const double left = 90, right = w - 260.0, top = 50, bottom = h - 70.0;
  auto px = [&](double x) { return left + (ax.unit(x) - ax.lo) / (ax.hi - ax.lo) * (right - left); };
  auto py = [&](double y) { return bottom - (ay.unit(y) - ay.lo) / (ay.hi - ay.lo) * (bottom - top); };
  // Grid and ticks.
  cairo_set_font_size(cr, 14);
  cairo_text_extents_t ext;
  // A grid line and its label per tick, x below the plot, y left of it.
  auto tick = [&](bool x_axis, double t) {
    const Axis& a = x_axis ? ax : ay;
    const double u = (t - a.lo) / (a.hi - a.lo);
    const double p = x_axis ? left + u * (right - left) : bottom - u * (bottom - top);
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_set_line_width(cr, 1);
    cairo_move_to(cr, x_axis ? p : left, x_axis ? top : p);
    cairo_line_to(cr, x_axis ? p : right, x_axis ? bottom : p);
    cairo_stroke(cr);
    const std::string s = tick_text(a, t);
    cairo_text_extents(cr, s.c_str(), &ext);
    cairo_set_source_rgb(cr, 0, 0, 0);
    if (x_axis)
      cairo_move_to(cr, p - ext.width / 2, bottom + 20);
    else
      cairo_move_to(cr, left - ext.width - 8, p + ext.height / 2);
    cairo_show_text(cr, s.c_str());
  };
  for (double t : ax.ticks) tick(true, t);
  for (double t : ay.ticks) tick(false, t);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.5);
  cairo_rectangle(cr, left, top, right - left, bottom - top);
  cairo_stroke(cr);
  // Axis labels.
  cairo_set_font_size(cr, 16);
  cairo_text_extents(cr, o.x_label.c_str(), &ext);
  cairo_move_to(cr, 0.5 * (left + right) - ext.width / 2, h - 20.0);
  cairo_show_text(cr, o.x_label.c_str());
  cairo_save(cr);
  cairo_text_extents(cr, o.y_label.c_str(), &ext);
  cairo_move_to(cr, 24, 0.5 * (top + bottom) + ext.width / 2);
  cairo_rotate(cr, -M_PI / 2);
  cairo_show_text(cr, o.y_label.c_str());
  cairo_restore(cr);
  // Series, clipped to the plot area; a point that cannot be drawn breaks the line.
  cairo_save(cr);
  cairo_rectangle(cr, left - 6, top - 6, right - left + 12, bottom - top + 12);
  cairo_clip(cr);
  // A series' pen: its colour, width and dashes (solid: dashes off).
  const double dash[] = {8, 5};
  auto pen_of = [&](const ChartSeries& s) {
    const double* c = palette[s.color % 10];
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_set_line_width(cr, 2.2);
    cairo_set_dash(cr, dash, s.dashed ? 2 : 0, 0);
  };
  for (const ChartSeries& s : series) {
    pen_of(s);
    bool pen = false;
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      const bool ok = ax.drawable(s.x[k]) && ay.drawable(s.y[k]);
      if (!ok) {
        pen = false;
        continue;
      }
      if (pen)
        cairo_line_to(cr, px(s.x[k]), py(s.y[k]));
      else
        cairo_move_to(cr, px(s.x[k]), py(s.y[k]));
      pen = true;
    }
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0);
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (ax.drawable(s.x[k]) && ay.drawable(s.y[k])) {
        if (s.dashed)
          cairo_rectangle(cr, px(s.x[k]) - 3.5, py(s.y[k]) - 3.5, 7, 7);
        else
          cairo_arc(cr, px(s.x[k]), py(s.y[k]), 3.5, 0, 2 * M_PI);
        cairo_fill(cr);
      }
  }
  cairo_restore(cr);
  // Legend.
  cairo_set_font_size(cr, 14);
  double ly = top + 10;
  for (const ChartSeries& s : series) {
    pen_of(s);
    cairo_move_to(cr, right + 15, ly);
    cairo_line_to(cr, right + 50, ly);
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, right + 58, ly + 5);
    cairo_show_text(cr, s.label.c_str());
    ly += 22;
  }
  finish_png(cr, surface, path);
}

void write_side_by_side_png(const std::vector<std::filesystem::path>& panels, const std::vector<std::string>& labels,
                            const std::string& title, const std::filesystem::path& path, int height) {
  std::vector<cairo_surface_t*> images;
  auto release = [&] {
    for (cairo_surface_t* s : images) cairo_surface_destroy(s);
  };
  for (const std::filesystem::path& p : panels) {
    cairo_surface_t* s = cairo_image_surface_create_from_png(p.c_str());
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
      cairo_surface_destroy(s);
      release();
      throw Error(p.string() + ": cannot read the PNG picture");
    }
    images.push_back(s);
  }
  const double label_h = 30, title_h = title.empty() ? 0 : 36;
  double panel_h = height;
  for (cairo_surface_t* s : images) panel_h = std::min(panel_h, static_cast<double>(cairo_image_surface_get_height(s)));
  std::vector<double> scales, widths;
  double total_w = 0;
  for (cairo_surface_t* s : images) {
    const double sc = panel_h / cairo_image_surface_get_height(s);
    scales.push_back(sc);
    widths.push_back(sc * cairo_image_surface_get_width(s));
    total_w += widths.back();
  }
  const int w = std::max(64, static_cast<int>(std::ceil(total_w))), h = static_cast<int>(std::ceil(panel_h + label_h + title_h));
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  draw_title(cr, title);
  double x = 0;
  for (std::size_t k = 0; k < images.size(); ++k) {
    cairo_save(cr);
    cairo_translate(cr, x, title_h + label_h);
    cairo_scale(cr, scales[k], scales[k]);
    cairo_set_source_surface(cr, images[k], 0, 0);
    cairo_paint(cr);
    cairo_restore(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, 18);
    cairo_move_to(cr, x + 10, title_h + label_h - 8);
    cairo_show_text(cr, k < labels.size() ? labels[k].c_str() : "");
    if (k > 0) {
      cairo_set_line_width(cr, 2);
      cairo_move_to(cr, x, title_h);
      cairo_line_to(cr, x, h);
      cairo_stroke(cr);
    }
    x += widths[k];
  }
  release();
  finish_png(cr, surface, path);
}

}  // namespace io
}  // namespace plaf
