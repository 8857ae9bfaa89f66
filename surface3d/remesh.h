// SPDX-License-Identifier: MIT
// Metric-conforming surface remeshing (Botsch & Kobbelt, "A remeshing approach to multiresolution
// modeling", SGP 2004, with every length measured in the metric): repeated rounds of
//   split edges longer than 4/3, collapse edges shorter than 4/5 (unless that makes an edge
//   longer than 4/3 or turns a face away from the surface), flip edges where the worse of the two
//   triangles gets better in the metric (a Delaunay-like criterion that holds for anisotropic
//   metrics), tangential relaxation (metric-density-weighted centroid in the tangent plane),
//   projection onto the reference geometry; after the rounds, needles, caps and folded faces are
//   collapsed or flipped; last, faces that cross other faces (a fold no local check sees) are
//   collapsed away, feature rules relaxed (remesh.cpp, untangle), and those left are counted.
//   No operation turns a face more than 60 degrees from the reference's normal (unless it was
//   already) or creates a needle.
// Features are preserved: feature edges are never flipped; a split of a feature edge puts the
// new vertex on its curve; a vertex on a curve collapses only along it and relaxes along it
// (projected onto the curve); corners never move or disappear. Edge lengths are metric lengths
// of the straight edge (metric.h), the metric being the field's, optionally intersected with a
// curvature size curvature_factor x radius of curvature of the reference (0: off).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "modules/metric/metric.h"
#include "modules/geometry/tri_surface.h"
#include "surface3d/discrete_reference.h"

namespace plaf {

struct RemeshOptions {
  int iterations = 8;  // rounds at most (they stop early once a round splits and collapses nothing)
  std::size_t max_triangles = 20000000;  // more than this: MesherError (sizes too small for the surface)
  std::function<void(int round, int rounds)> on_round;  // after each round (the run's progress); may be empty
};

// An edge over twice the unit length in the metric is one the remesher could not split: the
// surface report counts them.
inline constexpr double kLongEdge = 2.0;

struct RemeshReport {
  std::size_t splits = 0, collapses = 0, flips = 0, rounds = 0;
  std::size_t refused_splits = 0;   // long edges left because splitting them would fold a face
  std::size_t fan_cuts = 0;         // CAD fans of needles cut across (all their rays split together)
  std::size_t slivers_removed = 0;  // needles, caps and folds collapsed or flipped after the rounds
  std::size_t caps = 0;  // faces left with an angle over 160 degrees in the metric (is_cap)
  std::size_t faces_before = 0, faces_after = 0;
  double unit_fraction = 0;  // of edges with metric length in [1/sqrt 2, sqrt 2] after
  double longest = 0;        // the longest edge's metric length after
  std::size_t long_edges = 0;  // edges longer than kLongEdge after (splits refused to the end)
  std::string first_long;      // the longest edge's midpoint "(x, y, z)"
  std::size_t folded_faces = 0;  // normal more than 60 degrees from the reference's (should be 0)
  std::string first_folded;      // the first one's vertices, "(x, y, z) (x, y, z) (x, y, z)"
  Eigen::Vector3d first_folded_centroid = Eigen::Vector3d::Zero();
  double first_folded_size = 0;  // its longest edge
  std::size_t crossing_pairs_found = 0;  // face pairs crossing each other after the sliver passes
  std::size_t untangle_collapses = 0;    // edges collapsed to untangle them
  std::size_t crossing_pairs = 0;        // still crossing after that (the surface stage refuses them)
  std::string first_crossing;            // a face of the first such pair, its centroid "(x, y, z)"
  std::vector<Eigen::Vector3d> crossing_points;  // the centroids of every face still crossing
  double seconds = 0;
};

RemeshReport remesh_surface(TriSurface& s, const ReferenceGeometry<3>& reference, const MetricField<3>& metric,
                            const RemeshOptions& options);

}  // namespace plaf
