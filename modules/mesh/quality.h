// SPDX-License-Identifier: MIT
// The quality report of a mesh: per-type counts, certified validity (validity.h) and scaled
// Jacobian, aspect ratio, metric conformity of edges, conformity of the mesh, and stage timings.
//
// Aspect ratio of a cell: sigma_max / sigma_min of J W^-1 at the cell's centroid, where J is the
// mapping Jacobian and W maps the reference cell onto the regular cell of its type (equilateral
// triangle, unit square, regular tetrahedron, equilateral prism of unit side and unit height): 1
// for a regular cell, w/h for a w x h rectangle. For a prism, J W^-1 stretches the base by its
// in-plane shape and the axis by the height relative to the side, so a prism on an equilateral
// base of side s and height h has singular values s, s, h: aspect ratio s / h, 1e5 for a boundary
// layer prism whose height is 1e-5 of its base (a thin curved shell prism comes out at its base
// edge over its height, times its base triangle's own distortion).
// Metric conformity: every distinct linear edge of the cells is measured as the curved Lagrange
// edge it is (metric.h); the unit fraction is the share of lengths in [1/sqrt 2, sqrt 2].
// A 3D mesh of boundary facets alone (a surface mesh, e.g. the curved surface of surface3d) is
// assessed through its facets: they are the report's cells, triangles certified relative to their
// flat triangles and quadrilaterals in the plane of their vector area (certify_surface_triangle,
// certify_surface_quad, validity.h), with the aspect ratio in that plane and the metric lengths
// of their edges; the report is marked `surface`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "modules/mesh/hybrid_mesh.h"
#include "modules/metric/metric.h"
#include "modules/elements/validity.h"

namespace plaf {
inline namespace mesh {

struct EdgeLengthStats {
  std::size_t count = 0;
  double unit_fraction = 0;
  double min = 0, max = 0, mean = 0;
  std::string max_at;                // "(x, y[, z])": the midpoint of the longest edge's end nodes
  std::vector<double> bin_edges;     // histogram of log2(length): bins between these edges
  std::vector<std::size_t> histogram;
};

// The triangles' share of the metric section (2D): their distinct edges, and their shape in the
// metric, q = 4 sqrt(3) A_M / (l1^2 + l2^2 + l3^2) from the vertices with the metric at the
// centroid (1 for a triangle equilateral in the metric, 0 for a degenerate one).
struct TriangleMetricStats {
  std::size_t triangles = 0;
  EdgeLengthStats edges;
  double quality_min = 0, quality_mean = 0;
  std::vector<std::size_t> quality_histogram;  // 10 bins over [0, 1]
};

// Per-cell results, in block order (for pictures and VTU fields).
struct CellQuality {
  std::vector<std::uint8_t> valid;
  std::vector<double> scaled_jacobian;  // certified lower bound of min det J / max det J
  std::vector<double> aspect_ratio;
};

struct QualityReport {
  std::string name;
  // The run's verdict, when a run wrote the report (plaf run; -1 for plaf check): its exit code
  // (0 or 2) and the failures behind a 2 (a stage's, e.g. the layers' coverage, or the mesh's).
  // The report's "ok" is ok() and no failure, so that a script reading it agrees with the exit code.
  int exit_code = -1;
  std::vector<std::string> run_failures;
  bool surface = false;  // a 3D surface mesh: the cells are its boundary triangles
  std::size_t cells_total = 0;
  std::map<std::string, std::size_t> cells_by_type;  // "quadrilateral_Q3": n
  std::size_t cells_invalid = 0;
  std::size_t cells_unproven = 0;  // undecided at the depth limit (counted invalid too)
  // Simplices (2D triangles, 3D tetrahedra) whose Jacobian is certified positive but whose corners
  // span a non-positive area or volume (exact orient2d / orient3d): a curved cell may be valid so,
  // but readers that orient a cell by its corners (gmsh -check among them) take it for inverted.
  // Counted invalid too.
  std::size_t cells_inverted_corners = 0;
  std::string first_invalid;       // "<type> cell <i> of block <b> at (x, y[, z])" of the first invalid cell
  double scaled_jacobian_min = 0;
  std::string scaled_jacobian_worst;  // the cell with the smallest one, described as first_invalid
  double aspect_ratio_max = 0;
  bool has_metric = false;
  EdgeLengthStats metric;
  TriangleMetricStats triangle_metric;  // when has_metric and the mesh has triangles
  EdgeLengthStats tetrahedron_edges;     // 3D, when has_metric: the tetrahedra's distinct edges (count 0: none)
  ConformityReport conformity;
  std::vector<std::pair<std::string, double>> timings_s;
  // Where a failed run's picture looks (apps/run.cpp): a point (Dim coordinates; empty: none),
  // the radius around it, and why.
  std::vector<double> focus;
  double focus_radius = 0;
  std::string focus_label;
  // Further sections added by later stages, as (dotted key, JSON value text).
  std::vector<std::pair<std::string, std::string>> extra;

  bool ok() const { return cells_invalid == 0 && conformity.ok; }
};

struct QualityOptions {
  ValidityOptions validity;
  int histogram_bins = 12;
  // Told the share of the work done (cells certified, then edges measured) and what, as it goes
  // (the run's progress, modules/pipeline/progress.h); called from worker threads. May be empty.
  std::function<void(double fraction, const std::string& what)> progress;
};

// Metric conformity: every distinct linear edge of the cells is measured as the curved Lagrange
// edge it is; the edges of triangle cells are counted once more in triangle_metric.
// metric may be null (no metric section, e.g. for `plaf check`).
template <int Dim>
QualityReport assess_quality(const HybridMesh<Dim>& mesh, const MetricField<Dim>* metric,
                             const QualityOptions& options, CellQuality* per_cell = nullptr);

// JSON with nested keys cells.total, cells.by_type, cells.invalid, scaled_jacobian.min,
// aspect_ratio.max, metric.unit_fraction, timings_s.<stage>, conformity.*, plus `extra`.
std::string report_json(const QualityReport& report);
// JSON text of a number (null if not finite) and of a string (escaped), for report sections.
std::string json_number(double x);
std::string json_string(const std::string& x);

// A few human lines for stdout.
std::string report_summary(const QualityReport& report);

}  // namespace mesh
}  // namespace plaf
