// SPDX-License-Identifier: MIT
// The smooth reference (smooth_reference.h): local cubic fits per vertex and side, blended over
// each face (X. Jiao and D. Wang, Engineering with Computers 28, 2012), feature curves as cubic
// Hermite curves, Gauss-Newton projection from the closest flat facet.
#include "surface3d/smooth_reference.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "modules/base/error.h"
#include "modules/geometry/aabb_tree.h"
#include "surface3d/discrete_reference.h"

namespace plaf {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

std::size_t idx(int i) { return static_cast<std::size_t>(i); }

constexpr int kMaxHops = 6;                 // patches a projection may move across
constexpr int kMaxIterations = 40;          // Gauss-Newton steps per projection
constexpr double kStepTol = 1e-14;          // converged: barycentric step below this
constexpr double kSliverSine = 1e-10;       // a facet with a smaller angle is flat
constexpr double kMinRidgeSine = 0.1;      // sides meeting at a smaller angle give no curve tangent
constexpr double kMaxSlope = 1.0;           // fit points steeper than 45 degrees are left out
constexpr std::size_t kCubicPoints = 14;    // points a cubic fit needs (9 unknowns)
constexpr std::size_t kQuadraticPoints = 8; // points a quadratic fit needs (5 unknowns)

// A height function over the tangent plane at origin: w(u, v) = sum c_k m_k(u / su, v / sv),
// m = (u, v, u^2, uv, v^2, u^3, u^2 v, u v^2, v^3), t1 and t2 along the principal directions of
// the fitted points' spread and su, sv their spreads (well conditioned on stretched
// neighbourhoods); zero coefficients beyond its degree.
struct LocalFit {
  Vector3d origin = Vector3d::Zero(), t1 = Vector3d::UnitX(), t2 = Vector3d::UnitY(), n = Vector3d::UnitZ();
  double su = 1, sv = 1;
  std::array<double, 9> c{};

  // The slopes dw/du, dw/dv (lengths) at scaled coordinates (u, v).
  Vector2d slopes(double u, double v) const {
    return {(c[0] + 2 * c[2] * u + c[3] * v + 3 * c[5] * u * u + 2 * c[6] * u * v + c[7] * v * v) / su,
            (c[1] + c[3] * u + 2 * c[4] * v + c[6] * u * u + 2 * c[7] * u * v + 3 * c[8] * v * v) / sv};
  }
  // The fit's unit normal at its origin (the vertex normal of its side).
  Vector3d vertex_normal() const {
    const Vector2d g = slopes(0, 0);
    return (n - g.x() * t1 - g.y() * t2).normalized();
  }
  // p lifted onto the fit (p's tangent-plane coordinates, then the height); jac = dQ/dp.
  Vector3d lift(const Vector3d& p, Matrix3d& jac) const {
    const Vector3d d = p - origin;
    const double du = t1.dot(d), dv = t2.dot(d), u = du / su, v = dv / sv;
    const double w = c[0] * u + c[1] * v + c[2] * u * u + c[3] * u * v + c[4] * v * v + c[5] * u * u * u +
                     c[6] * u * u * v + c[7] * u * v * v + c[8] * v * v * v;
    const Vector2d g = slopes(u, v);
    jac = t1 * t1.transpose() + t2 * t2.transpose() + n * (g.x() * t1 + g.y() * t2).transpose();
    return origin + du * t1 + dv * t2 + w * n;
  }
};

// A unit vector orthogonal to unit n.
Vector3d any_orthogonal(const Vector3d& n) {
  const Vector3d a = std::abs(n.x()) < 0.6 ? Vector3d::UnitX() : Vector3d::UnitY();
  return (a - a.dot(n) * n).normalized();
}

// The least-squares height coefficients of `points` in the frame (t1, t2, n) at origin, of the
// highest degree (3, 2, 1) the points support with a full-rank system; false if none does.
bool fit_heights(const std::vector<Vector3d>& points, LocalFit& f) {
  std::vector<Vector3d> local;
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const Vector3d& x : points) {
    const Vector3d d = x - f.origin;
    const Vector3d q(f.t1.dot(d), f.t2.dot(d), f.n.dot(d));
    if (std::abs(q.z()) > kMaxSlope * q.head<2>().norm()) continue;  // folded away: no height function
    local.push_back(q);
    spread += q.head<2>() * q.head<2>().transpose();
  }
  if (local.size() < 2) return false;
  // The tangent frame along the principal directions of the points' spread.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(spread / static_cast<double>(local.size()));
  const Eigen::Matrix2d axes = eig.eigenvectors();
  const Vector3d old_t1 = f.t1, old_t2 = f.t2;
  const Vector3d t1 = axes(0, 1) * f.t1 + axes(1, 1) * f.t2;  // the wider spread first
  f.t2 = f.n.cross(t1);
  f.t1 = t1;
  f.su = std::sqrt(std::max(eig.eigenvalues()(1), 0.0));
  f.sv = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
  if (!(f.sv > 1e-6 * f.su)) return false;  // the points on a line: no surface
  std::vector<Vector3d> uvw;
  for (const Vector3d& q : local) {
    const Vector3d d = q.x() * old_t1 + q.y() * old_t2;
    uvw.emplace_back(f.t1.dot(d) / f.su, f.t2.dot(d) / f.sv, q.z());
  }
  for (const int cols : {9, 5, 2}) {
    if (uvw.size() < (cols == 9 ? kCubicPoints : cols == 5 ? kQuadraticPoints : 2)) continue;
    Eigen::MatrixXd a(static_cast<Eigen::Index>(uvw.size()), cols);
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(uvw.size()));
    for (std::size_t k = 0; k < uvw.size(); ++k) {
      const double u = uvw[k].x(), v = uvw[k].y();
      const double m[9] = {u, v, u * u, u * v, v * v, u * u * u, u * u * v, u * v * v, v * v * v};
      for (int j = 0; j < cols; ++j) a(static_cast<Eigen::Index>(k), j) = m[j];
      rhs(static_cast<Eigen::Index>(k)) = uvw[k].z();
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
    qr.setThreshold(1e-8);
    if (qr.rank() < cols) continue;
    const Eigen::VectorXd sol = qr.solve(rhs);
    f.c.fill(0);
    for (int j = 0; j < cols; ++j) f.c[idx(j)] = sol(j);
    return true;
  }
  return false;
}

