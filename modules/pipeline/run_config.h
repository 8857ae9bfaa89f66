// SPDX-License-Identifier: MIT
// The typed run configuration: the core keys (name, order, extrude, limits, validity, output) and
// one planned stage per stage kind. Parsed strictly (config.h): an unknown key, a wrong type or an
// out-of-range value is an error naming the file, line and key. Stage sections carry `type:`; the
// chosen type's plugin parses the section (modules/pipeline/stages.h), so only its keys are
// accepted there. The metric section's `intersect:` lists further metric sections, each with its
// own type and keys; the run's metric is their intersection (IntersectedMetricField, metric.h).
//
// Every key, with its type, default, range or choices and the types that read it: `plaf keys`
// (docs/config.md, generated from the parsers; one line per key in apps/key_notes.cpp).
//
// An extruded section (`extrude:` on a geometry of type airfoils) is a 3D run whose geometry,
// metric and surface curves are the 2D section's (2D keys): the front is their ruled band between
// the symmetry planes z = 0 and z = span (modules/mesh/extrude_front.h), the metric theirs extruded
// along z (modules/metric/extruded_metric.h); layers and fill are the 3D stages, and the layer
// table's heights are measured at the station nearest mid-span. The size limits (`limits:`,
// modules/pipeline/budget.h) are checked by each stage against its predicted element count before
// it meshes. The 3D picture's cut and view: modules/io/picture3d.h.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace plaf {
inline namespace pipeline {

template <int Dim>
struct RunState;
class StageReport;

// A stage chosen by its section's `type:` and configured by its plugin (stages.h); run2/run3 is
// set for the run's dimension. Type "none" (the section is absent) does nothing.
struct PlannedStage {
  std::string type = "none";
  std::string where;    // "file:line:col: section.type", for messages
  std::string section;  // "file:line:col: section"
  std::function<void(RunState<2>&, StageReport&)> run2;
  std::function<void(RunState<3>&, StageReport&)> run3;
  bool enabled() const { return type != "none"; }
};

struct ValidityParams {
  double rel_tol = 0.01;
  int max_depth = 12;
};

struct OutputParams {
  std::filesystem::path dir = "out";
  std::vector<std::string> formats = {"msh", "vtu", "report", "png"};
  // The MSH files' encoding (`output.msh`): "ascii", "binary", or "auto": binary above
  // kBinaryNodes nodes, where ASCII files grow to hundreds of MB and are slow to write and read.
  std::string msh = "auto";
  // The .vtu files' encoding (`output.vtu`), with the same choices and the same rule for auto.
  std::string vtu = "auto";
  static constexpr std::size_t kBinaryNodes = 100000;
  int picture_width = 1600;
  int picture_height = 1200;
  int histogram_bins = 12;
  bool uniform_order = true;
  bool split_quads = false;
  struct Zoom {
    std::string label;
    std::array<double, 4> box;  // x_min, x_max, y_min, y_max
  };
  std::vector<Zoom> zooms;
  // 3D pictures (modules/io/picture3d.h): the cut plane (has_cut false: its default) and the
  // shaded view's direction.
  bool has_cut = false;
  std::array<double, 3> cut_point{0, 0, 0}, cut_normal{0, 0, 1};
  // More cuts (`output.cuts`), each a picture of its own, NAME.cut<k>.png (k from 1): its plane,
  // and with a radius a zoom panel of that half-width around the point (marked on the shaded
  // view), e.g. stations across a trailing edge.
  struct Cut {
    std::array<double, 3> point{0, 0, 0}, normal{0, 0, 1};
    double radius = 0;  // 0: no zoom panel
    std::string label;
  };
  std::vector<Cut> cuts;
  std::array<double, 3> view{-1, -0.6, -0.8};
  // A failed run (exit 2) writes its report and picture to DIR/NAME.failed/; its mesh too only
  // with this (the CLI's --keep-invalid, not a config key).
  bool keep_invalid = false;
  bool wants(const std::string& f) const;
};

struct ExtrudeParams {
  double span = 1.0;
  int rows = 2;
  double hz = 0;  // <= 0: the section metric's largest size (modules/metric/extruded_metric.h)
  // The z of the row station nearest mid-span (mid-span when rows is even).
  double probe_z() const { return span * static_cast<double>(rows / 2) / rows; }
};

struct LimitParams {
  double surface_elements = 2e6;
  double cells = 2e7;
  double nodes = 6e7;
};
LimitParams default_limits(int dim);

struct RunConfig {
  std::string name;
  std::filesystem::path file;
  int order = 3;
  int dim = 2;  // 3 for the 3D geometry types and extruded sections
  // A 2D section extruded into a 3D run (geometry, metric and surface stages 2D; the rest 3D).
  std::optional<ExtrudeParams> extrude;
  PlannedStage geometry;  // type: its section's `type:`
  PlannedStage metric;    // type: its section's `type:` (default uniform)
  PlannedStage surface;   // type: annulus | curves (2D, by the geometry), remesh (3D)
  PlannedStage layers;
  // layers.max as the config gives it (-1: not given, the layers' plugin default), so the 3D
  // surface stage can check the layers' budget before it triangulates (budget.h).
  int layers_max = -1;
  PlannedStage fill;
  ValidityParams validity;
  OutputParams output;
  LimitParams limits;
};

// Reads and validates a run configuration (InputError for a missing file, ConfigError otherwise).
RunConfig load_run_config(const std::filesystem::path& path);
RunConfig parse_run_config(const std::string& yaml_text, const std::string& name);

}  // namespace pipeline
}  // namespace plaf
