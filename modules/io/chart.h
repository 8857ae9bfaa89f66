// SPDX-License-Identifier: MIT
// PNG line charts and picture panels (cairo), for reports that compare runs (the attenuation
// study, apps/study.h): series of (x, y) points as polylines with markers on linear or
// logarithmic axes with ticks, axis labels, a title and a legend; and PNG pictures placed side by
// side in one picture, each under its label.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace plaf {
inline namespace io {

struct ChartSeries {
  std::string label;
  std::vector<double> x, y;  // same length; a non-finite y (or x) breaks the line there
  int color = 0;             // index into the chart palette (10 colours, cycled)
  bool dashed = false;
};

struct ChartOptions {
  int width = 1200;
  int height = 800;
  std::string title, x_label, y_label;
  bool log_x = false;  // logarithmic axes take only positive values (others are left out)
  bool log_y = false;
};

// Writes the chart atomically; plaf::Error when no series has a drawable point or cairo fails.
void write_chart_png(const std::vector<ChartSeries>& series, const std::filesystem::path& path,
                     const ChartOptions& options);

// Places the PNG pictures `panels` side by side (scaled to a common height of at most
// `height` pixels), each under its label, under a title, and writes the result atomically.
// plaf::Error naming the file when a panel cannot be read.
void write_side_by_side_png(const std::vector<std::filesystem::path>& panels, const std::vector<std::string>& labels,
                            const std::string& title, const std::filesystem::path& path, int height = 900);

}  // namespace io
}  // namespace plaf
