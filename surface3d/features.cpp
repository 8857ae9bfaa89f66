// SPDX-License-Identifier: MIT
// Feature detection on a TriSurface (paper Sec. II.E: corners and edges "obtained by measuring
// changes in the normal across surface elements"). Three linear passes:
//   1. edges: boundary, or ridge when the angle between the two face normals exceeds the
//      threshold, convex or concave by the exact orient3d of one face and the other's far vertex;
//   2. vertices: their feature edges (count, kinds, the turn between two) and angle defect decide
//      Curve or a corner, classified by its ridges;
//   3. curves: each chain of feature edges is walked from a corner to the next corner; what is
//      left are closed loops without corners.
// Every pass visits each element (or each vertex's two stored feature halfedges) a bounded number
// of times, so the whole detection is O(V + E + F).
#include "surface3d/features.h"

#include <functional>
#include <map>
#include <set>
#include <memory>

#include "modules/geometry/aabb_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"

namespace plaf {

namespace {

using EdgeHandle = TriMesh::EdgeHandle;
using FaceHandle = TriMesh::FaceHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;
using VertexHandle = TriMesh::VertexHandle;

constexpr double kPi = 3.14159265358979323846;

double radians(double deg) {
  return deg * kPi / 180.0;
}

std::size_t idx(int i) {
  return static_cast<std::size_t>(i);
}

// Angle between a and b in [0, pi]. atan2 of |a x b| and a.b stays accurate near 0 and pi, where
// acos of a normalised dot product loses half the digits; a zero vector gives 0.
double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// The departure from flat of interior edge e: the angle between its faces' normals.
double dihedral_departure(const TriMesh& m, EdgeHandle e) {
  const HalfedgeHandle h = m.halfedge_handle(e, 0);
  const Eigen::Vector3d& a = m.point(m.from_vertex_handle(h));
  const Eigen::Vector3d& b = m.point(m.to_vertex_handle(h));
  const Eigen::Vector3d& c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
  const Eigen::Vector3d& d = m.point(m.to_vertex_handle(m.next_halfedge_handle(m.opposite_halfedge_handle(h))));
  // Face (a, b, c) and face (b, a, d), both counter-clockwise seen from outside.
  return angle_between((b - a).cross(c - a), (a - b).cross(d - b));
}

}  // namespace

// Per face: inverted, a fold of the triangulation rather than of the body. Its normal is more than
// 90 degrees from those of the faces across two or three of its edges, and those agree with each
// other (within 90 degrees): it lies back to back with the sheet on both sides. A body cannot do
// that (a knife edge's face is back to back with one neighbour, across the edge, not two), but a
// CAD tessellation can: the published Orion capsule has a fan of 6-long needles in a plane whose
// far ends double back, one needle 0.003 wide inverted between its neighbours; its two long
// edges were taken for a convex and a concave ridge 3 degrees apart, two feature curves the
// remesher sampled each at the size and whose chords then crossed (50 crossing pairs at a size
// of 0.25). Its edges are no ridges (classify_edges), and it counts for nothing in the discrete
// reference's vertex normals (discrete_reference.cpp): its normal says nothing of the body's.
std::vector<char> inverted_faces(const TriMesh& m) {
  std::vector<char> out(m.n_faces(), 0);
  auto normal = [&](FaceHandle f) {
    const HalfedgeHandle h = m.halfedge_handle(f);
    const Eigen::Vector3d& a = m.point(m.from_vertex_handle(h));
    const Eigen::Vector3d& b = m.point(m.to_vertex_handle(h));
    const Eigen::Vector3d& c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
    return Eigen::Vector3d((b - a).cross(c - a));
  };
  for (const FaceHandle f : m.faces()) {
    const Eigen::Vector3d n = normal(f);
    std::vector<Eigen::Vector3d> opposite;
    for (const HalfedgeHandle h : m.fh_range(f)) {
      const HalfedgeHandle o = m.opposite_halfedge_handle(h);
      if (m.is_boundary(o)) continue;
      const Eigen::Vector3d g = normal(m.face_handle(o));
      if (n.dot(g) < 0) opposite.push_back(g);
    }
    bool agree = opposite.size() >= 2;
    for (std::size_t i = 0; agree && i < opposite.size(); ++i)
      for (std::size_t j = i + 1; j < opposite.size(); ++j) agree = agree && opposite[i].dot(opposite[j]) > 0;
    out[idx(f.idx())] = agree ? 1 : 0;
  }
  return out;
}

namespace {

// Convex or concave, exactly, for interior edge e.
EdgeFeature ridge_kind(const TriMesh& m, EdgeHandle e) {
  const HalfedgeHandle h = m.halfedge_handle(e, 0);
  const Eigen::Vector3d& a = m.point(m.from_vertex_handle(h));
  const Eigen::Vector3d& b = m.point(m.to_vertex_handle(h));
  const Eigen::Vector3d& c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
  const Eigen::Vector3d& d = m.point(m.to_vertex_handle(m.next_halfedge_handle(m.opposite_halfedge_handle(h))));
  // (a, b, c) is counter-clockwise seen from outside, so orient3d > 0 puts d below its plane, inside
  // the body: the body is locally convex there. Coplanar (0) with a departure above the threshold
  // is a fold back onto itself (a zero-thickness blade edge), which the body wraps around: convex.
  return sign_orient3d(a, b, c, d) >= 0 ? EdgeFeature::ConvexRidge : EdgeFeature::ConcaveRidge;
}

// Per edge: the reference's feature curve it runs along, or -1 (FeatureOptions::reference). Each
// vertex is tested against every curve once; an edge only against the curves both its ends are
// on.
std::vector<int> body_curves(const TriMesh& m, const ReferenceGeometry<3>& ref) {
  const double tol = 1e-6 * ref.scale();
  std::vector<std::vector<int>> curves_at(m.n_vertices());
  for (const VertexHandle v : m.vertices()) {
    const Eigen::Vector3d x = m.point(v);
    for (int c = 0; c < ref.num_curves(); ++c)
      if ((ref.project_to_curve(x, c) - x).norm() <= tol) curves_at[idx(v.idx())].push_back(c);
  }
  std::vector<int> along(m.n_edges(), -1);
  for (const EdgeHandle e : m.edges()) {
    const HalfedgeHandle h = m.halfedge_handle(e, 0);
    const VertexHandle a = m.from_vertex_handle(h), b = m.to_vertex_handle(h);
    const Eigen::Vector3d mid = 0.5 * (m.point(a) + m.point(b));
    const double len = (m.point(b) - m.point(a)).norm();
    const auto& cb = curves_at[idx(b.idx())];
    // (Not a chord over another vertex of the curve: a flat triangle with three vertices on a
    // feature has one edge that skips the middle one.)
    const auto skips = [&](int c) {
      for (int i = 0; i < 2; ++i) {
        const HalfedgeHandle hi = m.halfedge_handle(e, static_cast<unsigned>(i));
        if (m.is_boundary(hi)) continue;
        const VertexHandle o = m.to_vertex_handle(m.next_halfedge_handle(hi));
        const auto& co = curves_at[idx(o.idx())];
        if (std::find(co.begin(), co.end(), c) != co.end() && (m.point(o) - mid).norm() < 0.5 * len) return true;
      }
      return false;
    };
    for (int c : curves_at[idx(a.idx())])
      if (std::find(cb.begin(), cb.end(), c) != cb.end() && (ref.project_to_curve(mid, c) - mid).norm() <= 0.25 * len + tol &&
          !skips(c)) {
        along[static_cast<std::size_t>(e.idx())] = c;
        break;
      }
  }
  return along;
}

// The kind of a ridge judged on the reference where the mesh's faces meet nearly flat (within the
// ridge angle; a clear bend is classified exactly from the mesh, ridge_kind): convex when the
// body's normal, from the closest point of one face's centroid to the other's, turns the way one
// travels ((p1 - p0).(n1 - n0) >= 0, as on a sphere), so a nearly flat stretch of a mesh along a
// convex crest is not called concave.
EdgeFeature body_ridge_kind(const TriMesh& m, EdgeHandle e, const ReferenceGeometry<3>& ref) {
  Eigen::Vector3d p[2], n[2];
  for (int i = 0; i < 2; ++i) {
    const FaceHandle f = m.face_handle(m.halfedge_handle(e, static_cast<unsigned>(i)));
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const VertexHandle v : m.fv_range(f)) c += m.point(v) / 3.0;
    p[i] = ref.project(c, n[i]);
  }
  return (p[1] - p[0]).dot(n[1] - n[0]) >= 0 ? EdgeFeature::ConvexRidge : EdgeFeature::ConcaveRidge;
}

// The crest rule of features.h: the input's triangles in an AABB tree, for the normals at
// distance r across an edge.
class Crests {
 public:
  Crests(const TriMesh& m, double r, double ridge_rad) : m_(m), r_(r), ridge_rad_(ridge_rad) {
    std::vector<Eigen::Vector3d> pts;
    for (const VertexHandle v : m.vertices()) pts.push_back(m.point(v));
    std::vector<std::array<int, 3>> tris;
    for (const auto f : m.faces()) {
      std::array<int, 3> t{};
      int k = 0;
      for (const VertexHandle v : m.fv_range(f)) t[static_cast<std::size_t>(k++)] = v.idx();
      tris.push_back(t);
      const Eigen::Vector3d n = (pts[idx(t[1])] - pts[idx(t[0])]).cross(pts[idx(t[2])] - pts[idx(t[0])]);
      normals_.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero());
    }
    tree_ = TriangleTree(pts, tris);
  }

