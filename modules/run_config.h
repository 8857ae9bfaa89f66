// SPDX-License-Identifier: MIT
// The typed run configuration: every YAML key plaf understands, with its default, in one place.
// Parsed strictly (config.h): an unknown key, a wrong type or an out-of-range value is an error
// naming the file, line and key. Plugin sections carry `type:`; only the chosen type's keys are
// accepted in that section.
//
//   name: <string>          output base name                      default: the config file's stem
//   order: <1..4>           geometry order Q of curved cells      default: 3
//   geometry:               what to mesh
//     type: annulus         curved quads (or triangles) of an annulus sector, from the exact
//                           polar map; sizes from the metric (element counts = rounded metric lengths)
//     r_inner: <>0>         inner radius                          default: 1
//     r_outer: <>r_inner>   outer radius                          default: 2
//     angle_deg: <0..360]   sector angle (360 = full annulus)     default: 360
//     cells: quad|tri       quads, or each quad split in two tris default: quad
//   metric:
//     type: uniform         one metric everywhere
//     h: <>0>               isotropic size                        default: 0.25
//     sizes: [h1, h2]       anisotropic sizes (instead of h)      default: none
//     angle_deg: <deg>      direction of h1 from the x axis       default: 0
//   validity:
//     rel_tol: <0..1>       Bezier bounds refined to this         default: 0.01
//     max_depth: <1..20>    subdivision depth limit               default: 12
//   output:
//     dir: <path>           output folder (plaf run --out wins)   default: out
//     formats: [msh, vtu, report, png]                            default: all four
//     picture_width: <px>   PNG width                             default: 1600
//     picture_height: <px>  PNG height                            default: 1200
//     histogram_bins: <n>   bins of the metric edge-length histogram  default: 12
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace plaf {

struct AnnulusParams {
  double r_inner = 1.0;
  double r_outer = 2.0;
  double angle_deg = 360.0;
  bool triangles = false;
};

struct GeometryParams {
  std::string type = "annulus";
  std::string where;  // "file:line:col: geometry.type" for plugin errors
  AnnulusParams annulus;
};

struct UniformMetricParams {
  double h = 0.25;
  std::vector<double> sizes;  // empty: isotropic h
  double angle_deg = 0.0;
};

struct MetricParams {
  std::string type = "uniform";
  std::string where;
  UniformMetricParams uniform;
};

struct ValidityParams {
  double rel_tol = 0.01;
  int max_depth = 12;
};

struct OutputParams {
  std::filesystem::path dir = "out";
  std::vector<std::string> formats = {"msh", "vtu", "report", "png"};
  int picture_width = 1600;
  int picture_height = 1200;
  int histogram_bins = 12;
  bool wants(const std::string& f) const;
};

struct RunConfig {
  std::string name;
  std::filesystem::path file;
  int order = 3;
  GeometryParams geometry;
  MetricParams metric;
  ValidityParams validity;
  OutputParams output;
};

// Reads and validates a run configuration (InputError for a missing file, ConfigError otherwise).
RunConfig load_run_config(const std::filesystem::path& path);
RunConfig parse_run_config(const std::string& yaml_text, const std::string& name);

}  // namespace plaf