// The fit at origin of `points`, starting from normal n0 and fitted twice: the second time in the
// tangent plane of the first fit. Without support, the tangent plane at n0 (Phong's).
LocalFit fit_vertex(const Vector3d& origin, const Vector3d& n0, const std::vector<Vector3d>& points) {
  LocalFit f;
  f.origin = origin;
  Vector3d n = n0;
  for (int pass = 0; pass < 2; ++pass) {
    LocalFit trial = f;
    trial.n = n;
    trial.t1 = any_orthogonal(n);
    trial.t2 = n.cross(trial.t1);
    if (!fit_heights(points, trial)) return pass == 0 ? trial : f;
    f = trial;
    const Vector2d g = f.slopes(0, 0);
    const Vector3d tilted = n - g.x() * f.t1 - g.y() * f.t2;
    if (!(tilted.dot(n0) > 0.5 * tilted.norm())) break;  // over 60 degrees off the faces: keep the first
    n = tilted.normalized();
  }
  return f;
}

// A feature edge's curve: cubic Hermite from a to b with end derivatives ma, mb (in t in [0, 1]).
struct Segment {
  int a = -1, b = -1;
  Vector3d pa, pb, ma, mb;
  int next_a = -1, next_b = -1;  // the curve's segment continuing at a (at b), -1 at an end

  Vector3d at(double t, Vector3d& dt) const {
    const double t2 = t * t, t3 = t2 * t;
    dt = (6 * t2 - 6 * t) * pa + (3 * t2 - 4 * t + 1) * ma + (6 * t - 6 * t2) * pb + (3 * t2 - 2 * t) * mb;
    return (2 * t3 - 3 * t2 + 1) * pa + (t3 - 2 * t2 + t) * ma + (3 * t2 - 2 * t3) * pb + (t3 - t2) * mb;
  }
};

