// SPDX-License-Identifier: MIT
// CAD slivers repaired (see slivers.h): needles' short edges collapsed, caps' long edges flipped,
// every operation checked against the faces it changes.
#include "surface3d/slivers.h"

#include "modules/geometry/aabb_tree.h"
#include "surface3d/features.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>
#include <utility>
#include <vector>

namespace plaf {

namespace {

using Vec = Eigen::Vector3d;
using VH = TriMesh::VertexHandle;
using HH = TriMesh::HalfedgeHandle;
using EH = TriMesh::EdgeHandle;
using FH = TriMesh::FaceHandle;

// A face that keeps its shape turns by at most 20 degrees; a sliver's normal (noise) must stay
// within 60 degrees of the good faces around it.
const double kTurnCos = std::cos(20.0 * M_PI / 180.0);
constexpr double kNoiseCos = 0.5;
// A sliver in the sheet: within 60 degrees of a good face around its corners.
const double kSheetCos = std::cos(60.0 * M_PI / 180.0);
// A needle: its shortest edge under this share of its longest.
constexpr double kNeedleShare = 0.2;
constexpr int kPasses = 10;

class SliverRepair {
 public:
  SliverRepair(TriSurface& s, double max_ratio, double max_move_rel) : m_(s.mesh), max_ratio_(max_ratio) {
    Eigen::AlignedBox3d box;
    for (const VH v : m_.vertices()) box.extend(m_.point(v));
    max_move_ = box.isEmpty() ? 0 : max_move_rel * box.diagonal().norm();
  }

  SliverRepairReport run() {
    SliverRepairReport rep;
    for (int pass = 0; pass < kPasses; ++pass) {
      std::vector<std::pair<double, FH>> thin = slivers();
      inverted_ = inverted_faces(m_);  // (the pass's faces keep their indices: no collection before the end)
      if (pass == 0) rep.found = thin.size();
      std::size_t changed = 0;
      for (const auto& [r0, f] : thin) {
        (void)r0;
        if (m_.status(f).deleted() || ratio(f) >= max_ratio_) continue;
        double moved = 0;
        if (repair(f, rep, moved)) {
          ++changed;
          rep.max_moved = std::max(rep.max_moved, moved);
        }
      }
      if (changed == 0) break;
    }
    rep.left = slivers().size();
    if (rep.collapsed > 0) m_.garbage_collection();
    return rep;
  }

 private:
  std::array<Vec, 3> corners(FH f) const {
    std::array<Vec, 3> x;
    std::size_t k = 0;
    for (const VH v : m_.fv_range(f)) x[k++] = m_.point(v);
    return x;
  }
  Vec normal(FH f) const {
    const std::array<Vec, 3> x = corners(f);
    return (x[1] - x[0]).cross(x[2] - x[0]);
  }
  double ratio(FH f) const {
    const std::array<Vec, 3> x = corners(f);
    return sliver_ratio(x[0], x[1], x[2]);
  }

