// SPDX-License-Identifier: MIT
// The Remesher's measurements (see remesher.h): metric edge lengths (along curves and around
// tight turns), feature bookkeeping, and the face checks every operation passes (turning,
// degeneracy, alignment with the reference, metric shape quality).
#include <Eigen/Cholesky>

#include "surface3d/remesher.h"

namespace plaf::remesh_detail {

void Remesher::grow_caches() {
  const std::size_t n = m_.n_vertices();
  vm_.resize(n, Eigen::Matrix3d::Zero());
  have_.resize(n, 0);
  vn_.resize(n, Vec::Zero());
  have_n_.resize(n, 0);
}

double Remesher::curve_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b, const Eigen::Matrix3d& mb,
                              int c) const {
  const Vec m = ref_.project_to_curve(0.5 * (a + b), c);
  const Vec d1 = m - a, d2 = b - m;
  return root(d1.dot(ma * d1)) + root(d2.dot(mb * d2));
}

double Remesher::wrapped_length(const Vec& a, const Eigen::Matrix3d& ma, const Vec& b,
                                const Eigen::Matrix3d& mb) const {
  const Vec m = ref_.project(0.5 * (a + b));
  const Eigen::Matrix3d mm = metric_.evaluate(m).matrix();
  const Vec d1 = m - a, d2 = b - m;
  return 0.5 * (root(d1.dot(ma * d1)) + root(d1.dot(mm * d1))) + 0.5 * (root(d2.dot(mm * d2)) + root(d2.dot(mb * d2)));
}

bool Remesher::wraps(const Vec& pa, const Vec* na, VH b) {
  const Vec* nb = vertex_normal(b);
  if (na && nb) return na->dot(*nb) < 0.5;
  const Vec mid = 0.5 * (pa + m_.point(b));
  return (ref_.project(mid) - mid).norm() > 0.25 * (m_.point(b) - pa).norm();
}

double Remesher::length(EH e) {
  const HH h = m_.halfedge_handle(e, 0);
  const VH a = m_.from_vertex_handle(h), b = m_.to_vertex_handle(h);
  const int c = curve(e);
  const Vec *na = vertex_normal(a), *nb = vertex_normal(b);
  // The length is a function of what the cache entry records (the metric and the reference are
  // fixed for the remesher's life): an unchanged entry is the same length.
  const std::size_t i = static_cast<std::size_t>(e.idx());
  if (i >= edge_lengths_.size()) edge_lengths_.resize(std::max<std::size_t>(i + 1, m_.n_edges()));
  EdgeLength& k = edge_lengths_[i];
  if (k.curve == c && k.normal_a == (na != nullptr) && k.normal_b == (nb != nullptr) && k.a == m_.point(a) && k.b == m_.point(b))
    return k.length;
  const double chord = length(a, b);
  double l = chord;
  if (c >= 0)
    l = std::max(chord, curve_length(m_.point(a), vertex_metric(a), m_.point(b), vertex_metric(b), c));
  else if (wraps(m_.point(a), na, b))
    l = std::max(chord, wrapped_length(m_.point(a), vertex_metric(a), m_.point(b), vertex_metric(b)));
  k = {m_.point(a), m_.point(b), c, na != nullptr, nb != nullptr, l};
  return l;
}

int Remesher::vertex_curve(VH v) const {
  for (const HH h : m_.voh_range(v)) {
    const int c = curve(m_.edge_handle(h));
    if (c >= 0) return c;
  }
  return -1;
}

bool Remesher::is_fixed(VH v) const {
  if (is_corner(feature(v))) return true;
  if (feature(v) == VertexFeature::Curve) return vertex_curve(v) < 0;
  for (const HH h : m_.voh_range(v))
    if (is_feature(m_.edge_handle(h))) return vertex_curve(v) < 0;
  return false;
}

std::array<Vec, 3> Remesher::corners_with(FH f, VH v, const Vec& p) const {
  std::array<Vec, 3> x;
  int k = 0;
  for (const VH w : m_.fv_range(f)) x[static_cast<std::size_t>(k++)] = w == v ? p : m_.point(w);
  return x;
}

double Remesher::alignment(const Vec& a, const Vec& b, const Vec& c, const Vec* na, const Vec* nb,
                           const Vec* nc) const {
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

double Remesher::alignment_with(FH f, VH v, const Vec& p, const Vec* np) {
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

bool Remesher::move_keeps_faces(VH v, const Vec& p, FH skip0, FH skip1, const Vec* known_normal) {
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

bool Remesher::mean_metric_factor(VH a, VH b, VH c, Eigen::Matrix3d& u) {
  const Eigen::LLT<Eigen::Matrix3d> llt((vertex_metric(a) + vertex_metric(b) + vertex_metric(c)) / 3);
  if (llt.info() != Eigen::Success) return false;
  u = llt.matrixU();  // M = U^T U: |U v| is the metric length of v
  return true;
}

double Remesher::quality(VH a, VH b, VH c) {
  Eigen::Matrix3d lt;
  if (!mean_metric_factor(a, b, c, lt)) return 0;
  const Vec pa = m_.point(a), pb = m_.point(b), pc = m_.point(c);
  const Vec u = lt * (pb - pa), w = lt * (pc - pa), z = lt * (pc - pb);
  const double area = 0.5 * u.cross(w).norm();
  const double sum = u.squaredNorm() + w.squaredNorm() + z.squaredNorm();
  return sum > 0 ? 4 * std::sqrt(3.0) * area / sum : 0;
}

bool Remesher::is_cap(FH f) {
  std::array<VH, 3> v;
  int k = 0;
  for (const VH w : m_.fv_range(f)) v[static_cast<std::size_t>(k++)] = w;
  Eigen::Matrix3d lt;
  if (!mean_metric_factor(v[0], v[1], v[2], lt)) return false;
  const double cos_cap = std::cos(160.0 * M_PI / 180.0);
  for (std::size_t i = 0; i < 3; ++i) {  // the angle at v[i]
    const Vec u = lt * (m_.point(v[(i + 1) % 3]) - m_.point(v[i])), w = lt * (m_.point(v[(i + 2) % 3]) - m_.point(v[i]));
    const double nu = u.norm(), nw = w.norm();
    if (nu > 0 && nw > 0 && u.dot(w) < cos_cap * nu * nw) return true;
  }
  return false;
}

bool Remesher::split_keeps_faces(HH h, const Vec& p) {
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

}  // namespace plaf::remesh_detail