// The derivative with respect to chord length, at v, of the parabola through u, v, o (pointing
// toward o): Bessel's tangent.
Vector3d bessel_tangent(const Vector3d& u, const Vector3d& v, const Vector3d& o) {
  const double du = (v - u).norm(), dout = (o - v).norm();
  if (!(du > 0 && dout > 0)) return dout > 0 ? Vector3d((o - v) / dout) : Vector3d::Zero();
  return (dout * (v - u) / du + du * (o - v) / dout) / (du + dout);
}

// The derivative at v, pointing toward o, of the parabola through v, o, w (one-sided).
Vector3d end_tangent(const Vector3d& v, const Vector3d& o, const Vector3d& w) {
  const double d0 = (o - v).norm(), d1 = (w - o).norm();
  if (!(d0 > 0 && d1 > 0)) return d0 > 0 ? Vector3d((o - v) / d0) : Vector3d::Zero();
  const Vector3d D0 = (o - v) / d0, D1 = (w - o) / d1;
  return D0 - d0 * (D1 - D0) / (d0 + d1);
}

struct Closest {
  Vector3d point, normal;
};

class SmoothReference final : public ReferenceGeometry<3> {
 public:
  explicit SmoothReference(const TriSurface& s);

  Vector3d project(const Vector3d& p) const override { return closest(p).point; }
  Vector3d project(const Vector3d& p, Vector3d& normal_out) const override {
    const Closest c = closest(p);
    normal_out = c.normal;
    return c.point;
  }
  Vector3d normal(const Vector3d& x) const override { return closest(x).normal; }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override;
  int num_curves() const override { return static_cast<int>(curve_trees_.size()); }
  double scale() const override { return scale_; }

 private:
  struct PatchPoint {
    Vector3d x, d1, d2;  // the point and its derivatives in b1, b2 (b0 = 1 - b1 - b2)
  };
  void add_faces(const TriSurface& s);
  void add_fits(const TriSurface& s);
  void add_segments(const TriSurface& s);
  PatchPoint evaluate(int f, const Vector3d& b) const;
  // The Gauss-Newton step (in barycentric coordinates) from b toward the closest point to q.x + r,
  // moving only along an edge that b is on and that the step cannot cross (open[k]: it can).
  Vector3d gauss_newton_step(const Vector3d& b, const PatchPoint& q, const Vector3d& r,
                             const std::array<char, 3>& open) const;
  // Adds face f's feature-edge defect opposite corner k at barycentric b (the three of them).
  void add_edge_defect(int f, int k, const Vector3d& b, PatchPoint& out) const;
  Closest closest(const Vector3d& p) const;
  Closest flat(const TriangleTree::Closest& c) const;
  Vector3d patch_normal(int f, const PatchPoint& q) const;
  // The closest point of segment seg's curve to p, starting from the best of a few samples.
  Vector3d closest_on_segment(int seg, const Vector3d& p) const;

  std::vector<Vector3d> points_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<Vector3d> face_normal_;          // unit (zero for a degenerate face)
  std::vector<char> flat_;                     // degenerate facet: projected flat
  std::vector<std::array<int, 3>> neighbour_;  // face across the edge opposite corner k, or -1
  std::vector<std::array<int, 3>> corner_fit_; // fits_ index of each corner
  std::vector<std::array<int, 3>> edge_seg_;   // segments_ index of the edge opposite corner k, or -1
  std::vector<LocalFit> fits_;
  std::vector<Segment> segments_;
  std::vector<std::vector<int>> curve_segs_;  // per curve, its segments (tree triangle order)
  std::vector<TriangleTree> curve_trees_;     // per curve, its polyline's segments (a, b, b)
  TriangleTree tree_;
  double scale_ = 0;
};

SmoothReference::SmoothReference(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  points_ = vertex_points(s, scale_);
  if (m.n_faces() == 0) throw MesherError("smooth reference: the surface has no faces");
  add_faces(s);
  tree_ = TriangleTree(points_, tris_);
  add_fits(s);
  add_segments(s);
}

bool is_feature(const TriSurface& s, TriMesh::EdgeHandle e) {
  return s.mesh.is_boundary(e) || s.mesh.property(s.edge_curve, e) >= 0 ||
         s.mesh.property(s.edge_feature, e) != EdgeFeature::Smooth;
}

