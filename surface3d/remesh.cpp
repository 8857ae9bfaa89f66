// SPDX-License-Identifier: MIT
// Metric-conforming surface remeshing (see remesh.h): the Remesher's operations (split,
// collapse, flip, tangential relaxation, sliver removal) and its rounds. What they measure
// (lengths, alignment, quality, face checks) is in remesher_measures.cpp.
#include "surface3d/remesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "modules/base/error.h"
#include "modules/base/parallel.h"
#include "surface3d/remesher.h"
#include "surface3d/validate.h"

namespace plaf {

namespace remesh_detail {

void Remesher::warm_vertices() {
  grow_caches();
  parallel_chunks(m_.n_vertices(), 512, [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const VH v(static_cast<int>(i));
      if (m_.status(v).deleted()) continue;
      if (!have_[i]) {
        vm_[i] = metric_.evaluate(m_.point(v)).matrix();
        have_[i] = 1;
      }
      // (as vertex_normal fills it)
      if (feature(v) == VertexFeature::Smooth && !m_.is_boundary(v) && !have_n_[i]) {
        vn_[i] = ref_.normal(m_.point(v));
        have_n_[i] = 1;
      }
    }
  });
}

void Remesher::warm_lengths() {
  warm_vertices();
  if (edge_lengths_.size() < m_.n_edges()) edge_lengths_.resize(m_.n_edges());
  parallel_chunks(m_.n_edges(), 512, [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const EH e(static_cast<int>(i));
      if (!m_.status(e).deleted()) length(e);  // fills edge_lengths_[i] only: the vertices are warm
    }
  });
}

void Remesher::split_long_edges() {
  // Repeated until no edge is long: a coarse start (an icosahedron for a fine metric) needs
  // several halvings; each pass splits the edges found long at its start, longest first.
  for (int pass = 0; pass < 40; ++pass) {
    warm_lengths();
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
    bool split_any = false;
    for (const auto& [l, e] : longs) {
      (void)l;
      if (m_.status(e).deleted()) continue;
      if (length(e) <= kSplitAbove) continue;  // an earlier split changed it
      split_any = try_split(e) || split_any;
    }
    // A pass that split nothing left the mesh as it was: the next would refuse the same edges
    // again (the long edges no split may halve, remesh.long_edges), and so would every other.
    if (!split_any) return;
  }
}

// Splits e at its midpoint projected onto the reference (onto its curve for a feature edge) unless
// that would fold one of its faces; the halves keep e's feature, curve and tag, the new faces their
// side's tag.
bool Remesher::try_split(EH e) {
  const HH h0 = m_.halfedge_handle(e, 0);
  const VH a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  const int c = curve(e);
  const Vec mid = 0.5 * (m_.point(a) + m_.point(b));
  const Vec p = c >= 0 ? ref_.project_to_curve(mid, c) : ref_.project(mid);
  if (!split_keeps_faces(h0, p)) {
    if (c < 0 && try_fan_cut(e)) return true;
    ++rep_.refused_splits;
    return false;
  }
  split_at(e, p);
  return true;
}