  // The crest edges (features.h): every candidate cap edge (a share of the turn, the normals r
  // across turning more than the ridge angle the same way), grouped into rows (candidates
  // joined at vertices) and the rows into caps (rows sharing a face); in each cap the one row
  // whose edges most often hold the far normals' bisector in their wedge. A whole row, so the
  // crest cannot zigzag between rows where the bisector falls near a row.
  std::vector<char> crest_edges() const {
    const std::size_t ne = m_.n_edges();
    std::vector<int> state(ne, 0);  // 0 not a candidate, 1 candidate, 2 candidate holding the bisector
    for (const EdgeHandle e : m_.edges())
      if (!m_.is_boundary(e)) state[static_cast<std::size_t>(e.idx())] = candidate(e);
    // Rows: chains of candidate edges, split at junctions (a vertex with other than two
    // candidate edges: where a trailing edge's rows meet a tip's); caps: rows joined through a
    // face at a vertex of theirs that is no junction.
    std::vector<int> count(m_.n_vertices(), 0);
    for (const EdgeHandle e : m_.edges())
      if (state[static_cast<std::size_t>(e.idx())]) {
        const HalfedgeHandle h = m_.halfedge_handle(e, 0);
        ++count[idx(m_.from_vertex_handle(h).idx())];
        ++count[idx(m_.to_vertex_handle(h).idx())];
      }
    std::vector<int> root(ne);
    for (std::size_t i = 0; i < ne; ++i) root[i] = static_cast<int>(i);
    std::function<int(int)> find = [&](int x) { return root[idx(x)] == x ? x : root[idx(x)] = find(root[idx(x)]); };
    std::vector<int> vertex_row(m_.n_vertices(), -1);  // a non-junction vertex's row (an edge id)
    for (const EdgeHandle e : m_.edges()) {
      if (!state[static_cast<std::size_t>(e.idx())]) continue;
      const HalfedgeHandle h = m_.halfedge_handle(e, 0);
      for (const VertexHandle v : {m_.from_vertex_handle(h), m_.to_vertex_handle(h)}) {
        if (count[idx(v.idx())] != 2) continue;
        int& r = vertex_row[idx(v.idx())];
        if (r < 0) r = e.idx();
        else root[idx(find(e.idx()))] = find(r);
      }
    }
    std::vector<int> cap(ne);
    for (std::size_t i = 0; i < ne; ++i) cap[i] = static_cast<int>(i);
    std::function<int(int)> find_cap = [&](int x) { return cap[idx(x)] == x ? x : cap[idx(x)] = find_cap(cap[idx(x)]); };
    for (const auto f : m_.faces()) {
      int first = -1;
      for (const VertexHandle v : m_.fv_range(f)) {
        const int r = vertex_row[idx(v.idx())];
        if (r < 0) continue;
        if (first < 0) first = find(r);
        else cap[idx(find_cap(find(r)))] = find_cap(first);
      }
    }
    auto row_of_edge = [&](EdgeHandle e) { return find(e.idx()); };
    // Per row: its edges holding the bisector, and its size; the best row of each cap.
    std::map<int, std::pair<int, int>> score;  // row -> (holding, edges)
    for (const EdgeHandle e : m_.edges()) {
      const int st = state[static_cast<std::size_t>(e.idx())];
      if (!st) continue;
      auto& sc = score[row_of_edge(e)];
      sc.first += st == 2;
      sc.second += 1;
    }
    std::map<int, int> best;  // cap -> row
    for (const auto& [row, sc] : score) {
      if (sc.first == 0) continue;
      const int c = find_cap(row);
      const auto it = best.find(c);
      if (it == best.end() || sc > score[it->second]) best[c] = row;
    }
    std::vector<char> crest(ne, 0);
    for (const EdgeHandle e : m_.edges()) {
      if (!state[static_cast<std::size_t>(e.idx())]) continue;
      const int row = row_of_edge(e);
      const auto it = best.find(find_cap(row));
      crest[static_cast<std::size_t>(e.idx())] = it != best.end() && it->second == row;
    }
    return crest;
  }

