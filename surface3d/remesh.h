// SPDX-License-Identifier: MIT
// Metric-conforming surface remeshing (Botsch & Kobbelt, "A remeshing approach to multiresolution
// modeling", SGP 2004, with every length measured in the metric): repeated rounds of
//   split edges longer than 4/3, collapse edges shorter than 4/5 (unless that makes an edge
//   longer than 4/3 or flips a face), flip edges toward valence 6 (4 on boundaries) when the flip
//   keeps the faces' normals, tangential relaxation (metric-weighted centroid in the tangent
//   plane), projection onto the reference geometry; after the rounds, needles and caps of poor
//   metric quality are collapsed or flipped.
// Features are preserved: feature edges are never flipped; a split of a feature edge puts the
// new vertex on its curve; a vertex on a curve collapses only along it and relaxes along it
// (projected onto the curve); corners never move or disappear. Edge lengths are metric lengths
// of the straight edge (metric.h), the metric being the field's, optionally intersected with a
// curvature size curvature_factor x radius of curvature of the reference (0: off).
#pragma once

#include <cstddef>
#include <string>

#include "modules/metric.h"
#include "modules/tri_surface.h"
#include "surface3d/reference.h"

namespace plaf {

struct RemeshOptions {
  int iterations = 8;
};

struct RemeshReport {
  std::size_t splits = 0, collapses = 0, flips = 0, rounds = 0;
  std::size_t refused_splits = 0;
  std::size_t slivers_removed = 0;  // needles collapsed and caps flipped after the rounds  // long edges left because splitting them would fold a face
  std::size_t faces_before = 0, faces_after = 0;
  double unit_fraction = 0;  // of edges with metric length in [1/sqrt 2, sqrt 2] after
  std::size_t folded_faces = 0;  // normal more than 60 degrees from the reference's (should be 0)
  std::string first_folded;      // the first one's vertices, "(x, y, z) (x, y, z) (x, y, z)"
  double seconds = 0;
};

RemeshReport remesh_surface(TriSurface& s, const ReferenceGeometry& reference, const MetricField<3>& metric,
                            const RemeshOptions& options);

}  // namespace plaf