// The halfedge of face f opposite its corner k (k = 0: v1 -> v2, 1: v2 -> v0, 2: v0 -> v1).
TriMesh::HalfedgeHandle opposite_halfedge(const TriMesh& m, TriMesh::FaceHandle f, int k) {
  TriMesh::HalfedgeHandle h = m.halfedge_handle(f);  // v0 -> v1
  for (int i = 0; i < (k + 1) % 3; ++i) h = m.next_halfedge_handle(h);
  return h;
}

void SmoothReference::add_faces(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  std::vector<int> index(m.n_faces(), -1);
  for (const auto f : m.faces()) {
    index[idx(f.idx())] = static_cast<int>(tris_.size());
    const auto fv = s.face_vertices(f);
    tris_.push_back({fv[0].idx(), fv[1].idx(), fv[2].idx()});
  }
  for (const auto& t : tris_) {
    const Vector3d &a = points_[idx(t[0])], &b = points_[idx(t[1])], &c = points_[idx(t[2])];
    const Vector3d n = (b - a).cross(c - a);
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    flat_.push_back(!(n.norm() > kSliverSine * longest2));
    face_normal_.push_back(n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::Zero());
  }
  for (const auto f : m.faces()) {
    std::array<int, 3> nb{-1, -1, -1};
    for (int k = 0; k < 3; ++k) {
      const auto g = m.face_handle(m.opposite_halfedge_handle(opposite_halfedge(m, f, k)));
      if (g.is_valid()) nb[idx(k)] = index[idx(g.idx())];
    }
    neighbour_.push_back(nb);
  }
}

// One fit per vertex and side: the faces around a vertex joined across its smooth edges form a
// sector; each sector's fit uses the points of its two-ring on that side (the sectors of the
// sector's faces' other corners), three-ring when short of kCubicPoints.
void SmoothReference::add_fits(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  std::vector<int> face_of(m.n_faces(), -1);
  {
    int i = 0;
    for (const auto f : m.faces()) face_of[idx(f.idx())] = i++;
  }
  corner_fit_.assign(tris_.size(), {-1, -1, -1});
  std::vector<std::vector<int>> sector_faces;
  std::vector<int> sector_vertex;
  auto corner_of = [&](int f, int v) {
    const auto& t = tris_[idx(f)];
    return t[0] == v ? 0 : t[1] == v ? 1 : 2;
  };
  // 1. Sectors: flood the faces around each vertex across its smooth edges.
  for (const auto v : m.vertices()) {
    for (const auto h : m.voh_range(v)) {
      const auto f0 = m.face_handle(h);
      if (!f0.is_valid() || corner_fit_[idx(face_of[idx(f0.idx())])][idx(corner_of(face_of[idx(f0.idx())], v.idx()))] >= 0)
        continue;
      const int sector = static_cast<int>(sector_faces.size());
      sector_faces.emplace_back();
      sector_vertex.push_back(v.idx());
      std::vector<TriMesh::FaceHandle> stack = {f0};
      while (!stack.empty()) {
        const auto f = stack.back();
        stack.pop_back();
        const int fi = face_of[idx(f.idx())];
        int& slot = corner_fit_[idx(fi)][idx(corner_of(fi, v.idx()))];
        if (slot >= 0) continue;
        slot = sector;
        sector_faces[idx(sector)].push_back(fi);
        for (const auto fh : m.fh_range(f)) {  // the face's two edges at v, crossed where smooth
          if (m.from_vertex_handle(fh) != v && m.to_vertex_handle(fh) != v) continue;
          if (is_feature(s, m.edge_handle(fh))) continue;
          const auto g = m.opposite_face_handle(fh);
          if (g.is_valid()) stack.push_back(g);
        }
      }
    }
  }
  // 2. The fits, from the sector's faces' normals (area weighted) and its rings.
  fits_.resize(sector_faces.size());
  for (std::size_t sec = 0; sec < sector_faces.size(); ++sec) {
    const int v = sector_vertex[sec];
    Vector3d n0 = Vector3d::Zero();
    for (const int f : sector_faces[sec]) {
      const auto& t = tris_[idx(f)];
      const int k = corner_of(f, v);
      const Vector3d &a = points_[idx(t[idx(k)])], &b = points_[idx(t[idx((k + 1) % 3)])],
                     &c = points_[idx(t[idx((k + 2) % 3)])];
      n0 += (b - a).cross(c - a);  // area weighted: slivers (an angle near pi at v) weigh nothing
    }
    if (!(n0.norm() > 0)) n0 = face_normal_[idx(sector_faces[sec].front())];
    if (!(n0.norm() > 0)) n0 = Vector3d::UnitZ();
    n0.normalize();
    std::vector<int> ring = sector_faces[sec], verts;
    for (int depth = 1; depth <= 3; ++depth) {
      verts.clear();
      for (const int f : ring)
        for (const int w : tris_[idx(f)])
          if (w != v) verts.push_back(w);
      std::sort(verts.begin(), verts.end());
      verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
      if (depth == 3 || (depth == 2 && verts.size() >= kCubicPoints)) break;
      std::vector<int> wider = ring;
      for (const int f : ring)
        for (int k = 0; k < 3; ++k) {
          const auto& more = sector_faces[idx(corner_fit_[idx(f)][idx(k)])];
          wider.insert(wider.end(), more.begin(), more.end());
        }
      std::sort(wider.begin(), wider.end());
      wider.erase(std::unique(wider.begin(), wider.end()), wider.end());
      ring = std::move(wider);
    }
    std::vector<Vector3d> pts;
    for (const int w : verts) pts.push_back(points_[idx(w)]);
    fits_[sec] = fit_vertex(points_[idx(v)], n0, pts);
  }
}