  // 0: not a cap edge; 1: a cap edge; 2: a cap edge whose wedge holds the far normals' bisector.
  int candidate(EdgeHandle e) const {
    const HalfedgeHandle h = m_.halfedge_handle(e, 0);
    const Eigen::Vector3d& a = m_.point(m_.from_vertex_handle(h));
    const Eigen::Vector3d& b = m_.point(m_.to_vertex_handle(h));
    const Eigen::Vector3d& c = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(h)));
    const Eigen::Vector3d& d = m_.point(m_.to_vertex_handle(m_.next_halfedge_handle(m_.opposite_halfedge_handle(h))));
    const Eigen::Vector3d u = b - a;
    if (!(u.norm() > 0)) return 0;
    const Eigen::Vector3d n1 = u.cross(c - a), n2 = (a - b).cross(d - b);  // left (a, b, c), right (b, a, d)
    if (!(n1.norm() > 0 && n2.norm() > 0)) return 0;
    // The edge carries a share of the turn (a cap of at most 8 such edges across).
    const double own = angle_between(n1, n2);
    if (own < ridge_rad_ / 8 || own > ridge_rad_) return 0;
    const Eigen::Vector3d mid = 0.5 * (a + b);
    // The surface normal r away from mid toward o (across the edge in that face's plane).
    auto across = [&](const Eigen::Vector3d& o) {
      Eigen::Vector3d t = (o - a) - (o - a).dot(u) / u.squaredNorm() * u;
      if (!(t.norm() > 0)) return Eigen::Vector3d(Eigen::Vector3d::Zero());
      const TriangleTree::Closest cl = tree_.closest(mid + r_ * t.normalized());
      return normals_[static_cast<std::size_t>(cl.triangle)];
    };
    const Eigen::Vector3d nl = across(c), nr = across(d);
    if (nl.squaredNorm() == 0 || nr.squaredNorm() == 0 || angle_between(nl, nr) <= ridge_rad_) return 0;
    // Signed angles around the edge's axis, from n1: the far normals turn the way the edge does,
    // and their bisector lies within [n1, n2).
    const Eigen::Vector3d axis = u.normalized(), m1 = n1.normalized();
    auto turn = [&](const Eigen::Vector3d& n) { return std::atan2(axis.dot(m1.cross(n)), m1.dot(n)); };
    const double t2 = turn(n2), tb = turn(nl + nr), tl = turn(nl), tr = turn(nr);
    if ((tr - tl) * t2 <= 0) return 0;
    return (t2 > 0 ? (tb >= 0 && tb < t2) : (tb <= 0 && tb > t2)) ? 2 : 1;
  }

 private:
  const TriMesh& m_;
  double r_, ridge_rad_;
  TriangleTree tree_;
  std::vector<Eigen::Vector3d> normals_;
};

