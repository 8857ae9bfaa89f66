// SPDX-License-Identifier: MIT
// Internal to remesh_surface (remesh.h): the Remesher, which holds the surface being remeshed, its
// reference geometry and metric, and per-vertex caches of the metric and the reference's normal.
// Its members fall in two jobs: measuring (metric lengths, feature bookkeeping, face alignment
// and quality, the checks an operation must pass), in remesher_measures.cpp; and the operations
// and rounds (split, collapse, flip, relax, sliver removal), in remesh.cpp. Not part of the
// surface3d API.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "surface3d/remesh.h"

namespace plaf::remesh_detail {

using Mesh = TriMesh;
using VH = Mesh::VertexHandle;
using EH = Mesh::EdgeHandle;
using HH = Mesh::HalfedgeHandle;
using FH = Mesh::FaceHandle;
using Vec = Eigen::Vector3d;

// Botsch & Kobbelt's thresholds, in metric length: split above 4/3, collapse below 4/5.
inline constexpr double kSplitAbove = 4.0 / 3.0;
inline constexpr double kCollapseBelow = 4.0 / 5.0;
// A face whose normal turns by more than this (cosine) in one operation is a fold: refuse.
inline constexpr double kMinNormalCos = 0.1;
// A face whose normal is within 60 degrees of the reference's normal (at its centroid's
// projection) lies on the surface's side it should; operations never make a face worse than that.
inline constexpr double kGoodAlignment = 0.5;
// A fan cut (Remesher::try_fan_cut) bends no edge around the fan by more than this (radians,
// 15 degrees: half the default ridge angle, features.h), unless it was bent more before.
inline constexpr double kFanCutMaxBend = 0.2617993877991494;
// Rounds of untangle() at most.
inline constexpr int kUntangleRounds = 6;
// The longest edge an untangling collapse may make (in the metric).
inline constexpr double kUntangleLength = 2.5;

class Remesher {
 public:
  Remesher(TriSurface& s, const ReferenceGeometry<3>& ref, const MetricField<3>& metric, const RemeshOptions& o)
      : s_(s), m_(s.mesh), ref_(ref), metric_(metric), opt_(o) {}

  RemeshReport run();