// A CAD fan: needles from one apex A to a curve sampled much finer than the rays are long (the
// published Orion's: rays 4.3 long to points 0.01-0.04 apart, edges of 150 in the metric left).
// Halving one ray leaves, in the needle on either side, a half as thin again (a cap over the
// ray), which split_keeps_faces refuses however long the ray is. Halving every ray of the fan at
// once cuts the fan across instead: each needle becomes a needle of half the length at the apex,
// and a strip of two triangles at the curve, each as good as halving allows. The rays are split
// one after another, in order around A: each split then connects its midpoint to the previous
// ray's, so the splits give exactly those faces (and the plain split of the faces at the fan's
// two ends); all of them are checked first, as split_keeps_faces checks a split.
bool Remesher::try_fan_cut(EH e) {
  if (is_feature(e)) return false;
  const auto narrow = [&](VH a, VH b, VH c) {  // face (a, b, c) a needle narrow at b - c
    const Vec pa = m_.point(a), pb = m_.point(b), pc = m_.point(c);
    return (pc - pb).norm() < 0.25 * std::min((pb - pa).norm(), (pc - pa).norm());
  };
  for (const HH h0 : {m_.halfedge_handle(e, 0), m_.halfedge_handle(e, 1)}) {
    const VH apex = m_.from_vertex_handle(h0);
    // The rays from the apex in counter-clockwise order: ray j + 1 follows ray j across the needle
    // on ray j's left, (apex, B_j, B_j+1).
    std::vector<HH> rays{h0};
    for (HH h = h0; rays.size() < 64;) {
      if (m_.is_boundary(h) || !narrow(apex, m_.to_vertex_handle(h), m_.to_vertex_handle(m_.next_halfedge_handle(h)))) break;
      const HH next = m_.opposite_halfedge_handle(m_.prev_halfedge_handle(h));
      if (next == h0 || is_feature(m_.edge_handle(next))) break;
      rays.push_back(next);
      h = next;
    }
    for (HH h = h0; rays.size() < 64;) {
      const HH o = m_.opposite_halfedge_handle(h);
      if (m_.is_boundary(o)) break;
      const HH prev = m_.next_halfedge_handle(o);  // apex -> the vertex before
      if (!narrow(apex, m_.to_vertex_handle(prev), m_.to_vertex_handle(h)) || prev == rays.back() ||
          is_feature(m_.edge_handle(prev)))
        break;
      rays.insert(rays.begin(), prev);
      h = prev;
    }
    if (rays.size() < 2) continue;
    // The midpoints, and every face before and after.
    const std::size_t k = rays.size();
    std::vector<Vec> p(k), np(k), b(k);
    for (std::size_t j = 0; j < k; ++j) {
      b[j] = m_.point(m_.to_vertex_handle(rays[j]));
      p[j] = ref_.project(0.5 * (m_.point(apex) + b[j]));
      np[j] = ref_.normal(p[j]);
    }
    const Vec a = m_.point(apex);
    const VH va = apex;
    struct Tri {
      std::array<Vec, 3> x;
      std::array<const Vec*, 3> n;
    };
    std::vector<std::pair<Tri, Tri>> changes;  // (a face before, one of its faces after)
    const auto vn = [&](VH v) { return vertex_normal(v); };
    for (std::size_t j = 0; j + 1 < k; ++j) {
      const VH bj = m_.to_vertex_handle(rays[j]), bn = m_.to_vertex_handle(rays[j + 1]);
      const Tri before{{a, b[j], b[j + 1]}, {vn(va), vn(bj), vn(bn)}};
      changes.push_back({before, {{a, p[j], p[j + 1]}, {vn(va), &np[j], &np[j + 1]}}});
      changes.push_back({before, {{p[j], b[j], b[j + 1]}, {&np[j], vn(bj), vn(bn)}}});
      changes.push_back({before, {{p[j], b[j + 1], p[j + 1]}, {&np[j], vn(bn), &np[j + 1]}}});
    }
    // The fan's end faces, split plainly: before the first ray, (B_0, apex, X); after the last,
    // (apex, B_k, Y).
    const HH o0 = m_.opposite_halfedge_handle(rays.front());
    if (!m_.is_boundary(o0)) {
      const VH b0 = m_.to_vertex_handle(rays.front()), x = m_.to_vertex_handle(m_.next_halfedge_handle(o0));
      const Tri before{{b[0], a, m_.point(x)}, {vn(b0), vn(va), vn(x)}};
      changes.push_back({before, {{b[0], p[0], m_.point(x)}, {vn(b0), &np[0], vn(x)}}});
      changes.push_back({before, {{p[0], a, m_.point(x)}, {&np[0], vn(va), vn(x)}}});
    }
    if (!m_.is_boundary(rays.back())) {
      const VH bk = m_.to_vertex_handle(rays.back()), y = m_.to_vertex_handle(m_.next_halfedge_handle(rays.back()));
      const Tri before{{a, b[k - 1], m_.point(y)}, {vn(va), vn(bk), vn(y)}};
      changes.push_back({before, {{a, p[k - 1], m_.point(y)}, {vn(va), &np[k - 1], vn(y)}}});
      changes.push_back({before, {{p[k - 1], b[k - 1], m_.point(y)}, {&np[k - 1], vn(bk), vn(y)}}});
    }
    bool ok = true;
    for (const auto& [old, now] : changes) {
      const Vec n = (old.x[1] - old.x[0]).cross(old.x[2] - old.x[0]);
      const Vec m = (now.x[1] - now.x[0]).cross(now.x[2] - now.x[0]);
      const double aligned = alignment(old.x[0], old.x[1], old.x[2], old.n[0], old.n[1], old.n[2]);
      ok = m.norm() > 1e-12 * n.norm() && m.dot(n) >= kMinNormalCos * m.norm() * n.norm() &&
           !degenerate(now.x[0], now.x[1], now.x[2]) &&
           acceptable(aligned, alignment(now.x[0], now.x[1], now.x[2], now.n[0], now.n[1], now.n[2]));
      if (!ok) break;
    }
    // The edges around the fan keep their bend: the cut moves the faces along them (the
    // midpoints lie on the reference, off the needles' planes), and a needle's short base on a
    // convex ridge must not come out bent the other way (a dent; and the features detected on the
    // final mesh would no longer be the kept ones), nor a smooth edge become a crease.
    const auto bend = [](const Vec& u, const Vec& w, const Vec& t, const Vec& o) {
      // (u, w, t) a face, o the far vertex across u - w: the angle between the faces' normals,
      // negative where the edge is concave.
      const Vec n1 = (w - u).cross(t - u), n2 = (u - w).cross(o - w);
      const double angle = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
      return n1.dot(o - u) <= 0 ? angle : -angle;
    };
    const auto keeps_bend = [&](HH h, const Vec& t_new) {  // h: u -> w in its old face
      if (m_.is_boundary(m_.opposite_halfedge_handle(h))) return true;
      const Vec u = m_.point(m_.from_vertex_handle(h)), w = m_.point(m_.to_vertex_handle(h));
      const Vec t_old = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h)));
      const Vec o = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(m_.opposite_halfedge_handle(h))));
      const double before = bend(u, w, t_old, o), after = bend(u, w, t_new, o);
      const EdgeFeature f = m_.property(s_.edge_feature, m_.edge_handle(h));
      if (f == EdgeFeature::ConvexRidge && before > 0 && after <= 0) return false;
      if (f == EdgeFeature::ConcaveRidge && before < 0 && after >= 0) return false;
      return std::abs(after) <= std::max(std::abs(before), kFanCutMaxBend);
    };
    for (std::size_t j = 0; ok && j + 1 < k; ++j) ok = keeps_bend(m_.next_halfedge_handle(rays[j]), p[j]);
    if (ok && !m_.is_boundary(o0)) {
      const HH ax = m_.next_halfedge_handle(o0);  // apex -> x, then x -> b0
      ok = keeps_bend(ax, p[0]) && keeps_bend(m_.next_halfedge_handle(ax), p[0]);
    }
    if (ok && !m_.is_boundary(rays.back())) {
      const HH by = m_.next_halfedge_handle(rays.back());  // b_k -> y, then y -> apex
      ok = keeps_bend(by, p[k - 1]) && keeps_bend(m_.next_halfedge_handle(by), p[k - 1]);
    }
    if (!ok) continue;
    std::vector<EH> edges;
    for (const HH h : rays) edges.push_back(m_.edge_handle(h));
    for (std::size_t j = 0; j < k; ++j) split_at(edges[j], p[j]);
    ++rep_.fan_cuts;
    return true;
  }
  return false;
}