// The feature edges around one vertex.
struct VertexEdges {
  int count = 0, convex = 0, concave = 0, boundary = 0;
  std::array<HalfedgeHandle, 2> out;  // the first two, as halfedges leaving the vertex
};

void check_options(const FeatureOptions& o) {
  const auto in_range = [](double x, double lo, double hi) { return x > lo && x < hi; };  // false for NaN
  if (!in_range(o.ridge_angle_deg, 0, 180))
    throw ConfigError("features: ridge_angle_deg = " + std::to_string(o.ridge_angle_deg) + " is not in (0, 180)");
  if (!in_range(o.curve_turn_deg, 0, 180))
    throw ConfigError("features: curve_turn_deg = " + std::to_string(o.curve_turn_deg) + " is not in (0, 180)");
  if (!in_range(o.corner_defect_deg, 0, 360))
    throw ConfigError("features: corner_defect_deg = " + std::to_string(o.corner_defect_deg) + " is not in (0, 360)");
  // Kept edges carry no body curve: judged on a reference, their corners would be misread.
  if (o.reference && o.keep_existing) throw ConfigError("features: reference and keep_existing exclude each other");
  if (!(o.min_curve_length >= 0)) throw ConfigError("features: min_curve_length must not be negative");
}

// A corner without ridges (a cone point). A positive defect is positive Gaussian curvature: convex
// when the apex points out of the body (it lies on the outer side of its one-ring, measured along
// the one-ring's area-weighted normal), concave for a dimple; a negative defect is a saddle.
VertexFeature cone_point_kind(const TriMesh& m, VertexHandle v, double defect) {
  if (defect < 0) return VertexFeature::SaddleCorner;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
  int n = 0;
  for (const HalfedgeHandle h : m.voh_range(v)) {
    const Eigen::Vector3d& a = m.point(m.to_vertex_handle(h));
    centroid += a;
    ++n;
    if (!m.is_boundary(h)) {
      const Eigen::Vector3d& b = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
      normal += (a - m.point(v)).cross(b - m.point(v));
    }
  }
  centroid /= std::max(n, 1);
  return (m.point(v) - centroid).dot(normal) >= 0 ? VertexFeature::ConvexCorner : VertexFeature::ConcaveCorner;
}

