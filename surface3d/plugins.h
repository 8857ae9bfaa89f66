// SPDX-License-Identifier: MIT
// The 3D surface stages' plugins (modules/pipeline/stages.h), registered by
// register_surface3d_plugins(); each parses its own section: the 3D geometries (sphere,
// ellipsoid, box, wing: analytic.h; surface_file: a triangulated or Plot3D surface, read_surface.h,
// validated, validate.h, its features detected, features.h, projected onto its facets,
// discrete_reference.h, or onto smooth patches, smooth_reference.h) and the `remesh` surface stage
// (features, remeshing, features.h and remesh.h; order-Q nodes on the reference, every triangle
// certified, high_order.h; curvature sizes, curvature_metric.h, graded, graded_metric.h; the
// fidelity loop, fidelity.h). Their keys, types, defaults and descriptions: `plaf keys geometry`
// and `plaf keys surface` (docs/config.md; the lines in apps/key_notes.cpp).
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
  bool repair_slivers = true;  // geometry.slivers: repair (validate.h, step 8) or keep
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
  // Rounds end once the surface is within fidelity_tol, so a body that meets it sooner is meshed
  // as with fewer. 3 left two bodies just over the tolerance: bench/cad_bodies.py's car at Q1,
  // 0.00212 -> 0.00138 -> 0.00117 -> 0.00118 and within it (0.00098) at round 4, and the published
  // Orion at Q3, 0.0058 -> 0.0032 -> 0.0026 -> 0.00108.
  int fidelity_rounds = 6;
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