void Remesher::split_at(EH e, const Vec& p) {
  const HH h0 = m_.halfedge_handle(e, 0);
  const VH a = m_.from_vertex_handle(h0), b = m_.to_vertex_handle(h0);
  const int c = curve(e);
  const int etag = m_.property(s_.edge_tag, e);
  const EdgeFeature ef = m_.property(s_.edge_feature, e);
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
}

bool Remesher::collapse_keeps_features(HH h) {
  const VH v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  const EH e = m_.edge_handle(h);
  if (is_fixed(v0)) return false;
  const int c0 = vertex_curve(v0);
  const bool v0_on_feature = c0 >= 0 || m_.is_boundary(v0);
  // A feature vertex moves only along its own curve; a smooth vertex anywhere.
  if (!untangling_ && v0_on_feature && (curve(e) < 0 || curve(e) != c0)) return false;
  if (!untangling_ && !v0_on_feature && is_feature(e)) return false;
  if (!m_.is_collapse_ok(h)) return false;
  if (untangling_) return true;
  // A curve vertex leaves its curve's polyline as the chord v1 - w from its other curve neighbour
  // w: refuse when that chord passes farther than a quarter of the metric size from it (it would
  // cut off a symmetry loop's leading-edge nose, which no projection of the new edge brings back).
  // The curve between them counts too, not only v0: its points along the two old edges
  // (projected onto the curve) against the new chord. A vertex that relaxation slid off a nose's
  // tip leaves the tip between two vertices, where v0's own offset misses it (measured: the
  // E387 wing's root nose cut back 0.013 over 8 rounds, surface.fidelity).
  if (v0_on_feature) {
    for (const HH hh : m_.voh_range(v0)) {
      const EH ee = m_.edge_handle(hh);
      if (ee == e || curve(ee) != curve(e)) continue;
      const Vec p0 = m_.point(v0), a = m_.point(v1), b = m_.point(m_.to_vertex_handle(hh));
      const double m = inverse_smallest_size(vertex_metric(v0));
      double gap = chord_gap(p0, a, b, m);
      for (const Vec& from : {a, b})
        for (double t : {0.25, 0.5, 0.75}) gap = std::max(gap, chord_gap(project_vertex(v0, from + t * (p0 - from)), a, b, m));
      if (gap > 0.25) return false;
    }
  }
  return true;
}