VertexFeature corner_kind(const TriMesh& m, VertexHandle v, const VertexEdges& ve, double defect) {
  if (ve.boundary > 0 || m.is_boundary(v)) return VertexFeature::BoundaryCorner;
  if (ve.convex > 0 && ve.concave > 0) return VertexFeature::SaddleCorner;
  if (ve.convex > 0) return VertexFeature::ConvexCorner;
  if (ve.concave > 0) return VertexFeature::ConcaveCorner;
  return cone_point_kind(m, v, defect);
}

// Pass 1: each edge Boundary, a convex or concave ridge, or Smooth. Kept edges (keep_existing)
// keep their kind and curve id; a kept interior edge marked only by its curve id (or wrongly as
// Boundary) gets its ridge kind from the geometry whatever its angle, and an open edge is always
// Boundary. Returns the first curve id not taken by a kept edge.
int classify_edges(TriSurface& s, const FeatureOptions& options, const std::vector<int>& body_curve) {
  TriMesh& m = s.mesh;
  const double ridge_rad = radians(options.ridge_angle_deg);
  std::vector<char> crest;
  if (options.crest_scale > 0 && !options.reference) crest = Crests(m, options.crest_scale, ridge_rad).crest_edges();
  const std::vector<char> inverted = inverted_faces(m);
  auto of_inverted = [&](EdgeHandle e) {
    for (unsigned i = 0; i < 2; ++i) {
      const HalfedgeHandle h = m.halfedge_handle(e, i);
      if (!m.is_boundary(h) && inverted[idx(m.face_handle(h).idx())]) return true;
    }
    return false;
  };
  int next_curve = 0;
  for (const EdgeHandle e : m.edges()) {
    EdgeFeature& f = m.property(s.edge_feature, e);
    int& curve = m.property(s.edge_curve, e);
    if (options.keep_existing && (curve >= 0 || f != EdgeFeature::Smooth)) {
      if (m.is_boundary(e))
        f = EdgeFeature::Boundary;
      else if (f == EdgeFeature::Smooth || f == EdgeFeature::Boundary)
        f = ridge_kind(m, e);
      next_curve = std::max(next_curve, curve + 1);
      continue;
    }
    curve = -1;
    if (m.is_boundary(e))
      f = EdgeFeature::Boundary;
    else if (options.reference)
      f = body_curve[static_cast<std::size_t>(e.idx())] < 0 ? EdgeFeature::Smooth
          : dihedral_departure(m, e) > ridge_rad           ? ridge_kind(m, e)
                                                           : body_ridge_kind(m, e, *options.reference);
    else if (of_inverted(e))
      f = EdgeFeature::Smooth;
    else if (dihedral_departure(m, e) > ridge_rad || (!crest.empty() && crest[static_cast<std::size_t>(e.idx())]))
      f = ridge_kind(m, e);
    else
      f = EdgeFeature::Smooth;
  }
  return next_curve;
}