// Feature edges as Hermite segments: curve edges with tangents from their neighbours along the
// curve (a vertex not a corner with exactly two of the curve's edges joins them smoothly), other
// feature edges straight.
void SmoothReference::add_segments(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  const int n_curves = s.num_curves();
  std::vector<int> face_index(m.n_faces(), -1);  // tris_ index of a face handle
  {
    int i = 0;
    for (const auto f : m.faces()) face_index[idx(f.idx())] = i++;
  }
  std::vector<int> seg_curve;  // per segment, its curve id (-1: a feature edge without one)
  std::vector<std::array<int, 2>> seg_sides;  // per segment, the faces on its two sides (-1: none)
  for (const auto e : m.edges()) {
    if (!is_feature(s, e)) continue;
    const auto h = m.halfedge_handle(e, 0);
    Segment g;
    g.a = m.from_vertex_handle(h).idx();
    g.b = m.to_vertex_handle(h).idx();
    g.pa = points_[idx(g.a)];
    g.pb = points_[idx(g.b)];
    seg_curve.push_back(m.property(s.edge_curve, e));
    std::array<int, 2> sides{-1, -1};
    for (unsigned k = 0; k < 2; ++k)
      if (const auto f = m.face_handle(m.halfedge_handle(e, k)); f.is_valid()) sides[k] = face_index[idx(f.idx())];
    seg_sides.push_back(sides);
    segments_.push_back(g);
  }
  // Each vertex's segments per curve; a smooth join where a non-corner vertex has exactly two.
  std::map<std::pair<int, int>, std::vector<int>> at;  // (curve, vertex) -> segments
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    if (seg_curve[i] < 0) continue;
    at[{seg_curve[i], segments_[i].a}].push_back(static_cast<int>(i));
    at[{seg_curve[i], segments_[i].b}].push_back(static_cast<int>(i));
  }
  std::vector<char> corner(points_.size(), 0);
  for (const auto v : m.vertices()) corner[idx(v.idx())] = is_corner(m.property(s.vertex_feature, v));
  auto continuation = [&](int seg, int v) {
    if (seg_curve[idx(seg)] < 0 || corner[idx(v)]) return -1;
    const std::vector<int>& here = at[{seg_curve[idx(seg)], v}];
    if (here.size() != 2) return -1;
    return here[0] == seg ? here[1] : here[0];
  };
  auto other_end = [&](int seg, int v) { return segments_[idx(seg)].a == v ? segments_[idx(seg)].b : segments_[idx(seg)].a; };
  // The unit tangent at v of segment seg, pointing to its other end: along the intersection of the
  // two sides' tangent planes at v where they meet at an angle, else that of the parabola through
  // v's neighbours along the curve.
  auto tangent = [&](int seg, int v) {
    const int o = other_end(seg, v);
    const Vector3d &pv = points_[idx(v)], &po = points_[idx(o)];
    Vector3d t = po - pv;
    if (const int before = continuation(seg, v); before >= 0)
      t = bessel_tangent(points_[idx(other_end(before, v))], pv, po);
    else if (const int after = continuation(seg, o); after >= 0)
      t = end_tangent(pv, po, points_[idx(other_end(after, o))]);
    const auto [f0, f1] = seg_sides[idx(seg)];
    if (f0 >= 0 && f1 >= 0) {
      auto side_normal = [&](int f) {
        const auto& tri = tris_[idx(f)];
        const int k = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
        return fits_[idx(corner_fit_[idx(f)][idx(k)])].vertex_normal();
      };
      const Vector3d x = side_normal(f0).cross(side_normal(f1));
      if (x.norm() > kMinRidgeSine) t = x.dot(t) >= 0 ? x : Vector3d(-x);
    }
    return t.norm() > 0 ? Vector3d(t.normalized()) : t;
  };
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    Segment& g = segments_[i];
    const Vector3d ta = tangent(static_cast<int>(i), g.a), tb = -tangent(static_cast<int>(i), g.b);
    // Derivatives of the length of the circular arc with these end tangents.
    const double half_turn = 0.5 * std::atan2(ta.cross(tb).norm(), ta.dot(tb));
    const double length = (g.pb - g.pa).norm() * (half_turn > 1e-8 ? half_turn / std::sin(half_turn) : 1.0);
    g.ma = length * ta;
    g.mb = length * tb;
    g.next_a = continuation(static_cast<int>(i), g.a);
    g.next_b = continuation(static_cast<int>(i), g.b);
  }
  std::map<std::pair<int, int>, int> seg_of;  // (lower, higher vertex) -> segment
  for (std::size_t i = 0; i < segments_.size(); ++i)
    seg_of[std::minmax(segments_[i].a, segments_[i].b)] = static_cast<int>(i);
  edge_seg_.assign(tris_.size(), {-1, -1, -1});
  for (std::size_t f = 0; f < tris_.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto it = seg_of.find(std::minmax(tris_[f][idx((k + 1) % 3)], tris_[f][idx((k + 2) % 3)]));
      if (it != seg_of.end()) edge_seg_[f][idx(k)] = it->second;
    }
  // Per curve, a tree of its polyline for the closest segment.
  curve_segs_.assign(idx(std::max(n_curves, 0)), {});
  for (std::size_t i = 0; i < segments_.size(); ++i)
    if (seg_curve[i] >= 0) curve_segs_[idx(seg_curve[i])].push_back(static_cast<int>(i));
  for (const std::vector<int>& segs : curve_segs_) {
    std::vector<std::array<int, 3>> tris;
    for (const int g : segs) tris.push_back({segments_[idx(g)].a, segments_[idx(g)].b, segments_[idx(g)].b});
    curve_trees_.emplace_back(points_, tris);
  }
}