  // The faces under max_ratio, the thinnest first.
  std::vector<std::pair<double, FH>> slivers() const {
    std::vector<std::pair<double, FH>> thin;
    for (const FH f : m_.faces()) {
      const double r = ratio(f);
      if (r < max_ratio_) thin.emplace_back(r, f);
    }
    std::sort(thin.begin(), thin.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return thin;
  }

  // The good faces' area-weighted normal around v0 and v1: the direction the slivers' normals
  // are judged against.
  Vec good_normal(VH v0, VH v1) const {
    Vec n = Vec::Zero();
    for (const VH v : {v0, v1})
      for (const FH f : m_.vf_range(v))
        if (ratio(f) >= max_ratio_) n += normal(f);
    return n;
  }

  // A changed face (normal `before`, ratio `rb`) becoming (normal `after`, ratio `ra`): no
  // thinner than it was or max_ratio, a good face turned by at most 20 degrees, a sliver within
  // 60 degrees of `good`. Lowers *worst to the good face's turn cosine.
  bool face_ok(const Vec& before, double rb, const Vec& after, double ra, const Vec& good, double* worst) const {
    if (ra < std::min(rb, max_ratio_)) return false;
    const double na = after.norm();
    if (!(na > 0)) return false;
    if (rb >= max_ratio_) {
      const double c = after.dot(before) / (na * before.norm());
      if (!(c >= kTurnCos)) return false;
      *worst = std::min(*worst, c);
      return true;
    }
    const Vec& ref = good.squaredNorm() > 0 ? good : before;
    return ref.squaredNorm() > 0 && after.dot(ref) >= kNoiseCos * na * ref.norm();
  }

  // Collapsing h's from-vertex into its to-vertex: whether it keeps every face (face_ok), with
  // the worst turn cosine of the good faces in *worst and in *moved how far the surface moves:
  // the distance from the old vertex to the new faces around it (a vertex on a straight line
  // between its neighbours, as in a collinear needle, leaves the surface where it was).
  bool collapse_ok(HH h, double* worst, double* moved) const {
    const VH v0 = m_.from_vertex_handle(h), v1 = m_.to_vertex_handle(h);
    if (m_.is_boundary(v0) || !m_.is_collapse_ok(h)) return false;
    const FH fl = m_.face_handle(h), fr = m_.face_handle(m_.opposite_halfedge_handle(h));
    const Vec good = good_normal(v0, v1), p = m_.point(v1);
    *worst = 1;
    *moved = (p - m_.point(v0)).norm();
    for (const FH f : m_.vf_range(v0)) {
      if (f == fl || f == fr) continue;
      std::array<Vec, 3> x;
      std::size_t k = 0;
      for (const VH w : m_.fv_range(f)) x[k++] = w == v0 ? p : m_.point(w);
      const Vec after = (x[1] - x[0]).cross(x[2] - x[0]);
      if (!face_ok(normal(f), ratio(f), after, sliver_ratio(x[0], x[1], x[2]), good, worst)) return false;
      *moved = std::min(*moved, (closest_point_on_triangle(m_.point(v0), x[0], x[1], x[2]) - m_.point(v0)).norm());
    }
    return *moved <= max_move_;
  }

  // Flipping e: both new faces better than the worse old one and each face_ok against the old
  // face it lies over; *moved: the sliver's height over e, how far the surface moves.
  bool flip_ok(EH e, double* moved) const {
    if (m_.is_boundary(e) || !m_.is_flip_ok(e)) return false;
    const HH h = m_.halfedge_handle(e, 0), o = m_.opposite_halfedge_handle(h);
    const Vec a = m_.point(m_.from_vertex_handle(h)), b = m_.point(m_.to_vertex_handle(h));
    const Vec c = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h)));
    const Vec d = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(o)));
    // Before: (a, b, c) and (b, a, d); after, counter-clockwise: (a, d, c) and (b, c, d).
    const Vec n1 = (b - a).cross(c - a), n2 = (a - b).cross(d - b);
    const double r1 = sliver_ratio(a, b, c), r2 = sliver_ratio(b, a, d);
    const Vec m1 = (d - a).cross(c - a), m2 = (c - b).cross(d - b);
    const double s1 = sliver_ratio(a, d, c), s2 = sliver_ratio(b, c, d);
    if (!(std::min(s1, s2) > std::min(r1, r2))) return false;
    // Each new face lies over the old good one (or both old faces when neither is good).
    const Vec good = (r1 >= max_ratio_ ? n1 : Vec::Zero()) + (r2 >= max_ratio_ ? n2 : Vec::Zero());
    const Vec ref = good.squaredNorm() > 0 ? good : Vec(n1 + n2);
    const double rref = good.squaredNorm() > 0 ? max_ratio_ : std::min(r1, r2);
    double worst = 1;
    if (!face_ok(ref, rref, m1, s1, ref, &worst) || !face_ok(ref, rref, m2, s2, ref, &worst)) return false;
    const double ab = (b - a).norm();
    *moved = ab > 0 ? std::min(n1.norm(), n2.norm()) / ab : 0;
    return *moved <= max_move_;
  }

  // Whether sliver f lies in the sheet: within 60 degrees of a good face (not a sliver) around
  // its corners. A CAD needle or cap does (the Orion's: 330 of 349, 303 within 5 degrees; its
  // longest, 6.3 long and 0.022 wide, twists 40 degrees out of the cone it lies on); a narrow
  // face of the body's own between sharp edges (a blunt trailing edge's base on a long wing,
  // 80-100 degrees from the faces beside it, a step) does not, and is left as it is. (A chamfer
  // under 60 degrees that narrow is smoothed, by at most its width: the remesher could keep it
  // only as a strip of slivers.)
  bool in_sheet(FH f) const {
    const Vec n = normal(f);
    if (!(n.squaredNorm() > 0)) return false;
    for (const VH v : m_.fv_range(f))
      for (const FH g : m_.vf_range(v)) {
        if (g == f || ratio(g) < max_ratio_) continue;
        const Vec b = normal(g);
        if (n.dot(b) >= kSheetCos * n.norm() * b.norm()) return true;
      }
    return false;
  }

  bool repair(FH f, SliverRepairReport& rep, double& moved) {
    std::array<HH, 3> hs;
    std::size_t k = 0;
    for (const HH h : m_.fh_range(f)) hs[k++] = h;
    std::array<double, 3> l;
    for (std::size_t i = 0; i < 3; ++i) l[i] = m_.calc_edge_length(hs[i]);
    const std::size_t shortest = static_cast<std::size_t>(std::min_element(l.begin(), l.end()) - l.begin());
    const std::size_t longest = static_cast<std::size_t>(std::max_element(l.begin(), l.end()) - l.begin());
    // Or folded back over the sheet: features.h's inverted faces (the Orion has a needle 4.3 long
    // and 0.016 wide at 121 degrees to the cone it lies in), a fold of the triangulation that the
    // repair unfolds.
    if (!in_sheet(f) && !inverted_[static_cast<std::size_t>(f.idx())]) return false;
    if (l[shortest] < kNeedleShare * l[longest]) {
      // The end that moves the surface least stays.
      const HH h = hs[shortest], o = m_.opposite_halfedge_handle(h);
      double wh = -2, wo = -2, mh = 0, mo = 0;
      const bool ok_h = collapse_ok(h, &wh, &mh), ok_o = collapse_ok(o, &wo, &mo);
      if (ok_h || ok_o) {
        // (the one that moves the surface less, then the one that turns the good faces less)
        const bool use_h = ok_h && (!ok_o || mh < mo || (mh == mo && wh >= wo));
        m_.collapse(use_h ? h : o);
        ++rep.collapsed;
        moved = use_h ? mh : mo;
        return true;
      }
    }
    const EH e = m_.edge_handle(hs[longest]);
    if (!flip_ok(e, &moved)) return false;
    m_.flip(e);
    ++rep.flipped;
    return true;
  }

  TriMesh& m_;
  double max_ratio_;
  double max_move_ = 0;
  std::vector<char> inverted_;  // per face at the pass's start (features.h)
};

}  // namespace

double sliver_ratio(const Vec& a, const Vec& b, const Vec& c) {
  const double l2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return l2 > 0 ? (b - a).cross(c - a).norm() / l2 : 0;
}

SliverRepairReport repair_slivers(TriSurface& s, double max_ratio, double max_move_rel) {
  return SliverRepair(s, max_ratio, max_move_rel).run();
}

std::size_t count_slivers(const TriSurface& s, double max_ratio) {
  std::size_t n = 0;
  for (const FH f : s.mesh.faces()) {
    const auto x = s.face_vertices(f);
    if (sliver_ratio(s.mesh.point(x[0]), s.mesh.point(x[1]), s.mesh.point(x[2])) < max_ratio) ++n;
  }
  return n;
}

}  // namespace plaf
