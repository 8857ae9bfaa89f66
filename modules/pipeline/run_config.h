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
//   geometry:
//     type: airfoils        bodies from coordinate files (airfoil_io.h), splines with corners
//     bodies:               a list, one map per body:
//       - file: <path>      Selig or Lednicer file, relative to the config file   (required)
//         name: <word>      boundary tag of the body                  default: wall, wall_2, ...
//         corners: [[x, y], ...]  extra corners: the nearest contour points   default: none
//     corner_angle_deg: <0..180>  turning angle above which a point is a corner   default: 30
//     farfield:
//       shape: circle|rectangle                                   default: circle
//       radius: <>0>        circle radius                         default: 20
//       size: [w, h]        rectangle width and height            default: [40, 40]
//       center: [x, y]      default: the centre of the bodies' bounding box
//   geometry:               3D surfaces (surface3d/; the run is 3D): the surface mesh alone
//     type: sphere          center: [x, y, z] (default origin), radius: <>0> (default 1)
//     type: ellipsoid       center, semi_axes: [a, b, c] along x, y, z   default: [1.5, 1.2, 1]
//     type: box             lo: [x, y, z], hi: [x, y, z]          default: [-1,-1,-1], [1,1,1]
//     type: wing            a straight wing along +z from z = 0 to span (surface3d/analytic.h)
//       file: <path>        airfoil section (Selig or Lednicer)   (required)
//       chord: <>0>         default: 1        span: <>0>          default: 1
//       root: flat|rounded|symmetry   the end at z = 0            default: symmetry
//       tip: flat|rounded|symmetry    the end at z = span         default: flat
//       corner_angle_deg: <(0, 180)>  section corners             default: 30
//     type: surface_file    a triangulated or Plot3D surface (surface3d/read_surface.h)
//       file: <path>        .stl .obj .off .ply .fmt .p3d         (required)
//       weld_rel: <0..0.1>  merge points closer than this x bbox diagonal   default: 1e-9
//       symmetry_planes:    open boundaries allowed on these planes, tagged symmetry:
//         - normal: [nx, ny, nz]   (required)   offset: <d>   (the plane normal . x = d, default 0)
//       self_intersections: check|skip                            default: check
//       inner_components: error|drop  bodies nested in another    default: error
//   surface:                3D only: features, remeshing (surface3d/features.h, remesh.h)
//     ridge_angle_deg: <0..180>   dihedral deviation of a ridge   default: 30
//     corner_defect_deg: <0..360> angle defect of a cone corner   default: 60
//     curve_turn_deg: <0..180>    turn of a feature curve making a corner   default: 45
//     remesh: <bool>        remesh to the metric                  default: true
//     iterations: <1..100>  remeshing rounds                      default: 8
//     curvature_factor: <0..100>  sizes at most this x radius of curvature (0: off)   default: 0
//     curvature_h_min: <>0, < the metric's size>  the smallest size curvature asks for   default: the metric's size / 20
//     max_triangles: <n>    give up (an error) beyond this many triangles   default: 20000000
//   metric:
//     type: uniform         one metric everywhere
//     h: <>0>               isotropic size                        default: 0.25
//     sizes: [h1, h2]       anisotropic sizes (instead of h); 3D: [hx, hy, hz]   default: none
//     angle_deg: <deg>      direction of h1 from the x axis (2D)  default: 0
//   metric:
//     type: wall_power_law  boundary-layer metric of the paper's eq. (6) (wall_metric.h)
//     h0: <>0>              first layer height                    default: 0.005
//     growth: <>1>          layer growth factor g                 default: 1.2
//     law: linear|exponential   h_perp = h0 + (g-1) d, or h0 g^(d/delta)   default: linear
//     delta: <>0>           growth distance of the exponential law    default: h0
//     h_max: <>0>           isotropic size far from the walls     default: 1
//     h_wall_max: <>0>      largest size along a wall             default: 0.05
//     curvature_factor: <>0>  size along a wall = factor x radius of curvature   default: 0.25
//     h_corner: <>0>        size along a wall at a corner (grows by g away)   default: 0.01
//   metric:
//     type: background      metric at the nodes of a background mesh (background_metric.h)
//     file: <path>          Gmsh .msh with a tensor $NodeData view, or a libMeshb .mesh  (required)
//     sol: <path>           the .sol of a .mesh file              default: none
//     mean: log_euclidean|affine_invariant                        default: log_euclidean
//   layers:                 prismatic layers grown from the walls; absent: none. Keys of the
//     type: extrude         chosen type, parsed by its plugin: layers/plugins.h
//   fill:                   the fill of the domain between the layers' outer front (or the surface
//     type: advancing_front mesh) and the farfield; absent: none. Keys: volume/plugins.h
//   validity:
//     rel_tol: <0..1>       Bezier bounds refined to this         default: 0.01
//     max_depth: <1..20>    subdivision depth limit               default: 12
//   output:
//     dir: <path>           output folder (plaf run --out wins)   default: out
//     formats: [msh, vtu, report, png]                            default: all four (3D: no png)
//     (2D only: picture_width, picture_height, uniform_order, split_quads, zooms)
//     picture_width: <px>   PNG width                             default: 1600
//     picture_height: <px>  PNG height                            default: 1200
//     histogram_bins: <n>   bins of the metric edge-length histogram  default: 12
//     uniform_order: <bool> the fill's triangles written at order Q (straight sided, edges shared
//                           with the layers' cells), so the mesh has one order   default: true
//     split_quads: <bool>   each layer quadrilateral split into two triangles in reference space
//                           (the paper's Fig. 12), along its shorter diagonal   default: false
//     zooms:                inset panels of the picture, a list of maps:
//       - label: <text>
//         box: [x_min, x_max, y_min, y_max]
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace plaf {
inline namespace pipeline {

struct AnnulusParams {
  double r_inner = 1.0;
  double r_outer = 2.0;
  double angle_deg = 360.0;
  bool triangles = false;
};

struct BodyParams {
  std::string file;
  std::string name;
  std::vector<std::array<double, 2>> corners;
};

struct FarfieldParams {
  std::string shape = "circle";
  double radius = 20.0;
  std::array<double, 2> size = {40.0, 40.0};
  bool has_center = false;
  std::array<double, 2> center = {0.0, 0.0};
};

struct AirfoilsParams {
  std::vector<BodyParams> bodies;
  double corner_angle_deg = 30.0;
  FarfieldParams farfield;
};

struct SymmetryPlaneParams {
  std::array<double, 3> normal = {0, 0, 1};
  double offset = 0;
};

// The 3D geometries (only the chosen type's fields are read).
struct Surface3Params {
  std::array<double, 3> center = {0, 0, 0};
  double radius = 1;
  std::array<double, 3> semi_axes = {1.5, 1.2, 1.0};
  std::array<double, 3> lo = {-1, -1, -1}, hi = {1, 1, 1};
  std::string file;  // wing section or surface file
  double chord = 1, span = 1;
  std::string root = "symmetry", tip = "flat";
  double corner_angle_deg = 30;
  double weld_rel = 1e-9;
  std::vector<SymmetryPlaneParams> symmetry_planes;
  bool check_self_intersections = true;
  bool drop_inner_components = false;
};

struct GeometryParams {
  std::string type = "annulus";
  std::string where;  // "file:line:col: geometry.type" for plugin errors
  AnnulusParams annulus;
  AirfoilsParams airfoils;
  Surface3Params surface3;
};

struct SurfaceParams {
  double ridge_angle_deg = 30;
  double corner_defect_deg = 60;
  double curve_turn_deg = 45;
  bool remesh = true;
  int iterations = 8;
  double curvature_factor = 0;
  double curvature_h_min = 0;  // 0: the metric's smallest size / 20
  int max_triangles = 20000000;
};

struct UniformMetricParams {
  double h = 0.25;
  std::vector<double> sizes;  // empty: isotropic h
  double angle_deg = 0.0;
};

struct WallLawParams {
  double h0 = 0.005;
  double growth = 1.2;
  bool exponential = false;
  double delta = 0.0;  // 0: h0
  double h_max = 1.0;
  double h_wall_max = 0.05;
  double curvature_factor = 0.25;
  double h_corner = 0.01;
};

struct BackgroundParams {
  std::string file;
  std::string sol;
  std::string mean = "log_euclidean";
};

struct MetricParams {
  std::string type = "uniform";
  std::string where;
  UniformMetricParams uniform;
  WallLawParams wall_law;
  BackgroundParams background;
};

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
  bool wants(const std::string& f) const;
};

struct RunConfig {
  std::string name;
  std::filesystem::path file;
  int order = 3;
  int dim = 2;  // 3 for the 3D geometry types
  GeometryParams geometry;
  SurfaceParams surface;
  MetricParams metric;
  std::string surface_type;  // the surface-mesh stage: annulus | curves (2D), remesh (3D)
  PlannedStage layers;
  PlannedStage fill;
  ValidityParams validity;
  OutputParams output;
};

// Reads and validates a run configuration (InputError for a missing file, ConfigError otherwise).
RunConfig load_run_config(const std::filesystem::path& path);
RunConfig parse_run_config(const std::string& yaml_text, const std::string& name);

}  // namespace pipeline
}  // namespace plaf