void SmoothReference::add_edge_defect(int f, int k, const Vector3d& b, PatchPoint& out) const {
  const Segment& g = segments_[idx(edge_seg_[idx(f)][idx(k)])];
  const int ci = (k + 1) % 3, cj = (k + 2) % 3;
  const double sum = b[ci] + b[cj];
  if (!(sum > 1e-300)) return;  // at corner k the defect vanishes
  const double t = b[cj] / sum;
  const auto& tri = tris_[idx(f)];
  const Vector3d &vi = points_[idx(tri[idx(ci)])], &vj = points_[idx(tri[idx(cj)])];
  const Vector3d pe = (1 - t) * vi + t * vj;
  Matrix3d ji, jj;
  const Vector3d qi = fits_[idx(corner_fit_[idx(f)][idx(ci)])].lift(pe, ji);
  const Vector3d qj = fits_[idx(corner_fit_[idx(f)][idx(cj)])].lift(pe, jj);
  Vector3d dc;
  const bool forward = g.a == tri[idx(ci)];
  const Vector3d c = g.at(forward ? t : 1 - t, dc);
  if (!forward) dc = -dc;
  const Vector3d defect = c - ((1 - t) * qi + t * qj);
  const Vector3d ddefect = dc - (qj - qi + ((1 - t) * ji + t * jj) * (vj - vi));
  // d/db_i and d/db_j of sum * defect(b_j / sum); d/db_k = 0.
  Vector3d grad[3] = {Vector3d::Zero(), Vector3d::Zero(), Vector3d::Zero()};
  grad[ci] = defect - t * ddefect;
  grad[cj] = defect + (1 - t) * ddefect;
  out.x += sum * defect;
  out.d1 += grad[1] - grad[0];
  out.d2 += grad[2] - grad[0];
}