// The feature edges around each vertex.
std::vector<VertexEdges> feature_edges_around(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  std::vector<VertexEdges> around(m.n_vertices());
  for (const EdgeHandle e : m.edges()) {
    const EdgeFeature f = m.property(s.edge_feature, e);
    if (f == EdgeFeature::Smooth) continue;
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h = m.halfedge_handle(e, static_cast<unsigned>(side));
      VertexEdges& ve = around[idx(m.from_vertex_handle(h).idx())];
      if (ve.count < 2) ve.out[idx(ve.count)] = h;
      ++ve.count;
      ve.convex += f == EdgeFeature::ConvexRidge;
      ve.concave += f == EdgeFeature::ConcaveRidge;
      ve.boundary += f == EdgeFeature::Boundary;
    }
  }
  return around;
}

// The sum of the corner angles of each vertex's faces.
std::vector<double> angle_sums(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  std::vector<double> angle_sum(m.n_vertices(), 0.0);
  for (const FaceHandle f : m.faces()) {
    const auto fv = s.face_vertices(f);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = m.point(fv[idx(k)]);
      angle_sum[idx(fv[idx(k)].idx())] +=
          angle_between(m.point(fv[idx((k + 1) % 3)]) - p, m.point(fv[idx((k + 2) % 3)]) - p);
    }
  }
  return angle_sum;
}

// Pass 2: each vertex a corner of its kind, Curve or Smooth, from its feature edges and angle
// defect. Returns which vertices are corners.
std::vector<char> classify_vertices(TriSurface& s, const FeatureOptions& options,
                                    const std::vector<VertexEdges>& around, const std::vector<int>& body_curve) {
  TriMesh& m = s.mesh;
  const double turn_rad = radians(options.curve_turn_deg);
  const double defect_rad = radians(options.corner_defect_deg);
  const std::vector<double> angle_sum = angle_sums(s);
  std::vector<char> corner(m.n_vertices(), 0);
  for (const VertexHandle v : m.vertices()) {
    VertexFeature& vf = m.property(s.vertex_feature, v);
    const VertexEdges& ve = around[idx(v.idx())];
    const bool interior = !m.is_isolated(v) && !m.is_boundary(v);
    const double defect = interior ? 2 * kPi - angle_sum[idx(v.idx())] : 0.0;
    if (options.keep_existing && is_corner(vf)) {
      corner[idx(v.idx())] = 1;
      continue;
    }
    bool is_a_corner = ve.count == 1 || ve.count >= 3 || std::abs(defect) > defect_rad;
    if (options.reference) {
      // Judged on the body: a vertex on two feature edges is a corner where the body's curves
      // change (or a ridge meets the boundary), not where the mesh turns or its angles add up
      // to a defect.
      is_a_corner = ve.count == 1 || ve.count >= 3 ||
                    (ve.count == 0 && options.reference->is_cone_point(m.point(v), 1e-6 * options.reference->scale()));
      if (ve.count == 2)
        is_a_corner = ve.boundary == 1 || body_curve[static_cast<std::size_t>(m.edge_handle(ve.out[0]).idx())] !=
                                              body_curve[static_cast<std::size_t>(m.edge_handle(ve.out[1]).idx())];
    } else if (ve.count == 2) {
      const EdgeHandle e0 = m.edge_handle(ve.out[0]), e1 = m.edge_handle(ve.out[1]);
      // A chain never mixes boundary and ridge edges, and kept curves end where another begins.
      is_a_corner = is_a_corner || ve.boundary == 1 || m.property(s.edge_curve, e0) != m.property(s.edge_curve, e1);
      const Eigen::Vector3d& p = m.point(v);
      const Eigen::Vector3d in = p - m.point(m.to_vertex_handle(ve.out[0]));
      const Eigen::Vector3d onward = m.point(m.to_vertex_handle(ve.out[1])) - p;
      is_a_corner = is_a_corner || angle_between(in, onward) > turn_rad;
    }
    if (is_a_corner) {
      vf = corner_kind(m, v, ve, defect);
      corner[idx(v.idx())] = 1;
    } else {
      vf = ve.count == 2 ? VertexFeature::Curve : VertexFeature::Smooth;
    }
  }
  return corner;
}

