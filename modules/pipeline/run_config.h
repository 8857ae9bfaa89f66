// SPDX-License-Identifier: MIT
// The typed run configuration: the core keys, with their defaults, and one planned stage per
// stage kind. Parsed strictly (config.h): an unknown key, a wrong type or an out-of-range value is
// an error naming the file, line and key. Stage sections carry `type:`; the chosen type's plugin
// parses the section (its keys are documented beside its options, named below), so only its keys
// are accepted there.
//
//   name: <string>          output base name                      default: the config file's stem
//   order: <1..4>           geometry order Q of curved cells      default: 3
//   geometry:               what to mesh; `type:` chooses the plugin (modules/pipeline/stages.h),
//     type: annulus | airfoils    whose keys are documented beside its options: AnnulusParams
//                           (modules/mesh/annulus.h), AirfoilsParams (modules/geometry/geometry2d.h);
//     type: sphere | ellipsoid | box | wing | surface_file   3D: Geometry3Params (surface3d/plugins.h)
//   surface:                3D only: features and remeshing, SurfaceParams (surface3d/plugins.h)
//   metric:                 the metric field; `type:` chooses the plugin, its keys beside its options:
//     type: uniform         UniformMetricParams (modules/metric/metric_fields.h), 2D and 3D
//     type: wall_power_law  WallLawParams (modules/metric/wall_metric.h), 2D and 3D (3D:
//                           modules/metric/wall_metric_3d.h, without curvature_factor and h_corner)
//     type: background      BackgroundParams (modules/metric/metric_fields.h), 2D and 3D (a
//                           background mesh of the run's dimension, modules/metric/background_metric.h)
//     intersect: [{type: ...}, ...]   further metric sections, each with its own type and keys;
//                           the run's metric is their intersection with this one (the smallest
//                           size any asks for along every direction: IntersectedMetricField,
//                           metric.h), e.g. a wall law with a refinement band on a background mesh
//   extrude:                a 2D section (geometry type airfoils) extruded between the symmetry
//                           planes z = 0 and z = span: the run is 3D (modules/mesh/extrude_front.h).
//                           Geometry, metric and the surface's curves are the 2D section's (2D
//                           keys); the front is their ruled band, the metric theirs extruded along z
//                           (modules/metric/extruded_metric.h); layers and fill are the 3D stages.
//                           The layer table's heights are measured at the station nearest mid-span.
//     span: <>0>            the planes' distance                  (required)
//     rows: <1..1000>       rows of order-Q triangles along z     default: 2 (even: a mid-span station)
//     hz: <>0>              the metric's size along z   default: the section metric's largest size
//                           at (x, y) (its size along the wall), so both are isotropic alike
//   layers:                 prismatic layers grown from the walls; absent: none. Keys of the
//     type: extrude         chosen type, parsed by its plugin: layers/plugins.h
//   fill:                   the fill of the domain between the layers' outer front (or the surface
//     type: advancing_front mesh) and the farfield; absent: none. Keys: volume/plugins.h
//   limits:                 the size budget (modules/pipeline/budget.h): each stage predicts its
//                           element count from the metric before meshing and stops with a ConfigError
//                           naming the key to raise when it would exceed one of these. Defaults fit
//                           a 24 GB, 2-core machine (a run of a few GB and minutes at most):
//     surface_elements: <>0> curve elements (2D) / surface triangles (3D)  default: 2e6 / 5e5
//     cells: <>0>           cells of the mesh (layers and fill)      default: 2e7 / 1e7
//     nodes: <>0>           nodes of the mesh, high-order ones too   default: 6e7 / 3e7
//   validity:
//     rel_tol: <0..1>       Bezier bounds refined to this         default: 0.01
//     max_depth: <1..20>    subdivision depth limit               default: 12
//   output:
//     dir: <path>           output folder (plaf run --out wins)   default: out
//     formats: [msh, vtu, report, png]                            default: all four
//     (2D only: uniform_order, split_quads)
//     picture_width: <px>   PNG width                             default: 1600
//     picture_height: <px>  PNG height                            default: 1200
//     histogram_bins: <n>   bins of the metric edge-length histogram  default: 12
//     uniform_order: <bool> the fill's triangles written at order Q (straight sided, edges shared
//                           with the layers' cells), so the mesh has one order   default: true
//     split_quads: <bool>   each layer quadrilateral split into two triangles in reference space
//                           (the paper's Fig. 12), along its shorter diagonal   default: false
//     zooms:                inset panels of the picture, a list of maps:
//       - label: <text>
//         box: [x_min, x_max, y_min, y_max]   (3D: in the cut plane's (u, v), picture3d.h)
//     (3D only:)
//     cut:                  the plane of the picture's cut       default: the first symmetry
//       point: [x, y, z]      plane, else the bounding box's mid-plane across its shortest side
//       normal: [x, y, z]
//     view: [x, y, z]       the shaded view of the outer front looks along this
//                                                                 default: [-1, -0.6, -0.8]
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