// The distance from x to the segment a - b over the smallest size (inv_size: its inverse, from
// inverse_smallest_size of the metric): a chord's sag lies
// along the surface's normal, where a surface metric keeps its coarse base size (curvature
// refines the tangential sizes only), so m's own length of it would let a chord cut a nose of
// the smallest size's scale (measured: the E387 wing's root nose cut back 0.013 at h_min 0.004).
double Remesher::chord_gap(const Vec& x, const Vec& a, const Vec& b, double inv_size) {
  const Vec ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - x).norm() * inv_size;
}

double Remesher::inverse_smallest_size(const Eigen::Matrix3d& m) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

// A curve vertex v moving to p (relaxation): the curve between its two curve neighbours (its
// points along the old edges, projected onto the curve) may not leave the new polyline
// w1 - p - w2 by more than a quarter of the smallest size, unless it already did (the collapse
// guard's measure): relaxation toward distant neighbours slid a nose's vertex 0.02 down the
// E387's lower surface in one round.
bool Remesher::curve_move_keeps_shape(VH v, const Vec& p) {
  const int c = vertex_curve(v);
  if (c < 0) return true;
  std::vector<Vec> w;
  for (const HH h : m_.voh_range(v))
    if (curve(m_.edge_handle(h)) == c) w.push_back(m_.point(m_.to_vertex_handle(h)));
  if (w.size() != 2) return true;
  const Vec p0 = m_.point(v);
  const double m = inverse_smallest_size(vertex_metric(v));
  double before = 0, after = 0;
  for (const Vec& from : w)
    for (double t : {0.25, 0.5, 0.75}) {
      const Vec x = project_vertex(v, from + t * (p0 - from));
      before = std::max(before, std::min(chord_gap(x, w[0], p0, m), chord_gap(x, p0, w[1], m)));
      after = std::max(after, std::min(chord_gap(x, w[0], p, m), chord_gap(x, p, w[1], m)));
    }
  return after <= std::max(0.25, before);
}

// The two faces of the collapsed edge disappear; their other edges merge pairwise. Features
// survive on the merged edge (repaired after the collapse), but two features merging would lose
// one.
bool Remesher::merged_edges(HH h, std::vector<MergedEdge>& merged) const {
  for (const HH hh : {h, m_.opposite_halfedge_handle(h)}) {
    if (m_.is_boundary(hh)) continue;
    const HH n = m_.next_halfedge_handle(hh), p = m_.prev_halfedge_handle(hh);
    const EH e1 = m_.edge_handle(n), e2 = m_.edge_handle(p);
    const bool f1 = is_feature(e1), f2 = is_feature(e2);
    if (f1 && f2 && !untangling_) return false;
    const EH keep = f1 ? e1 : e2;
    merged.push_back(
        {m_.to_vertex_handle(n), curve(keep), m_.property(s_.edge_tag, keep), m_.property(s_.edge_feature, keep)});
  }
  return true;
}

// (An edge already longer than the limit may stay as long: merging two nearly coincident
// vertices must not be refused for an edge it does not lengthen.)
bool Remesher::collapse_keeps_lengths(VH v0, VH v1, double max_length) {
  const Vec target = m_.point(v1);
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
  return true;
}