 private:
  // --- lengths -------------------------------------------------------------------------------
  // sqrt of a quadratic form that rounding may push just below zero for extreme anisotropy.
  static double root(double q) { return std::sqrt(std::max(q, 0.0)); }
  // The metric is evaluated once per vertex position and cached (vertices are created by splits
  // and moved by relaxation, and re-evaluated then); an edge's length is the mean of its length in
  // its two end metrics, exact for a uniform metric and second order for a smooth one.
  // (Returned by value: a cache may grow while a caller still holds an earlier entry.)
  Eigen::Matrix3d vertex_metric(VH v) {
    const std::size_t i = static_cast<std::size_t>(v.idx());
    if (i >= have_.size()) grow_caches();
    if (!have_[i]) {
      vm_[i] = metric_.evaluate(m_.point(v)).matrix();
      have_[i] = 1;
    }
    return vm_[i];
  }
  // Sizes the caches to the mesh's vertices: called after every split (the only operation adding
  // vertices), so that the normal cache never reallocates while its entries are pointed to.
  void grow_caches();
  // A vertex was created or moved: its cached metric and normal are stale.
  void forget_metric(VH v) {
    const std::size_t i = static_cast<std::size_t>(v.idx());
    if (i < have_.size()) have_[i] = 0;
    if (i < have_n_.size()) have_n_[i] = 0;
  }
  double length(VH a, VH b) {
    const Vec d = m_.point(b) - m_.point(a);
    return 0.5 * (root(d.dot(vertex_metric(a) * d)) + root(d.dot(vertex_metric(b) * d)));
  }
  // The length of a -> b if a stood at p (its metric taken as b's: a is being merged into b).
  double length_from(const Vec& p, VH b) {
    const Vec d = m_.point(b) - p;
    return root(d.dot(vertex_metric(b) * d));
  }
  // A feature edge becomes a piece of its curve (the high-order nodes follow the curve): where
  // the curve bends away from the chord (a symmetry loop around a leading edge), its length is
  // that of the polyline through the curve point nearest the chord's midpoint.
  double curve_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b, const Eigen::Matrix3d& mb, int c) const;
  // An edge between vertices whose surface normals differ by more than 60 degrees spans a tight
  // turn of the surface (wraps a thin trailing edge): the metrics at its ends do not see the
  // turn, so it is measured along the polyline through its projected midpoint, in the metric
  // there too.
  double wrapped_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b, const Eigen::Matrix3d& mb) const;
  // Whether the edge a - b (a at pa, with normal na) wraps a tight turn: its ends' normals differ
  // by more than 60 degrees, or, where one end is on a feature (no normal), the surface lies
  // farther than a quarter of the edge from its midpoint.
  bool wraps(const Vec& pa, const Vec* na, VH b);
  // The edge's metric length: the chord's, or more along its curve or around a tight turn.
  double length(EH e);

  // --- feature bookkeeping -----------------------------------------------------------------------
  int curve(EH e) const { return m_.property(s_.edge_curve, e); }
  bool is_feature(EH e) const { return curve(e) >= 0 || m_.is_boundary(e); }
  VertexFeature feature(VH v) const { return m_.property(s_.vertex_feature, v); }
  // The curve a (non-corner) feature vertex lies on, -1 for a smooth vertex.
  int vertex_curve(VH v) const;
  // A vertex that must stay where it is: a corner, or on a feature edge without a curve id.
  bool is_fixed(VH v) const;
  static double chord_gap(const Vec& x, const Vec& a, const Vec& b, double inv_size);
  static double inverse_smallest_size(const Eigen::Matrix3d& m);
  bool curve_move_keeps_shape(VH v, const Vec& p);
  Vec project_vertex(VH v, const Vec& p) const {
    const int c = vertex_curve(v);
    return c >= 0 ? ref_.project_to_curve(p, c) : ref_.project(p);
  }

  // --- faces -------------------------------------------------------------------------------------
  // A needle or a cap: twice the area over the longest edge squared below 1e-4 (about a 0.006
  // degree angle). No operation may create one (it could not be certified valid).
  static bool degenerate(const Vec& a, const Vec& b, const Vec& c) {
    const double l2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    return !((b - a).cross(c - a).norm() > 1e-4 * l2);
  }
  static bool degenerate(const std::array<Vec, 3>& x) { return degenerate(x[0], x[1], x[2]); }
  // The face's corners with vertex v moved to p.
  std::array<Vec, 3> corners_with(FH f, VH v, const Vec& p) const;
  // Unnormalised normal of face f with vertex v moved to p.
  Vec face_normal_with(FH f, VH v, const Vec& p) const {
    const std::array<Vec, 3> x = corners_with(f, v, p);
    return (x[1] - x[0]).cross(x[2] - x[0]);
  }
  // The reference's normal at a smooth vertex (cached like the metric), null at feature
  // vertices, where it is ambiguous (either side of a ridge).
  const Vec* vertex_normal(VH v) {
    if (feature(v) != VertexFeature::Smooth || m_.is_boundary(v)) return nullptr;
    const std::size_t i = static_cast<std::size_t>(v.idx());
    if (i >= have_n_.size()) grow_caches();  // (not reached: splits grow the caches)
    if (!have_n_[i]) {
      vn_[i] = ref_.normal(m_.point(v));
      have_n_[i] = 1;
    }
    return &vn_[i];
  }
  // Cosine between triangle (a, b, c)'s normal and the reference's: the mean of its smooth
  // vertices' normals (given, null at feature vertices), or at the centroid's projection when all
  // three are on features; -2 for a degenerate triangle.
  double alignment(const Vec& a, const Vec& b, const Vec& c, const Vec* na, const Vec* nb, const Vec* nc) const;
  // The alignment of face f with vertex v moved to p (whose normal is np, null if v is on a
  // feature).
  double alignment_with(FH f, VH v, const Vec& p, const Vec* np);
  // A new face is acceptable when it lies on the surface's side (alignment 60 degrees), or is no
  // worse than the face it replaces (the initial mesh may start worse).
  static bool acceptable(double before, double after) { return after >= std::min(kGoodAlignment, before); }
  // Moving v to p keeps every face around v (except those in `skip`) turned by less than 84
  // degrees, non-degenerate and acceptably aligned with the reference.
  // (known_normal: the reference's normal at p when the caller has it.)
  bool move_keeps_faces(VH v, const Vec& p, FH skip0 = FH(), FH skip1 = FH(), const Vec* known_normal = nullptr);
  // Shape quality of triangle (a, b, c) in the mean of its vertices' metrics:
  // 4 sqrt(3) A / sum l^2 (1 equilateral in the metric, 0 degenerate).
  double quality(VH a, VH b, VH c);
  // The upper Cholesky factor U of the mean of a, b and c's metrics (M = U^T U, |U v| the metric
  // length of v); false where that mean is not positive definite.
  bool mean_metric_factor(VH a, VH b, VH c, Eigen::Matrix3d& u);
  // Whether face f is a cap: an angle over 160 degrees in the mean of its vertices' metrics (a
  // triangle stretched as the metric asks is no cap).
  bool is_cap(FH f);
  // Splitting h's edge at p keeps each of its faces' two halves turned by less than 84 degrees
  // from the face (a projected midpoint on a tight leading edge can land behind a neighbour).
  bool split_keeps_faces(HH h, const Vec& p);

  // --- parallel warm-up (remesh.cpp) ------------------------------------------------------------
  // The caches the serial operations fill one entry at a time, filled on the worker threads
  // (modules/base/parallel.h) beforehand: every live vertex's metric and (smooth) reference
  // normal, and with warm_lengths every live edge's length. Each entry is a function of what its
  // cache key records (the metric fields and the reference keep no mutable state), so a warmed
  // entry is, bit for bit, the one the serial pass would compute: the remeshing is unchanged,
  // only its evaluations run in parallel.
  void warm_vertices();
  void warm_lengths();

  // --- operations (remesh.cpp) -------------------------------------------------------------------
  void split_long_edges();
  void collapse_short_edges();
  void flip_edges();
  void relax();
  void relax_target(VH v, std::vector<Vec>& target, std::vector<char>& moves);
  bool try_collapse(HH h, double max_length = kSplitAbove);
  bool try_flip(EH e, double min_gain);
  bool try_split(EH e);
  // e split at p (its properties, the new faces' tags), unchecked.
  void split_at(EH e, const Vec& p);
  // A ray of a CAD fan (needles from one apex to a finely sampled curve), whose split
  // split_keeps_faces refused: every ray of the fan split together (remesh.cpp).
  bool try_fan_cut(EH e);
  void remove_slivers();
  void untangle();

  // An edge merged by a collapse (one of the two other edges of a face of the collapsed edge):
  // the far vertex of that face, and the feature data the merged edge keeps.
  struct MergedEdge {
    VH far;
    int curve, tag;
    EdgeFeature feature;
  };
  // Whether collapsing h's from-vertex along h respects the features: corners stay, a feature
  // vertex moves only along its own curve (and not so far off the curve's polyline that its nose
  // is cut off), a smooth vertex not onto a feature edge, and the collapse keeps the topology.
  bool collapse_keeps_features(HH h);
  // The edges merged by collapsing h, with the feature data they keep; false when two feature
  // edges would merge (one would be lost).
  bool merged_edges(HH h, std::vector<MergedEdge>& merged) const;
  // Whether the edges from v1 to v0's other neighbours stay within max_length (or no longer
  // than 1.1 times the edge they replace).
  bool collapse_keeps_lengths(VH v0, VH v1, double max_length);
  // After the rounds: unit_fraction, folded_faces and first_folded.
  void measure_result();

  TriSurface& s_;
  Mesh& m_;
  const ReferenceGeometry<3>& ref_;
  const MetricField<3>& metric_;
  RemeshOptions opt_;
  RemeshReport rep_;
  std::vector<Eigen::Matrix3d> vm_;  // cached metric per vertex index
  std::vector<char> have_;
  bool untangling_ = false;  // untangle(): collapses may merge feature curves
  bool precise_ = false;  // alignment always at the centroid's projection (the final passes)
  std::vector<Vec> vn_;   // cached reference normal per (smooth) vertex index
  std::vector<char> have_n_;
  // The last length(EH) per edge index, with what it was computed from (both ends' positions,
  // the curve, whether each end has a normal): every pass of split_long_edges and
  // collapse_short_edges measures every edge, and an edge at a feature vertex or wrapping a turn
  // projects its midpoint onto the reference each time (on the published Orion capsule, 51,736
  // CAD triangles with 552 feature curves, those projections were 80 % of the surface stage).
  struct EdgeLength {
    Vec a = Vec::Constant(std::numeric_limits<double>::quiet_NaN()), b = a;
    int curve = -2;
    bool normal_a = false, normal_b = false;
    double length = 0;
  };
  std::vector<EdgeLength> edge_lengths_;
};

}  // namespace plaf::remesh_detail
