// SPDX-License-Identifier: MIT
#include "surface3d/remesh.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "modules/base/error.h"

namespace plaf {

namespace {

using Mesh = TriMesh;
using VH = Mesh::VertexHandle;
using EH = Mesh::EdgeHandle;
using HH = Mesh::HalfedgeHandle;
using FH = Mesh::FaceHandle;
using Vec = Eigen::Vector3d;

// Botsch & Kobbelt's thresholds, in metric length: split above 4/3, collapse below 4/5.
constexpr double kSplitAbove = 4.0 / 3.0;
constexpr double kCollapseBelow = 4.0 / 5.0;
// A face whose normal turns by more than this (cosine) in one operation is a fold: refuse.
constexpr double kMinNormalCos = 0.1;
// A face whose normal is within 60 degrees of the reference's normal (at its centroid's
// projection) lies on the surface's side it should; operations never make a face worse than that.
constexpr double kGoodAlignment = 0.5;

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
  void grow_caches() {
    const std::size_t n = m_.n_vertices();
    vm_.resize(n, Eigen::Matrix3d::Zero());
    have_.resize(n, 0);
    vn_.resize(n, Vec::Zero());
    have_n_.resize(n, 0);
  }
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
  double curve_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b, const Eigen::Matrix3d& mb, int c) const {
    const Vec m = ref_.project_to_curve(0.5 * (a + b), c);
    const Vec d1 = m - a, d2 = b - m;
    return root(d1.dot(ma * d1)) + root(d2.dot(mb * d2));
  }
  // An edge between vertices whose surface normals differ by more than 60 degrees spans a tight
  // turn of the surface (wraps a thin trailing edge): the metrics at its ends do not see the
  // turn, so it is measured along the polyline through its projected midpoint, in the metric
  // there too.
  double wrapped_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b, const Eigen::Matrix3d& mb) const {
    const Vec m = ref_.project(0.5 * (a + b));
    const Eigen::Matrix3d mm = metric_.evaluate(m).matrix();
    const Vec d1 = m - a, d2 = b - m;
    return 0.5 * (root(d1.dot(ma * d1)) + root(d1.dot(mm * d1))) +
           0.5 * (root(d2.dot(mm * d2)) + root(d2.dot(mb * d2)));
  }
  // Whether the edge a - b (a at pa, with normal na) wraps a tight turn: its ends' normals differ
  // by more than 60 degrees, or, where one end is on a feature (no normal), the surface lies
  // farther than a quarter of the edge from its midpoint.
  bool wraps(const Vec& pa, const Vec* na, VH b) {
    const Vec* nb = vertex_normal(b);
    if (na && nb) return na->dot(*nb) < 0.5;
    const Vec mid = 0.5 * (pa + m_.point(b));
    return (ref_.project(mid) - mid).norm() > 0.25 * (m_.point(b) - pa).norm();
  }
  double length(EH e) {
    const HH h = m_.halfedge_handle(e, 0);
    const VH a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
    const double chord = length(a, b);
    const int c = curve(e);
    if (c < 0) {
      if (!wraps(m_.point(a), vertex_normal(a), b)) return chord;
      return std::max(chord, wrapped_length(m_.point(a), vertex_metric(a), m_.point(b), vertex_metric(b)));
    }
    return std::max(chord, curve_length(m_.point(a), vertex_metric(a), m_.point(b), vertex_metric(b), c));
  }

  // --- feature bookkeeping -----------------------------------------------------------------------
  int curve(EH e) const { return m_.property(s_.edge_curve, e); }
  bool is_feature(EH e) const { return curve(e) >= 0 || m_.is_boundary(e); }
  VertexFeature feature(VH v) const { return m_.property(s_.vertex_feature, v); }
  // The curve a (non-corner) feature vertex lies on, -1 for a smooth vertex.
  int vertex_curve(VH v) const {
    for (const HH h : m_.voh_range(v)) {
      const int c = curve(m_.edge_handle(h));
      if (c >= 0) return c;
    }
    return -1;
  }
  // A vertex that must stay where it is: a corner, or on a feature edge without a curve id.
  bool is_fixed(VH v) const {
    if (is_corner(feature(v))) return true;
    if (feature(v) == VertexFeature::Curve) return vertex_curve(v) < 0;
    for (const HH h : m_.voh_range(v))
      if (is_feature(m_.edge_handle(h))) return vertex_curve(v) < 0;
    return false;
  }
  Vec project_vertex(VH v, const Vec& p) const {
    const int c = vertex_curve(v);
    return c >= 0 ? ref_.project_to_curve(p, c) : ref_.project(p);
  }

  // A needle or a cap: twice the area over the longest edge squared below 1e-4 (about a 0.006
  // degree angle). No operation may create one (it could not be certified valid).
  static bool degenerate(const Vec& a, const Vec& b, const Vec& c) {
    const double l2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    return !((b - a).cross(c - a).norm() > 1e-4 * l2);
  }
  static bool degenerate(const std::array<Vec, 3>& x) { return degenerate(x[0], x[1], x[2]); }
  // The face's corners with vertex v moved to p.
  std::array<Vec, 3> corners_with(FH f, VH v, const Vec& p) const {
    std::array<Vec, 3> x;
    int k = 0;
    for (const VH w : m_.fv_range(f)) x[static_cast<std::size_t>(k++)] = w == v ? p : m_.point(w);
    return x;
  }

  // Unnormalised normal of face f with vertex v moved to p.
  Vec face_normal_with(FH f, VH v, const Vec& p) const {
    std::array<Vec, 3> x;
    int k = 0;
    for (const VH w : m_.fv_range(f)) x[static_cast<std::size_t>(k++)] = w == v ? p : m_.point(w);
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
  double alignment(const Vec& a, const Vec& b, const Vec& c, const Vec* na, const Vec* nb, const Vec* nc) const {
    const Vec n = (b - a).cross(c - a);
    const double nn = n.norm();
    if (!(nn > 0)) return -2;
    // The vertices' normals stand for the face's where all three are smooth and agree (within ~25
    // degrees); beside a feature or where the surface turns fast across the face (a leading
    // edge) the centroid is projected.
    Vec r = Vec::Zero();
    bool agree = true;
    int given = 0;
    for (const Vec* x : {na, nb, nc}) {
      if (!x || precise_) continue;
      if (given > 0 && x->dot(r / given) < 0.9) agree = false;
      r += *x;
      ++given;
    }
    if (given < 3 || !agree) {
      r = ref_.normal(ref_.project((a + b + c) / 3));
    } else {
      r.normalize();
    }
    return n.dot(r) / nn;
  }
  // The alignment of face f with vertex v moved to p (whose normal is np, null if v is on a
  // feature).
  double alignment_with(FH f, VH v, const Vec& p, const Vec* np) {
    std::array<Vec, 3> x;
    std::array<const Vec*, 3> nx;
    int k = 0;
    for (const VH w : m_.fv_range(f)) {
      const std::size_t i = static_cast<std::size_t>(k++);
      x[i] = w == v ? p : m_.point(w);
      nx[i] = w == v ? np : vertex_normal(w);
    }
    return alignment(x[0], x[1], x[2], nx[0], nx[1], nx[2]);
  }
  // A new face is acceptable when it lies on the surface's side (alignment 60 degrees), or is no
  // worse than the face it replaces (the initial mesh may start worse).
  static bool acceptable(double before, double after) { return after >= std::min(kGoodAlignment, before); }

  // Moving v to p keeps every face around v (except those in `skip`) turned by less than 84
  // degrees, non-degenerate and acceptably aligned with the reference.
  // (known_normal: the reference's normal at p when the caller has it.)
  bool move_keeps_faces(VH v, const Vec& p, FH skip0 = FH(), FH skip1 = FH(), const Vec* known_normal = nullptr) {
    const Vec* old_normal = vertex_normal(v);
    Vec new_normal;
    if (old_normal) new_normal = known_normal ? *known_normal : ref_.normal(p);
    const Vec* np = old_normal ? &new_normal : nullptr;
    for (const FH f : m_.vf_range(v)) {
      if (f == skip0 || f == skip1) continue;
      const Vec before = face_normal_with(f, v, m_.point(v));
      const Vec after = face_normal_with(f, v, p);
      const double nb = before.norm(), na = after.norm();
      if (na <= 1e-4 * nb || after.dot(before) < kMinNormalCos * na * nb) return false;
      if (degenerate(corners_with(f, v, p))) return false;
      if (!acceptable(alignment_with(f, v, m_.point(v), old_normal), alignment_with(f, v, p, np))) return false;
    }
    return true;
  }

  // Shape quality of triangle (a, b, c) in the mean of its vertices' metrics:
  // 4 sqrt(3) A / sum l^2 (1 equilateral in the metric, 0 degenerate).
  double quality(VH a, VH b, VH c) {
    const Eigen::Matrix3d mm = (vertex_metric(a) + vertex_metric(b) + vertex_metric(c)) / 3;
    const Eigen::LLT<Eigen::Matrix3d> llt(mm);
    if (llt.info() != Eigen::Success) return 0;
    const Eigen::Matrix3d lt = llt.matrixU();  // M = U^T U: |U v| is the metric length of v
    const Vec pa = m_.point(a), pb = m_.point(b), pc = m_.point(c);
    const Vec u = lt * (pb - pa), w = lt * (pc - pa), z = lt * (pc - pb);
    const double area = 0.5 * u.cross(w).norm();
    const double sum = u.squaredNorm() + w.squaredNorm() + z.squaredNorm();
    return sum > 0 ? 4 * std::sqrt(3.0) * area / sum : 0;
  }

  // Splitting h's edge at p keeps each of its faces' two halves turned by less than 84 degrees
  // from the face (a projected midpoint on a tight leading edge can land behind a neighbour).
  bool split_keeps_faces(HH h, const Vec& p) {
    // The new vertex is smooth unless the edge is a feature.
    const bool smooth = !is_feature(m_.edge_handle(h));
    const Vec np = smooth ? ref_.normal(p) : Vec::Zero();
    for (const HH hh : {h, m_.opposite_halfedge_handle(h)}) {
      if (m_.is_boundary(hh)) continue;
      const VH va = m_.from_vertex_handle(hh), vb = m_.to_vertex_handle(hh);
      const VH vc = m_.to_vertex_handle(m_.next_halfedge_handle(hh));
      const Vec a = m_.point(va), b = m_.point(vb), c = m_.point(vc);
      const Vec *na = vertex_normal(va), *nb = vertex_normal(vb), *nc = vertex_normal(vc);
      const Vec n = (b - a).cross(c - a);
      for (const Vec& half : {Vec((p - a).cross(c - a)), Vec((b - p).cross(c - p))}) {
        const double nh = half.norm();
        if (nh <= 1e-12 * n.norm() || half.dot(n) < kMinNormalCos * nh * n.norm()) return false;
      }
      if (degenerate(a, p, c) || degenerate(p, b, c)) return false;
      const double before = alignment(a, b, c, na, nb, nc);
      const Vec* pn = smooth ? &np : nullptr;
      if (!acceptable(before, alignment(a, p, c, na, pn, nc)) || !acceptable(before, alignment(p, b, c, pn, nb, nc)))
        return false;
    }
    return true;
  }

  void split_long_edges();
  void collapse_short_edges();
  void flip_edges();
  void relax();
  bool try_collapse(HH h, double max_length = kSplitAbove);
  bool try_flip(EH e, double min_gain);
  bool try_split(EH e);
  void remove_slivers();

  TriSurface& s_;
  Mesh& m_;
  const ReferenceGeometry<3>& ref_;
  const MetricField<3>& metric_;
  RemeshOptions opt_;
  RemeshReport rep_;
  std::vector<Eigen::Matrix3d> vm_;  // cached metric per vertex index
  std::vector<char> have_;
  bool precise_ = false;  // alignment always at the centroid's projection (the final passes)
  std::vector<Vec> vn_;   // cached reference normal per (smooth) vertex index
  std::vector<char> have_n_;
};