// Collapses h's from-vertex into its to-vertex if that keeps topology, features, lengths and
// orientation.
bool Remesher::try_collapse(HH h, double max_length) {
  const VH v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
  if (!collapse_keeps_features(h)) return false;
  std::vector<MergedEdge> merged;
  if (!merged_edges(h, merged)) return false;
  // New edges v1 - (neighbours of v0) must not be long.
  if (!collapse_keeps_lengths(v0, v1, max_length)) return false;
  const FH fl = m_.is_boundary(h) ? FH() : m_.face_handle(h);
  const HH o = m_.opposite_halfedge_handle(h);
  const FH fr = m_.is_boundary(o) ? FH() : m_.face_handle(o);
  if (!move_keeps_faces(v0, m_.point(v1), fl, fr)) return false;
  m_.collapse(h);
  for (const MergedEdge& kept : merged) {
    const HH nh = m_.find_halfedge(v1, kept.far);
    if (!nh.is_valid()) continue;
    const EH ne = m_.edge_handle(nh);
    m_.property(s_.edge_curve, ne) = kept.curve;
    m_.property(s_.edge_tag, ne) = kept.tag;
    m_.property(s_.edge_feature, ne) = kept.feature;
  }
  ++rep_.collapses;
  return true;
}

void Remesher::collapse_short_edges() {
  warm_lengths();
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
    // By index over the faces at the pass's start: a fold's split adds faces as the pass goes,
    // and OpenMesh's face range then reads past the face properties (a segfault on the published
    // BWB surface when caps were split here, in an experiment).
    const int faces = static_cast<int>(m_.n_faces());
    for (int fi = 0; fi < faces; ++fi) {
      const FH f(fi);
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

// After the sliver passes: the faces that cross others. Every operation checks the faces it
// changes against the reference's normal, not against faces elsewhere, so a fold that keeps
// every face aligned goes unseen: two feature curves closer than the size, each sampled at the
// size, cross where the band between them is thinner than their chords' sag (measured on the
// published Orion capsule before features.cpp's inverted faces: two curves 3 degrees apart from
// one corner, 50 crossing pairs at a uniform size of 0.3, every face aligned within 3 degrees). Rounds
// of: the crossing pairs found (validate.h's test), then the edges of their faces collapsed,
// shortest first, with the feature rules relaxed (a band narrower than the size closes, two
// feature curves along it merge into one) and the orientation checks kept; at most
// kUntangleRounds rounds, while a round collapses something. What is left is counted
// (crossing_pairs, first_crossing) and the surface stage refuses it. Not in Botsch and
// Kobbelt's remeshing (one smooth sheet); a surface that crosses itself is no mesh, and a band
// thinner than the size is below what the sizes resolve, so closing it is the robust choice.
void Remesher::untangle() {
  for (int round = 0;; ++round) {
    m_.garbage_collection();
    vm_.clear();  // the collection renumbered the vertices
    have_.clear();
    vn_.clear();
    have_n_.clear();
    edge_lengths_.clear();
    grow_caches();
    const std::vector<std::pair<int, int>> pairs = self_intersecting_pairs(s_);
    if (round == 0) rep_.crossing_pairs_found = pairs.size();
    rep_.crossing_pairs = pairs.size();
    rep_.first_crossing.clear();
    rep_.crossing_points.clear();
    if (pairs.empty()) return;
    Vec at = Vec::Zero();
    for (const VH v : m_.fv_range(m_.face_handle(pairs.front().first))) at += m_.point(v) / 3;
    std::ostringstream o;
    o << "(" << at.x() << ", " << at.y() << ", " << at.z() << ")";
    rep_.first_crossing = o.str();
    for (const auto& [a, b] : pairs)
      for (const int fi : {a, b}) {
        Vec c = Vec::Zero();
        for (const VH v : m_.fv_range(m_.face_handle(fi))) c += m_.point(v) / 3;
        rep_.crossing_points.push_back(c);
      }
    if (round == kUntangleRounds) return;
    std::vector<FH> faces;
    for (const auto& [a, b] : pairs) faces.push_back(m_.face_handle(a)), faces.push_back(m_.face_handle(b));
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    std::vector<std::pair<double, HH>> edges;
    for (const FH f : faces)
      for (const HH h : m_.fh_range(f)) edges.emplace_back(length(m_.edge_handle(h)), h);
    std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    std::size_t collapses = 0;
    untangling_ = true;
    for (const auto& [l, h] : edges) {
      (void)l;
      if (m_.status(m_.edge_handle(h)).deleted()) continue;
      if (try_collapse(h, kUntangleLength) || try_collapse(m_.opposite_halfedge_handle(h), kUntangleLength))
        ++collapses;
    }
    untangling_ = false;
    rep_.untangle_collapses += collapses;
    if (collapses == 0) return;
  }
}

void Remesher::relax() {
  // Tangential relaxation: every free vertex moves halfway toward the density-weighted centroid of
  // its neighbours, within its tangent plane (or along its curve), then back onto the reference.
  std::vector<Vec> target(m_.n_vertices());
  std::vector<char> moves(m_.n_vertices(), 0);
  // The targets from the positions before any move (a Jacobi step): on the worker threads, the
  // vertices' metrics and normals warm.
  warm_vertices();
  parallel_chunks(m_.n_vertices(), 512, [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const VH v(static_cast<int>(i));
      if (!m_.status(v).deleted()) relax_target(v, target, moves);
    }
  });
  // The moved positions on the reference (a function of each target alone), on the worker
  // threads too; then the moves one by one, each checked against its neighbours as they stand.
  std::vector<Vec> projected(m_.n_vertices()), projected_normal(m_.n_vertices());
  parallel_chunks(m_.n_vertices(), 512, [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!moves[i]) continue;
      const VH v(static_cast<int>(i));
      if (feature(v) == VertexFeature::Smooth && !m_.is_boundary(v))
        projected[i] = ref_.project(target[i], projected_normal[i]);
      else
        projected[i] = project_vertex(v, target[i]);
    }
  });
  for (const VH v : m_.vertices()) {
    if (!moves[static_cast<std::size_t>(v.idx())]) continue;
    // A smooth vertex is projected with its normal in one search, and keeps that normal cached.
    const bool smooth = vertex_normal(v) != nullptr;
    const Vec& p = projected[static_cast<std::size_t>(v.idx())];
    const Vec& n = projected_normal[static_cast<std::size_t>(v.idx())];
    if (!smooth && !curve_move_keeps_shape(v, p)) continue;
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

// Relaxation's target for v (relax): halfway toward the density-weighted centroid of its
// neighbours, in its tangent plane or along its curve; moves[v] set when it has one. Reads only
// (the metrics and normals warm).
void Remesher::relax_target(VH v, std::vector<Vec>& target, std::vector<char>& moves) {
  if (is_fixed(v)) return;
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
  if (wsum <= 0) return;
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

void Remesher::measure_result() {
  std::size_t unit = 0, total = 0;
  EH longest;
  for (const EH e : m_.edges()) {
    const double l = length(e);
    ++total;
    if (l >= 1 / std::sqrt(2.0) && l <= std::sqrt(2.0)) ++unit;
    if (l > kLongEdge) ++rep_.long_edges;
    if (l > rep_.longest) {
      rep_.longest = l;
      longest = e;
    }
  }
  if (longest.is_valid()) {
    const HH h = m_.halfedge_handle(longest, 0);
    const Vec mid = 0.5 * (m_.point(m_.from_vertex_handle(h)) + m_.point(m_.to_vertex_handle(h)));
    std::ostringstream o;
    o << "(" << mid.x() << ", " << mid.y() << ", " << mid.z() << ")";
    rep_.first_long = o.str();
  }
  rep_.unit_fraction = total ? static_cast<double>(unit) / static_cast<double>(total) : 0;
  for (const FH f : m_.faces())
    if (is_cap(f)) ++rep_.caps;
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
        rep_.first_folded_centroid = (x[0] + x[1] + x[2]) / 3;
        rep_.first_folded_size = std::max({(x[1] - x[0]).norm(), (x[2] - x[1]).norm(), (x[0] - x[2]).norm()});
      }
      ++rep_.folded_faces;
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
    if (opt_.on_round) opt_.on_round(round + 1, opt_.iterations);
    // Converged: a round that split and collapsed nothing and flipped under 0.5 % of the edges
    // only relaxes further; the rounds stop (the final passes still run).
    if (rep_.splits + rep_.collapses == changes && rep_.flips - flips < m_.n_edges() / 200) break;
  }
  // The final passes judge every face by its centroid's projection, as the fold count does.
  precise_ = true;
  remove_slivers();
  relax();
  remove_slivers();
  untangle();  // (ends on a collected mesh, its caches renumbered)
  rep_.faces_after = m_.n_faces();
  measure_result();
  rep_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep_;
}

}  // namespace remesh_detail

RemeshReport remesh_surface(TriSurface& s, const ReferenceGeometry<3>& reference, const MetricField<3>& metric,
                            const RemeshOptions& options) {
  return remesh_detail::Remesher(s, reference, metric, options).run();
}

}  // namespace plaf