SmoothReference::PatchPoint SmoothReference::evaluate(int f, const Vector3d& b) const {
  const auto& tri = tris_[idx(f)];
  const Vector3d &v0 = points_[idx(tri[0])], &v1 = points_[idx(tri[1])], &v2 = points_[idx(tri[2])];
  const Vector3d p = b[0] * v0 + b[1] * v1 + b[2] * v2;
  std::array<Vector3d, 3> q;
  Matrix3d jsum = Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    Matrix3d j;
    q[idx(k)] = fits_[idx(corner_fit_[idx(f)][idx(k)])].lift(p, j);
    jsum += b[k] * j;
  }
  PatchPoint out;
  out.x = b[0] * q[0] + b[1] * q[1] + b[2] * q[2];
  out.d1 = q[1] - q[0] + jsum * (v1 - v0);
  out.d2 = q[2] - q[0] + jsum * (v2 - v0);
  for (int k = 0; k < 3; ++k)
    if (edge_seg_[idx(f)][idx(k)] >= 0) add_edge_defect(f, k, b, out);
  return out;
}

Vector3d SmoothReference::patch_normal(int f, const PatchPoint& q) const {
  const Vector3d n = q.d1.cross(q.d2);
  const Vector3d& fn = face_normal_[idx(f)];
  // A patch turned more than 90 degrees from its facet (or without a tangent plane) is folded.
  if (!(n.dot(fn) > 0) || !n.allFinite()) return fn;
  return n.normalized();
}

Closest SmoothReference::flat(const TriangleTree::Closest& c) const {
  return {c.point, face_normal_[idx(c.triangle)]};
}

Vector3d SmoothReference::gauss_newton_step(const Vector3d& b, const PatchPoint& q, const Vector3d& r,
                                            const std::array<char, 3>& open) const {
  Eigen::Matrix<double, 3, 2> jac;
  jac << q.d1, q.d2;
  const Eigen::Matrix2d a = jac.transpose() * jac;
  if (!(std::abs(a.determinant()) > 1e-30 * a.squaredNorm())) return Vector3d::Zero();
  Vector2d s = a.inverse() * (jac.transpose() * r);
  // Along an edge the point is on and the step would cross where it cannot (no patch beyond).
  for (int k = 0; k < 3; ++k) {
    const Vector3d d(-s.x() - s.y(), s.x(), s.y());
    if (b[k] > 0 || d[k] >= 0 || open[idx(k)]) continue;
    const Vector2d e = k == 0 ? Vector2d(1, -1) : k == 1 ? Vector2d(0, 1) : Vector2d(1, 0);
    const Vector3d je = jac * e;
    s = je.squaredNorm() > 0 ? Vector2d(je.dot(r) / je.squaredNorm() * e) : Vector2d::Zero();
  }
  return {-s.x() - s.y(), s.x(), s.y()};
}

