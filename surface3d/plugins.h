// SPDX-License-Identifier: MIT
// The 3D surface stages' plugins (modules/pipeline/stages.h), registered by
// register_surface3d_plugins(); each parses its own section:
//   geometry:               3D surfaces (the run is 3D)
//     type: sphere          center: [x, y, z] (default origin), radius: <>0> (default 1)
//     type: ellipsoid       center, semi_axes: [a, b, c] along x, y, z   default: [1.5, 1.2, 1]
//     type: box             lo: [x, y, z], hi: [x, y, z]          default: [-1,-1,-1], [1,1,1]
//     type: wing            a straight wing along +z from z = 0 to span (analytic.h)
//       file: <path>        airfoil section (Selig or Lednicer; data:REL in the data root), or
//       naca: "0012"        a generated NACA section (modules/pipeline/naca_config.h); one of them
//       chord: <>0>         default: 1        span: <>0>          default: 1
//       root: flat|rounded|symmetry   the end at z = 0            default: symmetry
//       tip: flat|rounded|symmetry    the end at z = span         default: flat
//       corner_angle_deg: <(0, 180)>  section corners             default: 30
//     type: surface_file    a triangulated or Plot3D surface (read_surface.h), validated
//                           (validate.h), its features detected (features.h); its own reference
//       file: <path>        .stl .obj .off .ply .fmt .p3d, or data:REL  (required)
//       reference: smooth|facets  what nodes are projected onto: smooth, cubic patches through the
//                           vertices with the feature curves kept sharp (smooth_reference.h), or
//                           the flat facets themselves (discrete_reference.h)   default: facets
//                           (smooth is not yet the default: on the pyHyp BWB its surface stage
//                           takes 737 s and folds 44 triangles)
//       weld_rel: <0..0.1>  merge points closer than this x bbox diagonal   default: 1e-9
//       symmetry_planes:    open boundaries allowed on these planes, tagged symmetry:
//         - normal: [nx, ny, nz]   (required)   offset: <d>   (the plane normal . x = d, default 0)
//       self_intersections: repair|check|skip  repair: folded sliver caps behind intersecting
//                         pairs, or back to back with the surface all around, get their long
//                         edge flipped (repair lines), then check;
//                         check: any pair is an error; skip: not tested    default: repair
//       inner_components: drop|error  bodies nested inside another (the flow never meets them):
//                         dropped with a repair line, or an error     default: drop
//   surface:                the `remesh` surface stage: features, remeshing (features.h, remesh.h),
//                           order-Q nodes on the reference, every triangle certified (high_order.h)
//     ridge_angle_deg: <0..180>   dihedral deviation of a ridge   default: 30
//     corner_defect_deg: <0..360> angle defect of a cone corner   default: 60
//     curve_turn_deg: <0..180>    turn of a feature curve making a corner   default: 45
//     remesh: <bool>        remesh to the metric                  default: true
//     iterations: <1..100>  remeshing rounds                      default: 8
//     curvature_factor: <0..100>  sizes at most this x radius of curvature (0: off), and at most
//                           the size whose order-Q chord error is half of fidelity_tol
//                           (curvature_metric.h, ChordCap)   default: 0
//     curvature_h_min: <>0, < the metric's size>  the smallest size curvature asks for   default: the metric's size / 20
//     gradation: <0 or >1> how fast curvature sizes may grow between neighbours (graded_metric.h:
//                           beta; sizes change by at most 1 + ln beta per unit edge); 0: off   default: 1.5
//     min_scaled_jacobian: <0..0.9>  a curved triangle below it has its high-order nodes pulled
//                           toward its flat triangle until it reaches it (high_order.h)   default: 0.1
//     max_triangles: <n>    give up (an error) beyond this many triangles   default: 20000000
//     fidelity_tol: <>0>    the run fails when the surface's two-sided distance to the body
//                           (fidelity.h) exceeds this x the body's bounding-box diagonal   default: 1e-3
//     fidelity_rounds: <0..10>  while over fidelity_tol, remesh at finer sizes around the samples
//                           farther than half of it, at most this many times (plugins.cpp)   default: 3
// An analytic body gives its exact reference at the geometry stage and its initial
// triangulation at the surface stage, at 1.5 times the metric's largest size there. The surface
// follows the metric's sizes; a wall_power_law metric's sizes along the wall, its size normal to
// the wall being the layers' (RunState<3>::surface_sizes, modules/metric/wall_metric_3d.h).
// A folded or invalid surface fails the run (exit 2, the mesh written for inspection).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "modules/io/naca_section.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/run_config.h"

namespace plaf {

struct SymmetryPlaneParams {
  std::array<double, 3> normal = {0, 0, 1};
  double offset = 0;
};

// The 3D geometries' keys (only the chosen type's are read).
struct Geometry3Params {
  std::array<double, 3> center = {0, 0, 0};
  double radius = 1;
  std::array<double, 3> semi_axes = {1.5, 1.2, 1.0};
  std::array<double, 3> lo = {-1, -1, -1}, hi = {1, 1, 1};
  std::string file;  // wing section or surface file
  std::optional<NacaSection> naca;  // or a generated wing section
  double chord = 1, span = 1;
  std::string root = "symmetry", tip = "flat";
  double corner_angle_deg = 30;
  double weld_rel = 1e-9;
  std::vector<SymmetryPlaneParams> symmetry_planes;
  bool check_self_intersections = true;
  bool repair_folded_caps = true;
  bool drop_inner_components = true;
  bool smooth_reference = false;  // surface_file: smooth patches, else the flat facets
};

struct SurfaceParams {
  double ridge_angle_deg = 30;
  double corner_defect_deg = 60;
  double curve_turn_deg = 45;
  bool remesh = true;
  int iterations = 8;
  double curvature_factor = 0;
  double curvature_h_min = 0;  // 0: the metric's smallest size / 20
  std::string curvature_h_min_where;  // "file:line:col: surface.curvature_h_min", for the check
  int max_triangles = 20000000;
  double fidelity_tol = 1e-3;
  int fidelity_rounds = 3;
  double gradation = 1.5;  // beta of graded_metric.h; 0: off (applies to curvature sizes)
  double min_scaled_jacobian = 0.1;  // curved triangles below it are straightened toward flat
};

// The keys of a 3D geometry section of type `type` (ConfigError naming the key).
Geometry3Params parse_geometry3_params(const ConfigNode& geometry, const std::string& type);
// The keys of the surface section (the curvature size is checked against the metric when the
// stage runs, before anything is written).
SurfaceParams parse_surface_params(const ConfigNode& surface);

void register_surface3d_plugins();

}  // namespace plaf