void Remesher::split_long_edges() {
  // Repeated until no edge is long: a coarse start (an icosahedron for a fine metric) needs
  // several halvings; each pass splits the edges found long at its start, longest first.
  for (int pass = 0; pass < 40; ++pass) {
    std::vector<std::pair<double, EH>> longs;
    for (const EH e : m_.edges()) {
      const double l = length(e);
      if (l > kSplitAbove) longs.emplace_back(l, e);
    }
    if (longs.empty()) return;
    if (m_.n_faces() + 2 * longs.size() > opt_.max_triangles)
      throw MesherError("remesh: the metric asks for more than " + std::to_string(opt_.max_triangles) +
                        " triangles on this surface (" + std::to_string(m_.n_faces()) + " so far, " +
                        std::to_string(longs.size()) +
                        " edges still too long): give larger sizes or raise surface.max_triangles");
    std::sort(longs.begin(), longs.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    for (const auto& [l, e] : longs) {
      (void)l;
      if (m_.status(e).deleted()) continue;
      if (length(e) <= kSplitAbove) continue;  // an earlier split changed it
      try_split(e);
    }
  }
}

// Splits e at its midpoint projected onto the reference (onto its curve for a feature edge) unless
// that would fold one of its faces; the halves keep e's feature, curve and tag, the new faces their
// side's tag.
bool Remesher::try_split(EH e) {
  const HH h0 = m_.halfedge_handle(e, 0);
  const VH a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  const int c = curve(e);
  const int etag = m_.property(s_.edge_tag, e);
  const EdgeFeature ef = m_.property(s_.edge_feature, e);
  const Vec mid = 0.5 * (m_.point(a) + m_.point(b));
  const Vec p = c >= 0 ? ref_.project_to_curve(mid, c) : ref_.project(mid);
  if (!split_keeps_faces(h0, p)) {
    ++rep_.refused_splits;
    return false;
  }
  // The faces' tags by their far vertex, to give the four new faces the right ones.
  std::vector<std::pair<VH, int>> far_tag;
  for (const HH h : {h0, m_.opposite_halfedge_handle(h0)})
    if (!m_.is_boundary(h))
      far_tag.emplace_back(m_.to_vertex_handle(m_.next_halfedge_handle(h)),
                           m_.property(s_.face_tag, m_.face_handle(h)));
  const VH v = m_.split(e, p);
  grow_caches();
  forget_metric(v);
  m_.property(s_.vertex_feature, v) = c >= 0 ? VertexFeature::Curve : VertexFeature::Smooth;
  for (const HH h : m_.voh_range(v)) {
    const EH ne = m_.edge_handle(h);
    const VH w = m_.to_vertex_handle(h);
    const bool half = w == a || w == b;
    m_.property(s_.edge_curve, ne) = half ? c : -1;
    m_.property(s_.edge_tag, ne) = half ? etag : -1;
    m_.property(s_.edge_feature, ne) = half ? ef : EdgeFeature::Smooth;
  }
  for (const FH f : m_.vf_range(v))
    for (const VH w : m_.fv_range(f))
      for (const auto& [far, tag] : far_tag)
        if (w == far) m_.property(s_.face_tag, f) = tag;
  ++rep_.splits;
  return true;
}

// Collapses h's from-vertex into its to-vertex if that keeps topology, features, lengths and
// orientation.
bool Remesher::try_collapse(HH h, double max_length) {
  const VH v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  const EH e = m_.edge_handle(h);
  if (is_fixed(v0)) return false;
  const int c0 = vertex_curve(v0);
  const bool v0_on_feature = c0 >= 0 || m_.is_boundary(v0);
  // A feature vertex moves only along its own curve; a smooth vertex anywhere.
  if (v0_on_feature && (curve(e) < 0 || curve(e) != c0)) return false;
  if (!v0_on_feature && is_feature(e)) return false;
  if (!m_.is_collapse_ok(h)) return false;
  // A curve vertex leaves its curve's polyline as the chord v1 - w from its other curve neighbour
  // w: refuse when that chord passes farther than a quarter of the metric size from it (it would
  // cut off a symmetry loop's leading-edge nose, which no projection of the new edge brings back).
  if (v0_on_feature) {
    for (const HH hh : m_.voh_range(v0)) {
      const EH ee = m_.edge_handle(hh);
      if (ee == e || curve(ee) != curve(e)) continue;
      const Vec p0 = m_.point(v0), a = m_.point(v1), b = m_.point(m_.to_vertex_handle(hh));
      const Vec ab = b - a;
      const double t = ab.squaredNorm() > 0 ? std::clamp((p0 - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      const Vec off = a + t * ab - p0;
      if (std::sqrt(off.dot(vertex_metric(v0) * off)) > 0.25) return false;
    }
  }
  // The two faces of e disappear; their other edges merge pairwise. Features survive on the
  // merged edge (repaired below), but two features merging would lose one: refuse.
  struct Wing {
    VH far;
    int curve, tag;
    EdgeFeature feature;
  };
  std::vector<Wing> wings;
  for (const HH hh : {h, m_.opposite_halfedge_handle(h)}) {
    if (m_.is_boundary(hh)) continue;
    const HH n = m_.next_halfedge_handle(hh), p = m_.prev_halfedge_handle(hh);
    const EH e1 = m_.edge_handle(n), e2 = m_.edge_handle(p);
    const bool f1 = is_feature(e1), f2 = is_feature(e2);
    if (f1 && f2) return false;
    const EH keep = f1 ? e1 : e2;
    wings.push_back(
        {m_.to_vertex_handle(n), curve(keep), m_.property(s_.edge_tag, keep), m_.property(s_.edge_feature, keep)});
  }
  const Vec target = m_.point(v1);
  // New edges v1 - (neighbours of v0) must not be long.
  // (An edge already longer than the limit may stay as long: merging two nearly coincident
  // vertices must not be refused for an edge it does not lengthen.)
  for (const VH w : m_.vv_range(v0)) {
    if (w == v1) continue;
    double l = length_from(m_.point(w), v1);
    const HH vw = m_.find_halfedge(v0, w);
    const int cw = curve(m_.edge_handle(vw));
    if (cw >= 0) l = std::max(l, curve_length(target, vertex_metric(v1), m_.point(w), vertex_metric(w), cw));
    if (cw < 0 && wraps(target, vertex_normal(v1), w))
      l = std::max(l, wrapped_length(target, vertex_metric(v1), m_.point(w), vertex_metric(w)));
    if (l > std::max(max_length, 1.1 * length(m_.edge_handle(vw)))) return false;
  }
  const FH fl = m_.is_boundary(h) ? FH() : m_.face_handle(h);
  const HH o = m_.opposite_halfedge_handle(h);
  const FH fr = m_.is_boundary(o) ? FH() : m_.face_handle(o);
  if (!move_keeps_faces(v0, target, fl, fr)) return false;
  m_.collapse(h);
  for (const Wing& w : wings) {
    const HH nh = m_.find_halfedge(v1, w.far);
    if (!nh.is_valid()) continue;
    const EH ne = m_.edge_handle(nh);
    m_.property(s_.edge_curve, ne) = w.curve;
    m_.property(s_.edge_tag, ne) = w.tag;
    m_.property(s_.edge_feature, ne) = w.feature;
  }
  ++rep_.collapses;
  return true;
}

void Remesher::collapse_short_edges() {
  std::vector<std::pair<double, EH>> shorts;
  for (const EH e : m_.edges()) {
    const double l = length(e);
    if (l < kCollapseBelow) shorts.emplace_back(l, e);
  }
  std::sort(shorts.begin(), shorts.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (const auto& [l, e] : shorts) {
    (void)l;
    if (m_.status(e).deleted()) continue;
    if (length(e) >= kCollapseBelow) continue;
    const HH h = m_.halfedge_handle(e, 0);
    if (!try_collapse(h)) try_collapse(m_.opposite_halfedge_handle(h));
  }
}

// Flips e if that makes the worse of its two triangles better by the factor min_gain in the
// metric, keeps both new faces aligned with the reference, adds no long edge and keeps the border
// between tagged patches. Feature edges never flip.
bool Remesher::try_flip(EH e, double min_gain) {
  if (is_feature(e) || !m_.is_flip_ok(e)) return false;
  const HH h = m_.halfedge_handle(e, 0), o = m_.opposite_halfedge_handle(h);
  const VH a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
  const VH c = m_.to_vertex_handle(m_.next_halfedge_handle(h));
  const VH d = m_.to_vertex_handle(m_.next_halfedge_handle(o));
  const Vec pa = m_.point(a), pb = m_.point(b), pc = m_.point(c), pd = m_.point(d);
  // Before: (a, b, c) and (b, a, d); after, counter-clockwise: (a, d, c) and (b, c, d).
  const Vec n_before = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
  const Vec n1 = (pd - pa).cross(pc - pa), n2 = (pc - pb).cross(pd - pb);
  if (n1.dot(n_before) <= kMinNormalCos * n1.norm() * n_before.norm() ||
      n2.dot(n_before) <= kMinNormalCos * n2.norm() * n_before.norm() ||
      n1.dot(n2) <= kMinNormalCos * n1.norm() * n2.norm())
    return false;
  const double before = std::min(quality(a, b, c), quality(b, a, d));
  const double after = std::min(quality(a, d, c), quality(b, c, d));
  // (Never down to a needle: a fold is unfolded, not traded for a degenerate triangle.)
  if (after <= std::max(before * min_gain, 1e-3)) return false;
  if (degenerate(pa, pd, pc) || degenerate(pb, pc, pd)) return false;
  const Vec *na = vertex_normal(a), *nb = vertex_normal(b), *nc = vertex_normal(c), *nd = vertex_normal(d);
  const double aligned = std::min(alignment(pa, pb, pc, na, nb, nc), alignment(pb, pa, pd, nb, na, nd));
  if (!acceptable(aligned, alignment(pa, pd, pc, na, nd, nc)) ||
      !acceptable(aligned, alignment(pb, pc, pd, nb, nc, nd)))
    return false;
  // The new edge must not be long (it would be split again, oscillating).
  if (length(c, d) > kSplitAbove) return false;
  if (m_.property(s_.face_tag, m_.face_handle(h)) != m_.property(s_.face_tag, m_.face_handle(o))) return false;
  m_.flip(e);
  ++rep_.flips;
  return true;
}

void Remesher::flip_edges() {
  // Flip where the worse of the two triangles gets better in the metric (a Delaunay-like
  // criterion that also holds for anisotropic metrics).
  for (int pass = 0; pass < 3; ++pass) {
    std::size_t flips = 0;
    for (const EH e : m_.edges())
      if (try_flip(e, 1.05)) ++flips;
    if (flips == 0) break;
  }
}

// Needles (one edge much shorter than the others) and caps (one angle near 180 degrees) of poor
// metric quality that the rounds left, typically where sizes change fast (a blunt trailing edge
// at h_min beside the span's size): a needle's short edge collapses even if a neighbouring edge
// then reaches twice the unit length; a cap's long edge flips if that helps at all.
void Remesher::remove_slivers() {
  for (int pass = 0; pass < 4; ++pass) {
    std::size_t fixed = 0;
    for (const FH f : m_.faces()) {
      if (m_.status(f).deleted()) continue;
      std::array<HH, 3> hs;
      int k = 0;
      for (const HH h : m_.fh_range(f)) hs[static_cast<std::size_t>(k++)] = h;
      const VH a = m_.from_vertex_handle(hs[0]), b = m_.from_vertex_handle(hs[1]), c = m_.from_vertex_handle(hs[2]);
      const bool folded = alignment(m_.point(a), m_.point(b), m_.point(c), nullptr, nullptr, nullptr) < kGoodAlignment;
      if (!folded && quality(a, b, c) >= 0.1) continue;
      std::array<double, 3> l;
      for (std::size_t i = 0; i < 3; ++i) l[i] = length(m_.edge_handle(hs[i]));
      const std::size_t shortest = static_cast<std::size_t>(std::min_element(l.begin(), l.end()) - l.begin());
      const std::size_t longest = static_cast<std::size_t>(std::max_element(l.begin(), l.end()) - l.begin());
      bool done = false;
      if (l[shortest] < 0.5 * l[longest]) {
        const HH h = hs[shortest];
        done = try_collapse(h, 2.0) || try_collapse(m_.opposite_halfedge_handle(h), 2.0);
      }
      if (!done) done = try_flip(m_.edge_handle(hs[longest]), folded ? 0.0 : 1.0);
      // A fold: any flip or collapse of its edges that leaves every face aligned.
      for (std::size_t i = 0; folded && !done && i < 3; ++i)
        done = try_flip(m_.edge_handle(hs[i]), 0.0) || try_collapse(hs[i], 2.0) ||
               try_collapse(m_.opposite_halfedge_handle(hs[i]), 2.0);
      // Else a finer surface there: the fold's longest edge split at the surface.
      if (folded && !done) done = try_split(m_.edge_handle(hs[longest]));
      if (done) {
        ++fixed;
        ++rep_.slivers_removed;
      }
    }
    if (fixed == 0) break;
  }
}

void Remesher::relax() {
  // Tangential relaxation: every free vertex moves halfway toward the density-weighted centroid of
  // its neighbours, within its tangent plane (or along its curve), then back onto the reference.
  std::vector<Vec> target(m_.n_vertices());
  std::vector<char> moves(m_.n_vertices(), 0);
  for (const VH v : m_.vertices()) {
    if (is_fixed(v)) continue;
    const int c = vertex_curve(v);
    const bool on_boundary = m_.is_boundary(v);
    Vec sum = Vec::Zero();
    double wsum = 0;
    for (const HH h : m_.voh_range(v)) {
      const EH e = m_.edge_handle(h);
      // A curve vertex averages its two curve neighbours only.
      if ((c >= 0 || on_boundary) && curve(e) != c) continue;
      const VH wv = m_.to_vertex_handle(h);
      const Vec w = m_.point(wv);
      // Weight by the metric density at the neighbour (1/h^2 for an isotropic size h), so the
      // centroid leans toward fine regions as the metric asks.
      const double rho = vertex_metric(wv).trace() / 3.0;
      sum += rho * w;
      wsum += rho;
    }
    if (wsum <= 0) continue;
    const Vec p = m_.point(v);
    Vec d = sum / wsum - p;
    if (c < 0) {
      const Vec* cached = vertex_normal(v);
      const Vec n = cached ? *cached : ref_.normal(p);
      d -= n * n.dot(d);
    }
    target[static_cast<std::size_t>(v.idx())] = p + 0.5 * d;
    moves[static_cast<std::size_t>(v.idx())] = 1;
  }
  for (const VH v : m_.vertices()) {
    if (!moves[static_cast<std::size_t>(v.idx())]) continue;
    // A smooth vertex is projected with its normal in one search, and keeps that normal cached.
    const bool smooth = vertex_normal(v) != nullptr;
    Vec n;
    const Vec p = smooth ? ref_.project(target[static_cast<std::size_t>(v.idx())], n)
                         : project_vertex(v, target[static_cast<std::size_t>(v.idx())]);
    if (move_keeps_faces(v, p, FH(), FH(), smooth ? &n : nullptr)) {
      m_.set_point(v, p);
      forget_metric(v);
      if (smooth) {
        vn_[static_cast<std::size_t>(v.idx())] = n;
        have_n_[static_cast<std::size_t>(v.idx())] = 1;
      }
    }
  }
}

RemeshReport Remesher::run() {
  const auto t0 = std::chrono::steady_clock::now();
  rep_.faces_before = m_.n_faces();
  grow_caches();
  for (int round = 0; round < opt_.iterations; ++round) {
    const std::size_t changes = rep_.splits + rep_.collapses, flips = rep_.flips;
    split_long_edges();
    collapse_short_edges();
    flip_edges();
    for (int k = 0; k < 2; ++k) relax();
    ++rep_.rounds;
    // Converged: a round that split and collapsed nothing and flipped under 0.5 % of the edges
    // only relaxes further; the rounds stop (the final passes still run).
    if (rep_.splits + rep_.collapses == changes && rep_.flips - flips < m_.n_edges() / 200) break;
  }
  // The final passes judge every face by its centroid's projection, as the fold count does.
  precise_ = true;
  remove_slivers();
  relax();
  remove_slivers();
  m_.garbage_collection();
  vm_.clear();  // the collection renumbered the vertices
  have_.clear();
  vn_.clear();
  have_n_.clear();
  rep_.faces_after = m_.n_faces();
  std::size_t unit = 0, total = 0;
  for (const EH e : m_.edges()) {
    const double l = length(e);
    ++total;
    if (l >= 1 / std::sqrt(2.0) && l <= std::sqrt(2.0)) ++unit;
  }
  rep_.unit_fraction = total ? static_cast<double>(unit) / static_cast<double>(total) : 0;
  // Faces turned away from the reference surface (their normal against the reference normal at
  // their centroid's projection by more than 60 degrees): folds the remeshing could not avoid.
  for (const FH f : m_.faces()) {
    std::array<Vec, 3> x;
    int k = 0;
    for (const VH w : m_.fv_range(f)) x[static_cast<std::size_t>(k++)] = m_.point(w);
    const Vec n = (x[1] - x[0]).cross(x[2] - x[0]);
    const Vec r = ref_.normal(ref_.project((x[0] + x[1] + x[2]) / 3));
    if (!(n.dot(r) > 0.5 * n.norm())) {
      if (rep_.folded_faces == 0) {
        std::ostringstream o;
        for (int i = 0; i < 3; ++i)
          o << (i ? " " : "") << "(" << x[static_cast<std::size_t>(i)].x() << ", " << x[static_cast<std::size_t>(i)].y()
            << ", " << x[static_cast<std::size_t>(i)].z() << ")";
        rep_.first_folded = o.str();
      }
      ++rep_.folded_faces;
    }
  }
  rep_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep_;
}

}  // namespace

RemeshReport remesh_surface(TriSurface& s, const ReferenceGeometry<3>& reference, const MetricField<3>& metric,
                            const RemeshOptions& options) {
  return Remesher(s, reference, metric, options).run();
}

}  // namespace plaf