// Pass 3: curve ids from next_curve on. From a corner the chain continues through Curve vertices
// (exactly two feature edges each, so the next edge is the stored one that is not the current
// one) to a corner; what is left are closed loops.
void number_curves(TriSurface& s, const std::vector<VertexEdges>& around, const std::vector<char>& corner,
                   int next_curve) {
  TriMesh& m = s.mesh;
  const auto walk = [&](HalfedgeHandle h, int id) {
    for (;;) {
      const EdgeHandle e = m.edge_handle(h);
      if (m.property(s.edge_curve, e) >= 0) return;  // a closed loop is back at its start
      m.property(s.edge_curve, e) = id;
      const VertexHandle v = m.to_vertex_handle(h);
      if (corner[idx(v.idx())]) return;
      const VertexEdges& ve = around[idx(v.idx())];
      h = m.edge_handle(ve.out[0]) == e ? ve.out[1] : ve.out[0];
    }
  };
  const auto unassigned_feature = [&](EdgeHandle e) {
    return m.property(s.edge_feature, e) != EdgeFeature::Smooth && m.property(s.edge_curve, e) < 0;
  };
  for (const VertexHandle v : m.vertices()) {
    if (!corner[idx(v.idx())]) continue;
    for (const HalfedgeHandle h : m.voh_range(v))
      if (unassigned_feature(m.edge_handle(h))) walk(h, next_curve++);
  }
  for (const EdgeHandle e : m.edges())
    if (unassigned_feature(e)) walk(m.halfedge_handle(e, 0), next_curve++);
}

// FeatureOptions::min_curve_length: ridge curves shorter than it lose their edges (Smooth), and
// the vertices and curves are classified again without them.
// Returns the number of curves dropped.
std::size_t drop_short_curves(TriSurface& s, const FeatureOptions& options, const std::vector<int>& body_curve) {
  TriMesh& m = s.mesh;
  std::map<int, double> length;
  std::set<int> has_boundary;
  for (const EdgeHandle e : m.edges()) {
    const int c = m.property(s.edge_curve, e);
    if (c < 0) continue;
    const HalfedgeHandle h = m.halfedge_handle(e, 0);
    length[c] += (m.point(m.to_vertex_handle(h)) - m.point(m.from_vertex_handle(h))).norm();
    if (m.property(s.edge_feature, e) == EdgeFeature::Boundary) has_boundary.insert(c);
  }
  std::set<int> dropped;
  for (const EdgeHandle e : m.edges()) {
    const int c = m.property(s.edge_curve, e);
    if (c >= 0 && !has_boundary.count(c) && length[c] < options.min_curve_length) {
      m.property(s.edge_feature, e) = EdgeFeature::Smooth;
      dropped.insert(c);
    }
  }
  if (dropped.empty()) return 0;
  for (const EdgeHandle e : m.edges()) m.property(s.edge_curve, e) = -1;
  const std::vector<VertexEdges> around = feature_edges_around(s);
  const std::vector<char> corner = classify_vertices(s, options, around, body_curve);
  number_curves(s, around, corner, 0);
  return dropped.size();
}

}  // namespace

FeatureReport detect_features(TriSurface& s, const FeatureOptions& options) {
  check_options(options);
  // 1. Edges.
  const std::vector<int> body_curve = options.reference ? body_curves(s.mesh, *options.reference) : std::vector<int>();
  const int next_curve = classify_edges(s, options, body_curve);
  // 2. Vertices: their feature edges, then the angle sums for the defects.
  const std::vector<VertexEdges> around = feature_edges_around(s);
  const std::vector<char> corner = classify_vertices(s, options, around, body_curve);
  // 3. Curves.
  number_curves(s, around, corner, next_curve);
  const std::size_t dropped =
      options.min_curve_length > 0 && !options.keep_existing ? drop_short_curves(s, options, body_curve) : 0;
  FeatureReport r = count_features(s);
  r.dropped_curves = dropped;
  return r;
}

