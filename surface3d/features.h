// SPDX-License-Identifier: MIT
// Features of a surface (paper Sec. II.E: "corners and edges ... obtained by measuring changes in
// the normal across surface elements"): ridges, corners and feature curves, written into the
// TriSurface's edge_feature / vertex_feature / edge_curve properties.
//
// - Ridge: an interior edge whose dihedral angle departs from flat by more than ridge_angle_deg
//   (the angle between the two face normals). Convex when the body is locally convex there
//   (the far vertex of one face lies below the other face's plane, exact orient3d), else concave.
//   Boundary edges (symmetry loops) are EdgeFeature::Boundary.
// - Crest (crest_scale r > 0): a rounded edge narrower than the mesh will be (a trailing edge's
//   cap of a few small turns, none above ridge_angle_deg) becomes one ridge, on its crest. Cap
//   edges: interior edges turning by 1/8 to 1 x ridge_angle_deg whose surface normals r across
//   (the closest input triangles to the points r away from the edge's midpoint within each of
//   its faces' planes) turn, the same way, by more than ridge_angle_deg. They form rows (chains,
//   split where other than two meet), rows sharing a face form a cap, and in each cap the one
//   row whose edges most often hold the far normals' bisector within their own dihedral wedge is
//   the ridge: a whole row, so the crest cannot zigzag where the bisector falls near a row. A
//   smooth surface of radius R turns by about 2 r / R over 2 r: only caps narrower than about
//   r / tan(ridge_angle / 2) are taken.
// - Corner: a feature vertex with 1 or >= 3 feature edges, or 2 that turn by more than
//   curve_turn_deg, or any vertex whose angle defect |2 pi - sum of angles| (interior vertices)
//   exceeds corner_defect_deg. Classified by its ridges: all convex -> ConvexCorner, all concave ->
//   ConcaveCorner, mixed -> SaddleCorner; on a boundary -> BoundaryCorner; a cone point without
//   ridges by the sign of its defect (> 0 convex, < 0 concave/saddle by the sign of the Gaussian
//   curvature). Other vertices on feature edges are VertexFeature::Curve.
// - Feature curves: maximal chains of feature edges between corners (or closed loops), numbered
//   0.. into edge_curve; a chain never mixes boundary and ridge edges.
#pragma once

#include <vector>

#include "modules/geometry/reference.h"
#include "modules/geometry/tri_surface.h"

namespace plaf {

struct FeatureOptions {
  double ridge_angle_deg = 30;
  double corner_defect_deg = 60;
  double curve_turn_deg = 45;
  bool keep_existing = false;  // true: keep edges already marked (e.g. by an analytic body) as features
  double crest_scale = 0;      // r of the crest rule above (0: off)
  // Judged on a reference (a final mesh checked against its body): an interior edge is a ridge
  // when it runs along one of the reference's feature curves (its ends within 1e-6 of the
  // reference's scale of the curve, its midpoint within 25 % of its length: a chord of a tightly
  // curved feature), whatever its dihedral; convex or concave as the mesh bends across it, or as
  // the body does where the mesh is nearly flat there. The crest rule is not used. So a ridge is
  // found only where the body has one, not where small triangles bend at a rounded edge; a
  // corner only where two feature curves meet (or a ridge meets the boundary) or at one of the
  // body's cone points (ReferenceGeometry::is_cone_point: a nose), not where the mesh's angles
  // add up to a defect.
  const ReferenceGeometry<3>* reference = nullptr;  // (not with keep_existing: a ConfigError)
  // Ridge curves shorter than this are dropped (their edges smooth, the corners found again
  // without them): a cluster of tiny curves where a rounded trailing edge meets a rounded tip is
  // no feature a mesh of this scale can follow (0: keep every curve; not with keep_existing).
  double min_curve_length = 0;
};

struct FeatureReport {
  std::size_t ridges_convex = 0, ridges_concave = 0, boundary_edges = 0;  // edges
  std::size_t corners_convex = 0, corners_concave = 0, corners_saddle = 0, corners_boundary = 0;
  std::size_t curves = 0;
  std::size_t dropped_curves = 0;  // detect_features: curves shorter than min_curve_length
};

FeatureReport detect_features(TriSurface& s, const FeatureOptions& options);
// Counts from the properties as they are (after remeshing, for the report).
FeatureReport count_features(const TriSurface& s);

// Per face (by index): inverted, a fold of the triangulation rather than of the body (features.cpp):
// its normal more than 90 degrees from those of the faces across two or three of its edges, which
// agree with each other. Its edges are no ridges, and the discrete reference leaves it out of its
// vertices' normals.
std::vector<char> inverted_faces(const TriMesh& m);

// Each feature curve's vertices in order along the curve (closed curves repeat the first vertex
// at the end), indexed by curve id.
std::vector<std::vector<TriMesh::VertexHandle>> feature_curves(const TriSurface& s);

}  // namespace plaf