Closest SmoothReference::closest(const Vector3d& p) const {
  const TriangleTree::Closest start = tree_.closest(p);
  if (flat_[idx(start.triangle)]) return flat(start);
  int f = start.triangle, from = -1, hops = 0;
  Vector3d b = start.barycentric;
  PatchPoint q = evaluate(f, b);
  double r2 = (p - q.x).squaredNorm();
  for (int iter = 0; iter < kMaxIterations; ++iter) {
    std::array<char, 3> open{};  // the edges a step may cross into the next patch
    for (int k = 0; k < 3; ++k) {
      const int g = neighbour_[idx(f)][idx(k)];
      open[idx(k)] = g >= 0 && g != from && hops < kMaxHops && !flat_[idx(g)];
    }
    Vector3d d = gauss_newton_step(b, q, p - q.x, open);
    // Leaving the triangle: stop where the step crosses the first edge.
    double lambda = 1;
    int edge = -1;
    for (int k = 0; k < 3; ++k)
      if (d[k] < 0 && b[k] + lambda * d[k] < 0) {
        lambda = std::max(0.0, b[k] / -d[k]);
        edge = k;
      }
    // Damped inside the triangle: halve the step until the distance does not grow.
    for (int halving = 0; edge < 0 && halving < 30; ++halving) {
      if ((p - evaluate(f, b + d).x).squaredNorm() <= r2) break;
      d *= 0.5;
    }
    Vector3d nb = b + lambda * d;
    if (edge >= 0) nb[edge] = 0;
    nb = nb.cwiseMax(0.0);
    nb /= nb.sum();
    const double change = (nb - b).norm();
    const bool hop = edge >= 0 && open[idx(edge)];
    if (hop) {  // into the next patch, at the same point of the shared edge
      const int g = neighbour_[idx(f)][idx(edge)];
      Vector3d bg = Vector3d::Zero();
      for (int k = 0; k < 3; ++k)
        for (int kk = 0; kk < 3; ++kk)
          if (tris_[idx(g)][idx(kk)] == tris_[idx(f)][idx(k)]) bg[kk] = nb[k];
      from = f;
      f = g;
      nb = bg;
      ++hops;
    }
    b = nb;
    q = evaluate(f, b);
    r2 = (p - q.x).squaredNorm();
    if (!hop && change < kStepTol) break;
  }
  if (!q.x.allFinite()) return flat(start);
  return {q.x, patch_normal(f, q)};
}

Vector3d SmoothReference::closest_on_segment(int seg, const Vector3d& p) const {
  const Segment& g = segments_[idx(seg)];
  Vector3d d;
  double best_t = 0, best = (g.pa - p).squaredNorm();
  for (const double t : {0.25, 0.5, 0.75, 1.0})
    if (const double e = (g.at(t, d) - p).squaredNorm(); e < best) {
      best = e;
      best_t = t;
    }
  double t = best_t;
  for (int iter = 0; iter < 20; ++iter) {  // Newton on (c - p) . c' = 0, clamped to [0, 1]
    const Vector3d x = g.at(t, d);
    const double h = 1e-4;
    Vector3d dp, dm;
    g.at(std::min(t + h, 1.0), dp);
    g.at(std::max(t - h, 0.0), dm);
    const Vector3d dd = (dp - dm) / (std::min(t + h, 1.0) - std::max(t - h, 0.0));
    const double gr = (x - p).dot(d), he = d.squaredNorm() + (x - p).dot(dd);
    const double next = std::clamp(he > 0 ? t - gr / he : (gr > 0 ? 0.0 : 1.0), 0.0, 1.0);
    const bool done = std::abs(next - t) < 1e-15;
    t = next;
    if (done) break;
  }
  const Vector3d x = g.at(t, d);
  return (x - p).squaredNorm() <= best ? x : g.at(best_t, d);
}

Vector3d SmoothReference::project_to_curve(const Vector3d& p, int curve) const {
  if (curve < 0 || curve >= num_curves())
    throw MesherError("smooth reference: curve " + std::to_string(curve) + " does not exist (" +
                      std::to_string(num_curves()) + " curves)");
  const TriangleTree& t = curve_trees_[idx(curve)];
  if (t.size() == 0) return project(p);  // an unused id: no edges carry it
  const int seg = curve_segs_[idx(curve)][idx(t.closest(p).triangle)];
  // The closest polyline segment's curve, or a neighbour's where the curve bulges past it.
  Vector3d best = closest_on_segment(seg, p);
  for (const int other : {segments_[idx(seg)].next_a, segments_[idx(seg)].next_b})
    if (other >= 0)
      if (const Vector3d x = closest_on_segment(other, p); (x - p).squaredNorm() < (best - p).squaredNorm()) best = x;
  return best;
}

}  // namespace

std::unique_ptr<ReferenceGeometry<3>> make_smooth_reference(const TriSurface& input) {
  return std::make_unique<SmoothReference>(input);
}

bool is_smooth_reference(const ReferenceGeometry<3>& r) {
  return dynamic_cast<const SmoothReference*>(&r) != nullptr;
}

}  // namespace plaf