FeatureReport count_features(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  FeatureReport r;
  std::vector<int> ids;
  for (const EdgeHandle e : m.edges()) {
    switch (m.property(s.edge_feature, e)) {
      case EdgeFeature::ConvexRidge:
        ++r.ridges_convex;
        break;
      case EdgeFeature::ConcaveRidge:
        ++r.ridges_concave;
        break;
      case EdgeFeature::Boundary:
        ++r.boundary_edges;
        break;
      case EdgeFeature::Smooth:
        break;
    }
    if (m.property(s.edge_curve, e) >= 0) ids.push_back(m.property(s.edge_curve, e));
  }
  for (const VertexHandle v : m.vertices()) {
    switch (m.property(s.vertex_feature, v)) {
      case VertexFeature::ConvexCorner:
        ++r.corners_convex;
        break;
      case VertexFeature::ConcaveCorner:
        ++r.corners_concave;
        break;
      case VertexFeature::SaddleCorner:
        ++r.corners_saddle;
        break;
      case VertexFeature::BoundaryCorner:
        ++r.corners_boundary;
        break;
      case VertexFeature::Smooth:
      case VertexFeature::Curve:
        break;
    }
  }
  // Distinct ids: a presence table when the ids are dense (always, after detect_features), a sort
  // otherwise.
  const int max_id = ids.empty() ? -1 : *std::max_element(ids.begin(), ids.end());
  if (idx(max_id + 1) <= 4 * ids.size() + 64) {
    std::vector<char> seen(idx(max_id + 1), 0);
    for (const int id : ids) {
      if (!seen[idx(id)]) ++r.curves;
      seen[idx(id)] = 1;
    }
  } else {
    std::sort(ids.begin(), ids.end());
    r.curves = static_cast<std::size_t>(std::unique(ids.begin(), ids.end()) - ids.begin());
  }
  return r;
}

std::vector<std::vector<TriMesh::VertexHandle>> feature_curves(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  const int n_curves = s.num_curves();
  std::vector<std::vector<EdgeHandle>> edges_of(idx(n_curves));
  for (const EdgeHandle e : m.edges()) {
    const int c = m.property(s.edge_curve, e);
    if (c >= 0) edges_of[idx(c)].push_back(e);
  }
  // Scratch shared by all curves and reset after each, so the total work is O(E + sum of the
  // valences of the curve vertices).
  std::vector<int> uses(m.n_vertices(), 0);
  std::vector<char> done(m.n_edges(), 0);
  std::vector<std::vector<VertexHandle>> curves(idx(n_curves));
  for (int c = 0; c < n_curves; ++c) {
    const std::vector<EdgeHandle>& edges = edges_of[idx(c)];
    if (edges.empty()) continue;
    const auto fail = [&](const std::string& why) {
      throw MesherError("features: curve " + std::to_string(c) + " (" + std::to_string(edges.size()) +
                        " edges) is not a simple chain: " + why);
    };
    for (const EdgeHandle e : edges) {
      ++uses[idx(m.from_vertex_handle(m.halfedge_handle(e, 0)).idx())];
      ++uses[idx(m.to_vertex_handle(m.halfedge_handle(e, 0)).idx())];
    }
    // Open chains start at their lower-numbered end; closed ones at their lowest corner if any.
    VertexHandle end, first_corner, any;
    for (const EdgeHandle e : edges) {
      for (int side = 0; side < 2; ++side) {
        const VertexHandle v = m.from_vertex_handle(m.halfedge_handle(e, static_cast<unsigned>(side)));
        const int k = uses[idx(v.idx())];
        if (k > 2) fail("vertex " + std::to_string(v.idx()) + " has " + std::to_string(k) + " of its edges");
        if (k == 1 && (!end.is_valid() || v.idx() < end.idx())) end = v;
        if (is_corner(m.property(s.vertex_feature, v)) && (!first_corner.is_valid() || v.idx() < first_corner.idx()))
          first_corner = v;
        if (!any.is_valid() || v.idx() < any.idx()) any = v;
      }
    }
    const VertexHandle start = end.is_valid() ? end : first_corner.is_valid() ? first_corner : any;
    std::vector<VertexHandle>& path = curves[idx(c)];
    path.push_back(start);
    VertexHandle v = start;
    for (std::size_t step = 0; step < edges.size(); ++step) {
      HalfedgeHandle next;
      for (const HalfedgeHandle h : m.voh_range(v)) {
        const EdgeHandle e = m.edge_handle(h);
        if (m.property(s.edge_curve, e) == c && !done[idx(e.idx())]) {
          next = h;
          break;
        }
      }
      if (!next.is_valid()) fail("it breaks at vertex " + std::to_string(v.idx()));
      done[idx(m.edge_handle(next).idx())] = 1;
      v = m.to_vertex_handle(next);
      path.push_back(v);
    }
    if (end.is_valid() == (path.back() == start)) fail("its ends do not match its vertex counts");
    for (const EdgeHandle e : edges) {
      uses[idx(m.from_vertex_handle(m.halfedge_handle(e, 0)).idx())] = 0;
      uses[idx(m.to_vertex_handle(m.halfedge_handle(e, 0)).idx())] = 0;
      done[idx(e.idx())] = 0;
    }
  }
  return curves;
}

}  // namespace plaf
