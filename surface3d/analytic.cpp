// SPDX-License-Identifier: MIT
// Analytic bodies (see analytic.h): exact closest-point references and initial triangulations with
// their features already set.
//
// Layout of this file:
// - MeshBuilder: points, triangles grouped in patches (each patch consistently oriented by
//   construction, reversed as a whole when that order is inward), feature edges
//   and corners, then the TriSurface with its properties.
// - Planar polygon triangulation (ear clipping, then Lawson flips to the constrained Delaunay
//   triangulation of the polygon) for the flat ends of wings.
// - Sphere (refined icosahedron), ellipsoid (a cube lattice mapped to the ellipsoid, closest point
//   by a safeguarded Newton iteration on the Lagrange multiplier), box (a cube lattice).
// - Wing: an extruded spline loop with flat, rounded or symmetry ends. The section is sampled at
//   spacing min(h, 30 degrees of turning), at least 12 points around it; the side is a structured
//   (contour x span) grid; flat ends triangulate the sampled contour polygon; rounded ends are
//   structured rows of half circles at shared chord stations of both surfaces. Feature curves are
//   made of pieces (spanwise ridge lines, end contour arcs, the half circle closing a blunt base)
//   merged where they continue each other smoothly; project_to_curve takes the nearest piece.
#include "surface3d/analytic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "modules/io/airfoil_io.h"
#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "modules/geometry/spline_loop.h"

namespace plaf {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();
// Initial meshes larger than this are refused: h is then surely a unit mistake.
constexpr double kMaxTriangles = 2e7;

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void check_h(const std::string& body, double h, double size) {
  if (!(h > 0) || !std::isfinite(h))
    throw ConfigError(body + ": the mesh size h must be positive and finite, got " + num(h));
  if (4 * (size / h) * (size / h) > kMaxTriangles)
    throw ConfigError(body + ": the mesh size h = " + num(h) + " is too small for a body of size " + num(size) +
                      " (more than " + num(kMaxTriangles) + " initial triangles)");
}

// ------------------------------------------------------------------------------------------------
// Mesh assembly.

class MeshBuilder {
 public:
  int add_point(const Vector3d& p) {
    points_.push_back(p);
    return static_cast<int>(points_.size()) - 1;
  }
  const Vector3d& point(int i) const { return points_[i]; }

  // Triangles of the current patch: all consistently oriented among themselves.
  void add_triangle(int a, int b, int c) { patch_.push_back({a, b, c}); }
  // Quad a, b, c, d in cyclic order: split along its shorter diagonal.
  void add_quad(int a, int b, int c, int d) {
    if ((points_[a] - points_[c]).squaredNorm() <= (points_[b] - points_[d]).squaredNorm()) {
      add_triangle(a, b, c);
      add_triangle(a, c, d);
    } else {
      add_triangle(a, b, d);
      add_triangle(b, c, d);
    }
  }
  // Closes the current patch, reversing its triangles when its construction order is inward.
  void end_patch(bool reverse) {
    for (auto t : patch_) {
      if (reverse) std::swap(t[1], t[2]);
      triangles_.push_back(t);
    }
    patch_.clear();
  }

  void mark_edge(int a, int b, int curve, EdgeFeature feature) {
    features_[{std::min(a, b), std::max(a, b)}] = {curve, feature};
  }
  void mark_polyline(const std::vector<int>& v, int curve, EdgeFeature feature) {
    for (std::size_t k = 0; k + 1 < v.size(); ++k) mark_edge(v[k], v[k + 1], curve, feature);
  }
  void mark_corner(int v, VertexFeature f) { corners_[v] = f; }
  void set_symmetry() { symmetry_ = true; }

  TriSurface build(const std::string& name) const {
    TriSurface s;
    const int wall = s.add_tag("wall", BoundaryKind::Wall);
    const int sym = symmetry_ ? s.add_tag("symmetry", BoundaryKind::Symmetry) : -1;
    std::vector<TriMesh::VertexHandle> vh;
    vh.reserve(points_.size());
    for (const Vector3d& p : points_) vh.push_back(s.mesh.add_vertex(p));
    for (const auto& t : triangles_) {
      const auto f = s.mesh.add_face(vh[t[0]], vh[t[1]], vh[t[2]]);
      if (!f.is_valid())
        throw MesherError(name + ": initial triangulation is not manifold at triangle (" + std::to_string(t[0]) + ", " +
                          std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")");
      s.mesh.property(s.face_tag, f) = wall;
    }
    for (const auto e : s.mesh.edges()) {
      s.mesh.property(s.edge_tag, e) = -1;
      s.mesh.property(s.edge_curve, e) = -1;
      s.mesh.property(s.edge_feature, e) = EdgeFeature::Smooth;
    }
    for (const auto v : s.mesh.vertices()) s.mesh.property(s.vertex_feature, v) = VertexFeature::Smooth;
    for (const auto& [key, info] : features_) {
      const auto h = s.mesh.find_halfedge(vh[key.first], vh[key.second]);
      if (!h.is_valid())
        throw MesherError(name + ": feature edge (" + std::to_string(key.first) + ", " + std::to_string(key.second) +
                          ") is not an edge of the initial triangulation");
      const auto e = s.mesh.edge_handle(h);
      s.mesh.property(s.edge_curve, e) = info.first;
      s.mesh.property(s.edge_feature, e) = info.second;
      for (const auto v : {vh[key.first], vh[key.second]}) s.mesh.property(s.vertex_feature, v) = VertexFeature::Curve;
    }
    for (const auto& [v, f] : corners_) s.mesh.property(s.vertex_feature, vh[v]) = f;
    std::size_t open = 0;
    for (const auto e : s.mesh.edges()) {
      if (!s.mesh.is_boundary(e)) continue;
      if (s.mesh.property(s.edge_feature, e) != EdgeFeature::Boundary || sym < 0) ++open;
      s.mesh.property(s.edge_tag, e) = sym;
    }
    if (open > 0)
      throw MesherError(name + ": initial triangulation has " + std::to_string(open) +
                        " open edges that are not on a symmetry plane");
    return s;
  }

 private:
  std::vector<Vector3d> points_;
  std::vector<std::array<int, 3>> triangles_, patch_;
  std::map<std::pair<int, int>, std::pair<int, EdgeFeature>> features_;
  std::map<int, VertexFeature> corners_;
  bool symmetry_ = false;
};

// ------------------------------------------------------------------------------------------------
// Planar polygon triangulation.

// Triangles (indices into pts, counter-clockwise) of the simple polygon pts (either orientation):
// ear clipping with exact orientation tests, then Lawson flips until every interior edge is
// locally Delaunay (the constrained Delaunay triangulation of the polygon: no small angles that
// the polygon does not force).
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Vector2d>& pts, const std::string& name) {
  const int n = static_cast<int>(pts.size());
  if (n < 3) throw MesherError(name + ": a polygon needs 3 points, got " + std::to_string(n));
  double area = 0;
  for (int i = 0; i < n; ++i) {
    const Vector2d& a = pts[i];
    const Vector2d& b = pts[(i + 1) % n];
    area += a.x() * b.y() - a.y() * b.x();
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (area < 0) std::reverse(order.begin(), order.end());
  std::vector<int> prev(n), next(n);
  for (int k = 0; k < n; ++k) {
    prev[order[k]] = order[(k + n - 1) % n];
    next[order[k]] = order[(k + 1) % n];
  }
  std::vector<std::array<int, 3>> tris;
  int remaining = n, v = order[0], misses = 0;
  const auto inside_closed = [&](const Vector2d& p, int a, int b, int c) {
    return sign_orient2d(pts[a], pts[b], p) >= 0 && sign_orient2d(pts[b], pts[c], p) >= 0 &&
           sign_orient2d(pts[c], pts[a], p) >= 0;
  };
  while (remaining > 3) {
    const int a = prev[v], c = next[v];
    bool ear = sign_orient2d(pts[a], pts[v], pts[c]) > 0;
    for (int w = next[c]; ear && w != a; w = next[w]) {
      if (pts[w] == pts[a] || pts[w] == pts[v] || pts[w] == pts[c]) continue;
      if (inside_closed(pts[w], a, v, c)) ear = false;
    }
    if (ear) {
      tris.push_back({a, v, c});
      next[a] = c;
      prev[c] = a;
      --remaining;
      v = c;
      misses = 0;
    } else {
      v = next[v];
      if (++misses > remaining) throw MesherError(name + ": the polygon is not simple (no ear left to clip)");
    }
  }
  tris.push_back({prev[v], v, next[v]});

  // Lawson flips: an interior edge (a, b) with opposite vertices c (in a, b, c) and d (in b, a, d)
  // is flipped to (c, d) when d is inside the circumcircle of a, b, c and the quad is convex.
  // Inexact in-circle test with a relative margin: a flip needs a clear gain, so cocircular
  // configurations never flip back and forth.
  const auto incircle = [&](int a, int b, int c, int d) {
    const Vector2d pa = pts[a] - pts[d], pb = pts[b] - pts[d], pc = pts[c] - pts[d];
    const double det = pa.squaredNorm() * (pb.x() * pc.y() - pb.y() * pc.x()) -
                       pb.squaredNorm() * (pa.x() * pc.y() - pa.y() * pc.x()) +
                       pc.squaredNorm() * (pa.x() * pb.y() - pa.y() * pb.x());
    const double size = std::max({pa.squaredNorm(), pb.squaredNorm(), pc.squaredNorm()});
    return det > 1e-10 * size * size;
  };
  for (int sweep = 0; sweep < 10 * n; ++sweep) {
    std::map<std::pair<int, int>, std::pair<int, int>> edge_to;  // directed edge -> (triangle, local index)
    for (int t = 0; t < static_cast<int>(tris.size()); ++t)
      for (int k = 0; k < 3; ++k) edge_to[{tris[t][k], tris[t][(k + 1) % 3]}] = {t, k};
    bool flipped = false;
    std::vector<bool> touched(tris.size(), false);
    for (const auto& [e, tk] : edge_to) {
      const auto it = edge_to.find({e.second, e.first});
      if (it == edge_to.end()) continue;
      const int t1 = tk.first, t2 = it->second.first;
      if (touched[t1] || touched[t2]) continue;
      const int a = e.first, b = e.second;
      const int c = tris[t1][(tk.second + 2) % 3], d = tris[t2][(it->second.second + 2) % 3];
      if (!incircle(a, b, c, d)) continue;
      if (sign_orient2d(pts[c], pts[d], pts[b]) <= 0 || sign_orient2d(pts[d], pts[c], pts[a]) <= 0) continue;
      tris[t1] = {c, d, b};
      tris[t2] = {d, c, a};
      touched[t1] = touched[t2] = true;
      flipped = true;
    }
    if (!flipped) break;
  }
  return tris;
}

// Whether the closed polygon is simple (no two non-adjacent edges meet; exact tests).
bool polygon_is_simple(const std::vector<Vector2d>& p) {
  const int n = static_cast<int>(p.size());
  if (n < 3) return false;
  for (int i = 0; i < n; ++i) {
    if (p[i] == p[(i + 1) % n]) return false;
    for (int j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) continue;
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
    }
  }
  return true;
}

// ------------------------------------------------------------------------------------------------
// Cube lattice: the surface points of the lattice {0..n[0]} x {0..n[1]} x {0..n[2]}, each face a
// structured grid of quads split along the shorter diagonal, outward oriented for a map that
// preserves the orientation of the cube. Returns the vertex ids keyed by lattice index.

struct CubeLattice {
  std::array<int, 3> n;
  std::unordered_map<long long, int> ids;
  long long key(int i, int j, int k) const { return (static_cast<long long>(k) * (n[1] + 1) + j) * (n[0] + 1) + i; }
  int id(int i, int j, int k) const { return ids.at(key(i, j, k)); }
};

template <class Map>
CubeLattice build_cube(MeshBuilder& mb, const std::array<int, 3>& n, const Map& map) {
  CubeLattice lat{n, {}};
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) {
        if (i != 0 && i != n[0] && j != 0 && j != n[1] && k != 0 && k != n[2]) continue;
        lat.ids[lat.key(i, j, k)] = mb.add_point(map(i, j, k));
      }
  for (int a = 0; a < 3; ++a) {
    // Axes b, c follow a cyclically, so (b, c) is counter-clockwise seen from +a.
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int q = 0; q < n[b]; ++q)
        for (int r = 0; r < n[c]; ++r) {
          std::array<int, 4> quad;
          const std::array<std::array<int, 2>, 4> br = {{{q, r}, {q + 1, r}, {q + 1, r + 1}, {q, r + 1}}};
          for (int m = 0; m < 4; ++m) {
            std::array<int, 3> ijk{};
            ijk[a] = side == 0 ? 0 : n[a];
            ijk[b] = br[m][0];
            ijk[c] = br[m][1];
            quad[m] = lat.id(ijk[0], ijk[1], ijk[2]);
          }
          if (side == 0)
            mb.add_quad(quad[0], quad[3], quad[2], quad[1]);
          else
            mb.add_quad(quad[0], quad[1], quad[2], quad[3]);
        }
    }
  }
  return lat;
}

// ------------------------------------------------------------------------------------------------
// Sphere.

class SphereReference final : public ReferenceGeometry<3> {
 public:
  SphereReference(const Vector3d& c, double r) : c_(c), r_(r) {}
  Vector3d project(const Vector3d& p) const override { return c_ + r_ * direction(p); }
  Vector3d normal(const Vector3d& x) const override { return direction(x); }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    throw MesherError("sphere: no feature curve " + std::to_string(curve) + " (a sphere has none); point " +
                      num(p.x()) + " " + num(p.y()) + " " + num(p.z()));
  }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * std::sqrt(3.0) * r_; }

 private:
  Vector3d direction(const Vector3d& p) const {
    const Vector3d d = p - c_;
    const double len = d.norm();
    return len > 0 ? Vector3d(d / len) : Vector3d::UnitZ();  // the centre: any point is closest
  }
  Vector3d c_;
  double r_;
};

// ------------------------------------------------------------------------------------------------
// Ellipsoid.

// Closest point of the ellipsoid sum (x_i / e_i)^2 = 1 to y (both relative to the centre).
// Stationary points are x_i = e_i^2 y_i / (e_i^2 + t); the closest one has the largest multiplier
// t, the root of F(t) = sum (e_i y_i / (e_i^2 + t))^2 - 1 on (-min e_i^2, inf) over the components
// with y_i != 0 (F decreases there from +inf to -1). When that root lies below -e_k^2 for the
// smallest axis k with y_k = 0 (points inside, near the plane y_k = 0), the closest point leaves
// that plane: t = -e_k^2 and x_k follows from the constraint.
Vector3d ellipsoid_closest(const Vector3d& e, const Vector3d& y) {
  Vector3d q = y.cwiseAbs(), x = Vector3d::Zero();
  int kmin = 0;
  for (int i = 1; i < 3; ++i)
    if (e[i] < e[kmin]) kmin = i;
  double m = kInf;
  for (int i = 0; i < 3; ++i)
    if (q[i] > 0) m = std::min(m, e[i] * e[i]);
  double t = -kInf;
  if (m < kInf) {
    const auto F = [&](double s, double* dF) {
      double f = -1, d = 0;
      for (int i = 0; i < 3; ++i) {
        if (q[i] == 0) continue;
        const double w = e[i] * q[i] / (e[i] * e[i] + s);
        f += w * w;
        d -= 2 * w * w / (e[i] * e[i] + s);
      }
      *dF = d;
      return f;
    };
    double lo = -m, hi = std::max(0.0, e.maxCoeff() * q.norm());
    t = hi;
    for (int iter = 0; iter < 300; ++iter) {
      double d = 0;
      const double f = F(t, &d);
      if (f == 0) break;
      if (f > 0)
        lo = t;
      else
        hi = t;
      double next = d < 0 ? t - f / d : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - t) <= 4 * kEps * std::max(std::abs(t), m) ||
          hi - lo <= 4 * kEps * std::max(std::abs(lo), m)) {
        t = next;
        break;
      }
      t = next;
    }
  }
  const double ek2 = e[kmin] * e[kmin];
  if (q[kmin] == 0 && t < -ek2) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      if (i == kmin || q[i] == 0) continue;
      x[i] = e[i] * e[i] * q[i] / (e[i] * e[i] - ek2);
      sum += (x[i] / e[i]) * (x[i] / e[i]);
    }
    x[kmin] = e[kmin] * std::sqrt(std::max(0.0, 1 - sum));
  } else {
    // Components whose denominator e_i^2 + t is tiny carry a large relative error (the
    // cancellation in e_i^2 + t): rescale them together so the constraint holds, keeping their
    // mutual ratios (exact when their axes are equal).
    double rest = 1, stiff = 0;
    std::array<bool, 3> is_stiff{};
    for (int i = 0; i < 3; ++i) {
      if (q[i] == 0) continue;
      const double den = e[i] * e[i] + t;
      x[i] = e[i] * e[i] * q[i] / den;
      const double w = (x[i] / e[i]) * (x[i] / e[i]);
      is_stiff[i] = den < 1e-3 * e[i] * e[i];
      if (is_stiff[i])
        stiff += w;
      else
        rest -= w;
    }
    if (stiff > 0) {
      const double lambda = std::sqrt(std::max(0.0, rest) / stiff);
      for (int i = 0; i < 3; ++i)
        if (is_stiff[i]) x[i] *= lambda;
    }
  }
  // Final exact normalisation (a relative change of a few ulps).
  const double g = std::sqrt((x.cwiseQuotient(e)).squaredNorm());
  if (g > 0) x /= g;
  for (int i = 0; i < 3; ++i)
    if (y[i] < 0) x[i] = -x[i];
  return x;
}

class EllipsoidReference final : public ReferenceGeometry<3> {
 public:
  EllipsoidReference(const Vector3d& c, const Vector3d& e) : c_(c), e_(e) {}
  Vector3d project(const Vector3d& p) const override { return c_ + ellipsoid_closest(e_, p - c_); }
  Vector3d normal(const Vector3d& x) const override {
    const Vector3d f = ellipsoid_closest(e_, x - c_);
    return f.cwiseQuotient(e_.cwiseProduct(e_)).normalized();
  }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    throw MesherError("ellipsoid: no feature curve " + std::to_string(curve) + " (an ellipsoid has none); point " +
                      num(p.x()) + " " + num(p.y()) + " " + num(p.z()));
  }
  int num_curves() const override { return 0; }
  double scale() const override { return 2 * e_.norm(); }

 private:
  Vector3d c_, e_;
};

// ------------------------------------------------------------------------------------------------
// Box.

class BoxReference final : public ReferenceGeometry<3> {
 public:
  BoxReference(const Vector3d& lo, const Vector3d& hi) : lo_(lo), hi_(hi) {}
  Vector3d project(const Vector3d& p) const override {
    const Vector3d c = p.cwiseMax(lo_).cwiseMin(hi_);
    if (c != p) return c;  // outside: the clamp is the closest point
    const auto [axis, side] = nearest_face(p);
    Vector3d out = p;
    out[axis] = side ? hi_[axis] : lo_[axis];
    return out;
  }
  Vector3d normal(const Vector3d& x) const override {
    const auto [axis, side] = nearest_face(x);
    Vector3d n = Vector3d::Zero();
    n[axis] = side ? 1 : -1;
    return n;
  }
  // Curve 4 a + 2 sb + sc: the edge along axis a at the lo (0) / hi (1) sides sb, sc of the two
  // following axes b = a + 1, c = a + 2 (mod 3).
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    if (curve < 0 || curve >= 12) throw MesherError("box: no feature curve " + std::to_string(curve));
    const int a = curve / 4, b = (a + 1) % 3, c = (a + 2) % 3;
    Vector3d out;
    out[a] = std::clamp(p[a], lo_[a], hi_[a]);
    out[b] = (curve & 2) ? hi_[b] : lo_[b];
    out[c] = (curve & 1) ? hi_[c] : lo_[c];
    return out;
  }
  int num_curves() const override { return 12; }
  double scale() const override { return (hi_ - lo_).norm(); }

 private:
  // The face nearest to x (inside or on the box; outside, the face x is farthest beyond).
  std::pair<int, bool> nearest_face(const Vector3d& x) const {
    int axis = 0;
    bool side = false;
    double best = kInf;
    for (int a = 0; a < 3; ++a) {
      const double dl = x[a] - lo_[a], dh = hi_[a] - x[a];
      if (dl < best) best = dl, axis = a, side = false;
      if (dh < best) best = dh, axis = a, side = true;
    }
    return {axis, side};
  }
  Vector3d lo_, hi_;
};

// ------------------------------------------------------------------------------------------------
// Wing.

// Exact closest parameter of the loop to x restricted to [t0, t1] (t1 > t0, unwrapped): the
// global closest point when it lies in the range, else the best of a dense sampling refined by a
// bracketed root of (p(t) - x) . p'(t).
double closest_on_range(const SplineLoop& loop, const Vector2d& x, double t0, double t1) {
  const double P = loop.period();
  const SplineLoop::Closest g = loop.closest_point(x);
  double tg = g.t;
  while (tg < t0) tg += P;
  while (tg >= t0 + P) tg -= P;
  if (tg <= t1 || t1 - t0 >= P) return tg;
  const int samples = std::max(8, static_cast<int>(std::ceil((t1 - t0) * 16)));
  double best_t = t0, best_d = kInf;
  for (int k = 0; k <= samples; ++k) {
    const double t = t0 + (t1 - t0) * k / samples;
    const double d = (loop.point(t) - x).squaredNorm();
    if (d < best_d) best_d = d, best_t = t;
  }
  const double step = (t1 - t0) / samples;
  double lo = std::max(t0, best_t - step), hi = std::min(t1, best_t + step);
  const auto f = [&](double t) { return (loop.point(t) - x).dot(loop.derivative(t)); };
  double flo = f(lo), fhi = f(hi);
  if (flo < 0 && fhi > 0) {
    for (int iter = 0; iter < 200 && hi - lo > 4 * kEps * std::max(1.0, std::abs(hi)); ++iter) {
      const double mid = 0.5 * (lo + hi);
      const double fm = f(mid);
      if (fm == 0) {
        lo = hi = mid;
        break;
      }
      (fm < 0 ? lo : hi) = mid;
    }
    const double r = 0.5 * (lo + hi);
    if ((loop.point(r) - x).squaredNorm() < best_d) best_t = r;
  }
  return best_t;
}

// One end of a wing rounded as a half body of revolution: at station s in [0, 1] the arcs from
// the leading edge (minimum x) to the trailing-edge corner(s) give points P1(s), P2(s) at the same
// normalised chord station x = x_le + s^2 (x_te - x_le) (the square makes the arcs' parameters
// smooth in s at the leading edge, where x is quadratic in the spline parameter); the cap is
// C(s, theta) = M + r (cos theta d + sin theta e), M = (P1 + P2) / 2, r = |P1 - P2| / 2,
// d = (P1 - P2) / (2 r), e = the outward span direction, theta in [0, pi]. At theta = 0, pi it
// meets the extrusion with the tangent e: tangent-continuous. The arc parameter as a function of s
// is tabulated (bisection on the monotone x) and interpolated by cubic Hermite pieces, so the cap
// is an exactly defined smooth surface with analytic derivatives.
class RoundedCap {
 public:
  RoundedCap(const SplineLoop* loop, double t_le, double t_a, double t_b, double z, double dir, bool sharp)
      : loop_(loop), t_le_(t_le), t_a_(t_a), t_b_(t_b), z_(z), dir_(dir), sharp_(sharp) {
    x_le_ = loop_->point(t_le_).x();
    for (int arc = 0; arc < 2; ++arc) {
      const double x_end = loop_->point(arc == 0 ? t_a_ : t_b_).x();
      std::vector<double>& u = table_[arc];
      u.assign(kTable + 1, 0.0);
      u[kTable] = 1;
      for (int m = 1; m < kTable; ++m) {
        const double s = static_cast<double>(m) / kTable;
        const double target = x_le_ + s * s * (x_end - x_le_);
        double lo = 0, hi = 1;
        for (int iter = 0; iter < 60; ++iter) {
          const double mid = 0.5 * (lo + hi);
          (loop_->point(arc_t(arc, mid)).x() < target ? lo : hi) = mid;
        }
        u[m] = 0.5 * (lo + hi);
      }
      std::vector<double>& du = slope_[arc];
      du.assign(kTable + 1, 0.0);
      const double ds = 1.0 / kTable;
      du[0] = (-3 * u[0] + 4 * u[1] - u[2]) / (2 * ds);
      du[kTable] = (3 * u[kTable] - 4 * u[kTable - 1] + u[kTable - 2]) / (2 * ds);
      for (int m = 1; m < kTable; ++m) du[m] = (u[m + 1] - u[m - 1]) / (2 * ds);
    }
    // Bounding box of the cap: a dense grid of its points, padded by the largest grid spacing
    // (the surface never strays farther than that from its grid).
    constexpr int kRows = 4 * kSamples, kCols = 16;
    double pad = 0;
    std::vector<Vector3d> row_prev;
    for (int m = 0; m <= kRows; ++m) {
      const Section c = section(static_cast<double>(m) / kRows);
      std::vector<Vector3d> row;
      for (int k = 0; k <= kCols; ++k) {
        row.push_back(at(c, M_PI * k / kCols));
        box_.extend(row.back());
        if (k > 0) pad = std::max(pad, (row[k] - row[k - 1]).norm());
        if (m > 0) pad = std::max(pad, (row[k] - row_prev[k]).norm());
      }
      row_prev = std::move(row);
    }
    box_.min().array() -= pad;
    box_.max().array() += pad;
  }
  // A lower bound on the distance from p to the cap.
  double distance_bound(const Vector3d& p) const { return box_.exteriorDistance(p); }

  // Spline parameter of arc 0 (leading edge to t_a) or 1 (leading edge to t_b) at fraction u.
  double arc_t(int arc, double u) const { return t_le_ + u * ((arc == 0 ? t_a_ : t_b_) - t_le_); }
  // The arc's spline parameter at station s, and its derivative.
  std::pair<double, double> station_t(int arc, double s) const {
    s = std::clamp(s, 0.0, 1.0);
    const double ds = 1.0 / kTable;
    const int m = std::min(static_cast<int>(s * kTable), kTable - 1);
    const double w = s * kTable - m;
    const std::vector<double>& u = table_[arc];
    const std::vector<double>& du = slope_[arc];
    const double h00 = (1 + 2 * w) * (1 - w) * (1 - w), h10 = w * (1 - w) * (1 - w);
    const double h01 = w * w * (3 - 2 * w), h11 = w * w * (w - 1);
    const double g00 = 6 * w * w - 6 * w, g10 = 3 * w * w - 4 * w + 1, g01 = -g00, g11 = 3 * w * w - 2 * w;
    const double val = h00 * u[m] + h10 * ds * du[m] + h01 * u[m + 1] + h11 * ds * du[m + 1];
    const double der = (g00 * u[m] + g10 * ds * du[m] + g01 * u[m + 1] + g11 * ds * du[m + 1]) / ds;
    const double span = (arc == 0 ? t_a_ : t_b_) - t_le_;
    return {arc_t(arc, val), der * span};
  }

  struct Section {
    Vector3d m, d, e, dm, dd;
    double r, dr;
  };
  Section section(double s) const {
    const auto [t1, dt1] = station_t(0, s);
    const auto [t2, dt2] = station_t(1, s);
    const Vector2d p1 = loop_->point(t1);
    const Vector2d p2 = (sharp_ && s >= 1) ? p1 : loop_->point(t2);
    const Vector2d dp1 = loop_->derivative(t1) * dt1, dp2 = loop_->derivative(t2) * dt2;
    Section c;
    const Vector2d w = p1 - p2, dw = dp1 - dp2;
    const double len = w.norm();
    c.m = Vector3d(0.5 * (p1.x() + p2.x()), 0.5 * (p1.y() + p2.y()), z_);
    c.dm = Vector3d(0.5 * (dp1.x() + dp2.x()), 0.5 * (dp1.y() + dp2.y()), 0);
    c.e = Vector3d(0, 0, dir_);
    c.r = 0.5 * len;
    if (len > 0) {
      const Vector2d d = w / len;
      c.d = Vector3d(d.x(), d.y(), 0);
      c.dr = 0.5 * d.dot(dw);
      const Vector2d dd = (dw - d * d.dot(dw)) / len;
      c.dd = Vector3d(dd.x(), dd.y(), 0);
    } else {
      c.d = Vector3d::UnitY();
      c.dr = 0.5 * dw.norm();
      c.dd = Vector3d::Zero();
    }
    return c;
  }
  static Vector3d at(const Section& c, double theta) {
    return c.m + c.r * (std::cos(theta) * c.d + std::sin(theta) * c.e);
  }
  // Closest angle of the section's half circle to p.
  static double closest_theta(const Section& c, const Vector3d& p) {
    const Vector3d w = p - c.m;
    const double a = w.dot(c.d), b = w.dot(c.e);
    if (b <= 0) return a >= 0 ? 0.0 : M_PI;
    return std::atan2(b, a);
  }

  struct Foot {
    double s = 0, theta = 0;
    Vector3d point;
    double distance = kInf;
  };
  Foot closest(const Vector3d& p) const {
    const auto eval = [&](double s) {
      const Section c = section(s);
      const double th = closest_theta(c, p);
      Foot f{s, th, at(c, th), 0};
      f.distance = (p - f.point).norm();
      return f;
    };
    // g(s) = half the derivative of the squared distance (envelope theorem over theta).
    const auto g = [&](double s) {
      const Section c = section(s);
      const double th = closest_theta(c, p);
      const Vector3d dir = std::cos(th) * c.d + std::sin(th) * c.e;
      const Vector3d cs = c.dm + c.dr * dir + c.r * std::cos(th) * c.dd;
      return -(p - at(c, th)).dot(cs);
    };
    Foot best;
    int best_m = 0;
    for (int m = 0; m <= kSamples; ++m) {
      const Foot f = eval(static_cast<double>(m) / kSamples);
      if (f.distance < best.distance) best = f, best_m = m;
    }
    double lo = static_cast<double>(std::max(0, best_m - 1)) / kSamples;
    double hi = static_cast<double>(std::min(kSamples, best_m + 1)) / kSamples;
    for (const double s : {lo, hi}) {
      const Foot f = eval(s);
      if (f.distance < best.distance) best = f;
    }
    double glo = g(lo), ghi = g(hi);
    if (glo < 0 && ghi > 0) {
      // Illinois regula falsi with a bisection fallback: converges to the root to rounding.
      int side = 0;
      for (int iter = 0; iter < 200 && hi - lo > 2 * kEps; ++iter) {
        double s = (lo * ghi - hi * glo) / (ghi - glo);
        if (!(s > lo && s < hi) || iter % 8 == 7) s = 0.5 * (lo + hi);
        const double gs = g(s);
        if (gs == 0) {
          lo = hi = s;
          break;
        }
        if (gs < 0) {
          lo = s, glo = gs;
          if (side == -1) ghi *= 0.5;
          side = -1;
        } else {
          hi = s, ghi = gs;
          if (side == 1) glo *= 0.5;
          side = 1;
        }
      }
      const Foot f = eval(0.5 * (lo + hi));
      if (f.distance <= best.distance) best = f;
    }
    return best;
  }

  Vector3d normal(double s, double theta) const {
    // Away from the degenerate leading and trailing edges the normal is C_s x C_theta; at them
    // the limit from inside is used.
    s = std::clamp(s, 1e-7, 1 - 1e-7);
    const Section c = section(s);
    const Vector3d dir = std::cos(theta) * c.d + std::sin(theta) * c.e;
    const Vector3d cs = c.dm + c.dr * dir + c.r * std::cos(theta) * c.dd;
    const Vector3d ct = c.r * (-std::sin(theta) * c.d + std::cos(theta) * c.e);
    Vector3d n = cs.cross(ct);
    if (!(n.norm() > 0)) return dir;
    n.normalize();
    return n.dot(dir) < 0 ? Vector3d(-n) : n;
  }
  double z() const { return z_; }
  double dir() const { return dir_; }
  double max_radius() const {
    double r = 0;
    for (int m = 0; m <= kSamples; ++m) r = std::max(r, section(static_cast<double>(m) / kSamples).r);
    return r;
  }

 private:
  static constexpr int kTable = 512;
  static constexpr int kSamples = 64;
  const SplineLoop* loop_;
  double t_le_, t_a_, t_b_, z_, dir_;
  bool sharp_;
  double x_le_ = 0;
  std::array<std::vector<double>, 2> table_, slope_;
  Eigen::AlignedBox3d box_;
};

struct CurvePiece {
  enum Kind { Span, Contour, HalfCircle } kind;
  double t0 = 0, t1 = 0;  // Span: corner parameter t0; Contour: the range [t0, t1] (unwrapped)
  double z0 = 0, z1 = 0;  // Span: [z0, z1]; Contour: z0
  int end = 0;            // HalfCircle: the end (0 root, 1 tip)
};

class WingReference final : public ReferenceGeometry<3> {
 public:
  WingReference(SplineLoop loop, double span, std::array<WingEnd, 2> ends, std::vector<int> te_corners)
      : loop_(std::move(loop)), span_(span), ends_(ends) {
    for (int c : loop_.corners()) {
      corner_t_.push_back(c);
      corner_convex_.push_back(turning_angle(loop_.points(), c) < 0);
    }
    if (ends_[0] == WingEnd::Rounded || ends_[1] == WingEnd::Rounded) {
      // Leading edge: the minimum of x on the spline, near the leftmost point.
      const auto& pts = loop_.points();
      int i = 0;
      for (int k = 1; k < loop_.num_points(); ++k)
        if (pts[k].x() < pts[i].x()) i = k;
      double lo = i - 1.0, hi = i + 1.0;
      for (int iter = 0; iter < 100; ++iter) {
        const double mid = 0.5 * (lo + hi);
        (loop_.derivative(mid).x() < 0 ? lo : hi) = mid;
      }
      t_le_ = 0.5 * (lo + hi);
      const double P = loop_.period();
      if (t_le_ < 0) t_le_ += P;
      // The trailing-edge corners reached going forward (t_a) and backward (t_b) from it.
      t_a_ = kInf, t_b_ = -kInf;
      for (int c : te_corners) {
        double fwd = c, bwd = c;
        while (fwd <= t_le_) fwd += P;
        while (bwd >= t_le_) bwd -= P;
        t_a_ = std::min(t_a_, fwd);
        t_b_ = std::max(t_b_, bwd);
      }
      sharp_ = te_corners.size() == 1;
      for (int end = 0; end < 2; ++end)
        if (ends_[end] == WingEnd::Rounded)
          caps_[end] = std::make_unique<RoundedCap>(&loop_, t_le_, t_a_, t_b_, end == 0 ? 0.0 : span_,
                                                    end == 0 ? -1.0 : 1.0, sharp_);
    }
    Eigen::AlignedBox3d box;
    const double P = loop_.period();
    for (int k = 0; k < 16 * loop_.num_points(); ++k) {
      const Vector2d q = loop_.point(P * k / (16.0 * loop_.num_points()));
      box.extend(Vector3d(q.x(), q.y(), 0));
      box.extend(Vector3d(q.x(), q.y(), span_));
    }
    for (const auto& cap : caps_)
      if (cap) box.extend(Vector3d(box.min().x(), box.min().y(), cap->z() + cap->dir() * cap->max_radius()));
    scale_ = box.diagonal().norm();
  }

  const SplineLoop& loop() const { return loop_; }
  double span() const { return span_; }
  WingEnd end(int e) const { return ends_[e]; }
  const RoundedCap* cap(int e) const { return caps_[e].get(); }
  double t_le() const { return t_le_; }
  double t_a() const { return t_a_; }
  double t_b() const { return t_b_; }
  bool sharp() const { return sharp_; }
  const std::vector<double>& corner_t() const { return corner_t_; }
  const std::vector<bool>& corner_convex() const { return corner_convex_; }
  std::vector<std::vector<CurvePiece>>& curves() { return curves_; }

  Vector3d project(const Vector3d& p) const override { return locate(p).point; }
  Vector3d normal(const Vector3d& x) const override { return locate(x).normal(*this); }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override {
    if (curve < 0 || curve >= num_curves())
      throw MesherError("wing: no feature curve " + std::to_string(curve) + " (it has " + std::to_string(num_curves()) +
                        ")");
    Vector3d best = Vector3d::Zero();
    double best_d = kInf;
    for (const CurvePiece& c : curves_[curve]) {
      Vector3d q;
      if (c.kind == CurvePiece::Span) {
        const Vector2d xy = loop_.point(c.t0);
        q = Vector3d(xy.x(), xy.y(), std::clamp(p.z(), c.z0, c.z1));
      } else if (c.kind == CurvePiece::Contour) {
        const Vector2d xy = loop_.point(closest_on_range(loop_, p.head<2>(), c.t0, c.t1));
        q = Vector3d(xy.x(), xy.y(), c.z0);
      } else {
        const RoundedCap::Section s = caps_[c.end]->section(1.0);
        q = RoundedCap::at(s, RoundedCap::closest_theta(s, p));
      }
      if ((q - p).norm() < best_d) best_d = (q - p).norm(), best = q;
    }
    return best;
  }
  int num_curves() const override { return static_cast<int>(curves_.size()); }
  double scale() const override { return scale_; }

 private:
  struct Foot {
    enum Part { Side, Flat, Cap, Base } part = Side;
    Vector3d point;
    double distance = kInf;
    double t = 0;             // Side: the loop parameter
    int end = 0;              // Flat, Cap, Base
    double s = 0, theta = 0;  // Cap
    Vector3d normal(const WingReference& w) const {
      switch (part) {
        case Side:
          return w.side_normal(t);
        case Flat:
          return Vector3d(0, 0, end == 0 ? -1 : 1);
        case Cap:
          return w.caps_[end]->normal(s, theta);
        case Base:
          return w.side_normal(w.t_a_ + 0.5);
      }
      return Vector3d::UnitZ();
    }
  };

  // Outward normal of the extrusion at loop parameter t (at a corner: the mean of both sides).
  Vector3d side_normal(double t) const {
    const double P = loop_.period();
    for (double c : corner_t_) {
      double d = std::fmod(t - c, P);
      if (d < 0) d += P;
      if (d < 1e-9 || P - d < 1e-9) {
        const Vector2d n = (loop_.normal(c - 1e-9) + loop_.normal(c + 1e-9)).normalized();
        return Vector3d(n.x(), n.y(), 0);
      }
    }
    const Vector2d n = loop_.normal(t);
    return Vector3d(n.x(), n.y(), 0);
  }

  // Whether 2D point xy lies inside the section (c: its closest loop point).
  bool inside(const Vector2d& xy, const SplineLoop::Closest& c) const {
    const Vector2d w = xy - c.point;
    Vector2d n = loop_.normal(c.t);
    for (double t : corner_t_)
      if (std::abs(c.t - t) < 1e-9 || std::abs(c.t - t - loop_.period()) < 1e-9)
        n = loop_.normal(t - 1e-9) + loop_.normal(t + 1e-9);
    return w.dot(n) < 0;
  }

  Foot locate(const Vector3d& p) const {
    const Vector2d xy = p.head<2>();
    const SplineLoop::Closest c = loop_.closest_point(xy);
    Foot best;
    best.part = Foot::Side;
    best.t = c.t;
    best.point = Vector3d(c.point.x(), c.point.y(), std::clamp(p.z(), 0.0, span_));
    best.distance = (p - best.point).norm();
    const bool in = c.distance > 0 && inside(xy, c);
    for (int end = 0; end < 2; ++end) {
      const double z = end == 0 ? 0.0 : span_;
      if (ends_[end] == WingEnd::Flat && in && std::abs(p.z() - z) < best.distance) {
        best.part = Foot::Flat;
        best.end = end;
        best.point = Vector3d(p.x(), p.y(), z);
        best.distance = std::abs(p.z() - z);
      } else if (ends_[end] == WingEnd::Rounded && caps_[end]->distance_bound(p) < best.distance) {
        const RoundedCap::Foot f = caps_[end]->closest(p);
        if (f.distance < best.distance) {
          best.part = Foot::Cap;
          best.end = end;
          best.s = f.s;
          best.theta = f.theta;
          best.point = f.point;
          best.distance = f.distance;
        }
        if (!sharp_) {
          // The flat half disc closing the blunt base under the cap's last half circle.
          const RoundedCap::Section s = caps_[end]->section(1.0);
          const Vector3d w = p - s.m;
          const double a = w.dot(s.d), b = w.dot(s.e);
          const Vector3d n = s.d.cross(s.e);
          if (b >= 0 && a * a + b * b <= s.r * s.r && std::abs(w.dot(n)) < best.distance) {
            best.part = Foot::Base;
            best.end = end;
            best.point = p - w.dot(n) * n;
            best.distance = std::abs(w.dot(n));
          }
        }
      }
    }
    return best;
  }

  SplineLoop loop_;
  double span_;
  std::array<WingEnd, 2> ends_;
  std::vector<double> corner_t_;
  std::vector<bool> corner_convex_;
  double t_le_ = 0, t_a_ = 0, t_b_ = 0;
  bool sharp_ = true;
  std::array<std::unique_ptr<RoundedCap>, 2> caps_;
  std::vector<std::vector<CurvePiece>> curves_;
  double scale_ = 1;
};

// Union-find over curve pieces (pieces that continue each other smoothly form one curve).
struct UnionFind {
  std::vector<int> parent;
  int add() {
    parent.push_back(static_cast<int>(parent.size()));
    return parent.back();
  }
  int find(int i) { return parent[i] == i ? i : parent[i] = find(parent[i]); }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

// Contour samples of a wing section, in loop order (unwrapped increasing parameters).
struct ContourSamples {
  std::vector<double> t;
  std::vector<int> corner_index;  // sample index of each loop corner (in loop_.corners() order)
  // Rounded ends only: stations s_j and the sample index of each station on both arcs.
  std::vector<double> stations;
  std::vector<int> arc1, arc2;
};

// The contour is sampled at spacing min(h, kTurn * radius of curvature): the initial triangles
// are about h, but their chords never cut across a leading edge much smaller than h (a chord
// turning more would leave the wing's faces facing away from the surface they approximate).
// A floor of kMinSamples around the section keeps coarse h (of the order of the chord) from
// collapsing a thin section's surface into single chords.
constexpr double kTurn = M_PI / 6;
constexpr int kMinSamples = 12;

// Inverts a cumulative table: the abscissa (linear in the table) where `cum` reaches `target`.
double invert_table(const std::vector<double>& x, const std::vector<double>& cum, double target) {
  const auto it = std::upper_bound(cum.begin(), cum.end(), target);
  const int m = std::clamp(static_cast<int>(it - cum.begin()) - 1, 0, static_cast<int>(cum.size()) - 2);
  const double w = cum[m + 1] > cum[m] ? std::clamp((target - cum[m]) / (cum[m + 1] - cum[m]), 0.0, 1.0) : 0.0;
  return x[m] + w * (x[m + 1] - x[m]);
}

// Samples t0 < ... < t_{n-1} in [t0, t1) of one corner-to-corner run (at least min_n).
std::vector<double> graded_samples(const SplineLoop& loop, double t0, double t1, double h, int min_n) {
  const int fine = 32 * std::max(1, static_cast<int>(std::ceil(t1 - t0)));
  std::vector<double> ts(fine + 1), cum(fine + 1, 0.0);
  Vector2d prev = loop.point(t0);
  for (int k = 0; k <= fine; ++k) {
    ts[k] = t0 + (t1 - t0) * k / fine;
    if (k == 0) continue;
    const Vector2d q = loop.point(ts[k]);
    const double kappa = std::abs(loop.curvature(0.5 * (ts[k - 1] + ts[k])));
    cum[k] = cum[k - 1] + (q - prev).norm() * std::max(1 / h, kappa / kTurn);
    prev = q;
  }
  const int n = std::max(min_n, static_cast<int>(std::lround(cum[fine])));
  std::vector<double> out = {t0};
  for (int q = 1; q < n; ++q) out.push_back(invert_table(ts, cum, cum[fine] * q / n));
  return out;
}

ContourSamples sample_by_corners(const WingReference& w, double h) {
  const SplineLoop& loop = w.loop();
  ContourSamples out;
  const std::vector<double>& corners = w.corner_t();
  const double P = loop.period();
  std::vector<double> starts = corners;
  if (starts.empty()) starts.push_back(0.0);
  const int nc = static_cast<int>(starts.size());
  for (int m = 0; m < nc; ++m) {
    const double t0 = starts[m], t1 = m + 1 < nc ? starts[m + 1] : starts[0] + P;
    if (!corners.empty()) out.corner_index.push_back(static_cast<int>(out.t.size()));
    const int min_n =
        std::max(nc == 1 ? 3 : 1, static_cast<int>(std::lround(kMinSamples * loop.arc_length(t0, t1) / loop.length())));
    for (double t : graded_samples(loop, t0, t1, h, min_n)) out.t.push_back(t);
  }
  return out;
}

// Samples at shared chord stations of both arcs (rounded ends), then the blunt base.
ContourSamples sample_by_stations(const WingReference& w, const RoundedCap& cap, double h) {
  const SplineLoop& loop = w.loop();
  // Stations graded as in graded_samples, on the mean of both arcs' lengths and curvatures.
  constexpr int kFine = 2048;
  std::vector<double> sigma(kFine + 1), cum(kFine + 1, 0.0);
  Vector2d prev1 = loop.point(w.t_le()), prev2 = prev1;
  for (int m = 0; m <= kFine; ++m) {
    sigma[m] = static_cast<double>(m) / kFine;
    if (m == 0) continue;
    const double s = sigma[m];
    const Vector2d p1 = loop.point(cap.station_t(0, s).first), p2 = loop.point(cap.station_t(1, s).first);
    const double mid = 0.5 * (sigma[m - 1] + s);
    const double kappa = std::max(std::abs(loop.curvature(cap.station_t(0, mid).first)),
                                  std::abs(loop.curvature(cap.station_t(1, mid).first)));
    cum[m] = cum[m - 1] + 0.5 * ((p1 - prev1).norm() + (p2 - prev2).norm()) * std::max(1 / h, kappa / kTurn);
    prev1 = p1;
    prev2 = p2;
  }
  const int J = std::max(kMinSamples / 2, static_cast<int>(std::lround(cum[kFine])));
  ContourSamples out;
  out.stations.resize(J + 1);
  for (int j = 0; j <= J; ++j) out.stations[j] = std::clamp(invert_table(sigma, cum, cum[kFine] * j / J), 0.0, 1.0);
  out.stations[0] = 0;
  out.stations[J] = 1;
  const double P = loop.period();
  out.t.push_back(w.t_le());
  for (int j = 1; j <= J; ++j) out.t.push_back(cap.station_t(0, out.stations[j]).first);
  out.arc1.resize(J + 1);
  out.arc2.resize(J + 1);
  for (int j = 0; j <= J; ++j) out.arc1[j] = j;
  out.t[J] = w.t_a();
  int te2 = J;
  if (!w.sharp()) {
    const double tb = w.t_b() + P;  // the base runs from t_a to t_b + P
    const double len = loop.arc_length(w.t_a(), tb);
    const int nb = std::max(1, static_cast<int>(std::lround(len / h)));
    for (int q = 1; q < nb; ++q) out.t.push_back(w.t_a() + (tb - w.t_a()) * q / nb);
    out.t.push_back(tb);
    te2 = static_cast<int>(out.t.size()) - 1;
  }
  out.arc2[0] = 0;
  out.arc2[J] = te2;
  for (int j = J - 1; j >= 1; --j) {
    out.arc2[j] = static_cast<int>(out.t.size());
    out.t.push_back(cap.station_t(1, out.stations[j]).first + P);
  }
  // Corner samples, in the loop's corner order.
  for (double c : w.corner_t()) {
    int best = 0;
    for (int i = 0; i < static_cast<int>(out.t.size()); ++i) {
      const double d = std::abs(std::remainder(out.t[i] - c, P));
      if (d < std::abs(std::remainder(out.t[best] - c, P))) best = i;
    }
    out.corner_index.push_back(best);
  }
  return out;
}

void build_wing_mesh(WingReference& ref, const ContourSamples& cs, double h, MeshBuilder& mb, const std::string& name) {
  const SplineLoop& loop = ref.loop();
  const double span = ref.span();
  const int M = static_cast<int>(cs.t.size());
  const int K = std::max(1, static_cast<int>(std::lround(span / h)));
  std::vector<std::vector<int>> V(M, std::vector<int>(K + 1));
  for (int i = 0; i < M; ++i) {
    const Vector2d xy = loop.point(cs.t[i]);
    for (int k = 0; k <= K; ++k) V[i][k] = mb.add_point(Vector3d(xy.x(), xy.y(), span * k / K));
  }
  // Side: quads in (contour, span) order, whose normal tangent x e_z is the loop's right normal:
  // inward, since the body loop is clockwise (its left normal points out of the body).
  for (int i = 0; i < M; ++i)
    for (int k = 0; k < K; ++k) mb.add_quad(V[i][k], V[(i + 1) % M][k], V[(i + 1) % M][k + 1], V[i][k + 1]);
  mb.end_patch(true);

  // Curve pieces and their mesh edges; pieces merge into curves through the union-find.
  UnionFind uf;
  struct PieceEdges {
    CurvePiece piece;
    std::vector<int> vertices;
    EdgeFeature feature;
  };
  std::vector<PieceEdges> pieces;
  const auto add_piece = [&](const CurvePiece& c, std::vector<int> vs, EdgeFeature f) {
    uf.add();
    pieces.push_back({c, std::move(vs), f});
    return static_cast<int>(pieces.size()) - 1;
  };
  const int nc = static_cast<int>(ref.corner_t().size());
  std::vector<int> span_piece(nc);
  for (int c = 0; c < nc; ++c) {
    std::vector<int> vs;
    for (int k = 0; k <= K; ++k) vs.push_back(V[cs.corner_index[c]][k]);
    CurvePiece p{CurvePiece::Span, ref.corner_t()[c], 0, 0, span, 0};
    span_piece[c] = add_piece(p, vs, ref.corner_convex()[c] ? EdgeFeature::ConvexRidge : EdgeFeature::ConcaveRidge);
  }

  for (int end = 0; end < 2; ++end) {
    const int kz = end == 0 ? 0 : K;
    const double z = end == 0 ? 0.0 : span;
    const WingEnd type = ref.end(end);
    if (type == WingEnd::Flat || type == WingEnd::Symmetry) {
      const EdgeFeature f = type == WingEnd::Flat ? EdgeFeature::ConvexRidge : EdgeFeature::Boundary;
      if (type == WingEnd::Symmetry) mb.set_symmetry();
      // The end contour split at the corners.
      std::vector<int> starts = cs.corner_index;
      std::sort(starts.begin(), starts.end());
      if (starts.empty()) starts.push_back(0);
      for (std::size_t m = 0; m < starts.size(); ++m) {
        const int i0 = starts[m];
        const int i1 = m + 1 < starts.size() ? starts[m + 1] : starts[0] + M;
        std::vector<int> vs;
        for (int i = i0; i <= i1; ++i) vs.push_back(V[i % M][kz]);
        double t0 = cs.t[i0], t1 = i1 < M ? cs.t[i1] : cs.t[i1 - M] + loop.period();
        if (t1 <= t0) t1 += loop.period();
        add_piece({CurvePiece::Contour, t0, t1, z, z, end}, vs, f);
      }
      for (int c = 0; c < nc; ++c) {
        const int v = V[cs.corner_index[c]][kz];
        if (type == WingEnd::Symmetry)
          mb.mark_corner(v, VertexFeature::BoundaryCorner);
        else
          mb.mark_corner(v, ref.corner_convex()[c] ? VertexFeature::ConvexCorner : VertexFeature::SaddleCorner);
      }
      if (type == WingEnd::Flat) {
        std::vector<Vector2d> poly(M);
        for (int i = 0; i < M; ++i) poly[i] = mb.point(V[i][kz]).head<2>();
        // Counter-clockwise in (x, y): normal +z, outward at the tip, inward at the root.
        for (const auto& t : triangulate_polygon(poly, name + " flat end"))
          mb.add_triangle(V[t[0]][kz], V[t[1]][kz], V[t[2]][kz]);
        mb.end_patch(end == 0);
      }
      continue;
    }
    // Rounded end: rows of the cap at the stations, each a half circle from arc 1 to arc 2.
    const RoundedCap& cap = *ref.cap(end);
    const int J = static_cast<int>(cs.stations.size()) - 1;
    std::vector<std::vector<int>> rows(J + 1);
    for (int j = 0; j <= J; ++j) {
      const RoundedCap::Section sec = cap.section(cs.stations[j]);
      const int a = V[cs.arc1[j]][kz], b = V[cs.arc2[j]][kz];
      rows[j].push_back(a);
      if (a == b) continue;
      const int n = std::max(2, static_cast<int>(std::lround(M_PI * sec.r / h)));
      for (int k = 1; k < n; ++k) rows[j].push_back(mb.add_point(RoundedCap::at(sec, M_PI * k / n)));
      rows[j].push_back(b);
    }
    for (int j = 0; j < J; ++j) {
      const std::vector<int>& A = rows[j];
      const std::vector<int>& B = rows[j + 1];
      const int na = static_cast<int>(A.size()) - 1, nb = static_cast<int>(B.size()) - 1;
      int ia = 0, ib = 0;
      while (ia < na || ib < nb) {
        // Advance the row whose next point comes first in normalised angle (in (s, theta),
        // A is the left column and B the right one; both triangles below are counter-clockwise).
        const bool step_a = ib == nb || (ia < na && (ia + 1.0) / na <= (ib + 1.0) / nb);
        if (step_a) {
          mb.add_triangle(A[ia], B[ib], A[ia + 1]);
          ++ia;
        } else {
          mb.add_triangle(A[ia], B[ib], B[ib + 1]);
          ++ib;
        }
      }
    }
    // Counter-clockwise in (s, theta): normal C_s x C_theta, compared with the outward radial
    // direction at the top of a mid-chord section.
    {
      const RoundedCap::Section sec = cap.section(0.5);
      const Vector3d c_s = sec.dm + sec.dr * sec.e;
      const Vector3d ct = -sec.r * sec.d;
      mb.end_patch(c_s.cross(ct).dot(sec.e) < 0);
    }
    if (ref.sharp()) {
      for (int c = 0; c < nc; ++c)
        mb.mark_corner(V[cs.corner_index[c]][kz],
                       ref.corner_convex()[c] ? VertexFeature::ConvexCorner : VertexFeature::ConcaveCorner);
    } else {
      // The blunt base closed by a flat half disc; its half circle continues both TE ridges.
      const std::vector<int>& last = rows[J];
      const int hc = add_piece({CurvePiece::HalfCircle, 0, 0, z, z, end}, last, EdgeFeature::ConvexRidge);
      for (int c = 0; c < nc; ++c) uf.unite(span_piece[c], hc);
      const RoundedCap::Section sec = cap.section(1.0);
      std::vector<int> poly_ids = last;
      for (int i = cs.arc2[J] - 1; i > cs.arc1[J]; --i) poly_ids.push_back(V[i][kz]);
      std::vector<Vector2d> poly;
      for (int v : poly_ids) {
        const Vector3d w = mb.point(v) - sec.m;
        poly.emplace_back(w.dot(sec.d), w.dot(sec.e));
      }
      // Counter-clockwise in (d, e): normal d x e, against the base's outward normal.
      for (const auto& t : triangulate_polygon(poly, name + " rounded end base"))
        mb.add_triangle(poly_ids[t[0]], poly_ids[t[1]], poly_ids[t[2]]);
      const Vector2d nb = loop.normal(ref.t_a() + 0.5);
      mb.end_patch(sec.d.cross(sec.e).dot(Vector3d(nb.x(), nb.y(), 0)) < 0);
    }
  }

  // Number the curves by first appearance and mark their edges.
  std::map<int, int> curve_of_root;
  auto& curves = ref.curves();
  for (int p = 0; p < static_cast<int>(pieces.size()); ++p) {
    const int root = uf.find(p);
    auto it = curve_of_root.find(root);
    if (it == curve_of_root.end()) {
      it = curve_of_root.emplace(root, static_cast<int>(curves.size())).first;
      curves.emplace_back();
    }
    curves[it->second].push_back(pieces[p].piece);
    mb.mark_polyline(pieces[p].vertices, it->second, pieces[p].feature);
  }
}

}  // namespace

// ------------------------------------------------------------------------------------------------

AnalyticBody make_sphere(const Eigen::Vector3d& center, double radius, double h) {
  if (!center.allFinite()) throw ConfigError("sphere: the centre must be finite");
  if (!(radius > 0) || !std::isfinite(radius)) throw ConfigError("sphere: radius must be positive, got " + num(radius));
  check_h("sphere", h, 2 * radius);
  AnalyticBody body;
  body.reference = std::make_unique<SphereReference>(center, radius);
  // Icosahedron: the cyclic permutations of (0, +-1, +-phi).
  const double phi = 0.5 * (1 + std::sqrt(5.0));
  std::vector<Vector3d> ico;
  for (int perm = 0; perm < 3; ++perm)
    for (double a : {-1.0, 1.0})
      for (double b : {-phi, phi}) {
        Vector3d v;
        v[perm] = 0;
        v[(perm + 1) % 3] = a;
        v[(perm + 2) % 3] = b;
        ico.push_back(v.normalized());
      }
  // Faces: triples of mutually adjacent vertices (edge length 2 before normalisation), outward.
  double min_edge = kInf;
  for (std::size_t i = 0; i < ico.size(); ++i)
    for (std::size_t j = i + 1; j < ico.size(); ++j) min_edge = std::min(min_edge, (ico[i] - ico[j]).norm());
  const auto adjacent = [&](std::size_t i, std::size_t j) { return (ico[i] - ico[j]).norm() < 1.01 * min_edge; };
  std::vector<std::array<int, 3>> faces;
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = i + 1; j < 12; ++j)
      for (std::size_t k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) {
          std::array<int, 3> f = {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
          if ((ico[j] - ico[i]).cross(ico[k] - ico[i]).dot(ico[i]) < 0) std::swap(f[1], f[2]);
          faces.push_back(f);
        }
  // Frequency n: the projected icosahedron edge (angle atan(2) ~ 63.4 degrees) cut into ~h pieces.
  const int n = std::max(1, static_cast<int>(std::lround(std::atan(2.0) * radius / h)));
  MeshBuilder mb;
  std::map<std::array<int, 4>, int> ids;  // canonical barycentric key -> vertex
  const auto vertex = [&](int fi, int i, int j) {
    const std::array<int, 3>& f = faces[fi];
    // Weights of (f0, f1, f2) = (n - i - j, i, j); the key lists the nonzero ones by vertex id.
    std::array<std::pair<int, int>, 3> w = {{{f[0], n - i - j}, {f[1], i}, {f[2], j}}};
    std::sort(w.begin(), w.end());
    std::array<int, 4> key = {-1, -1, -1, -1};
    int used = 0, nonzero = 0;
    for (const auto& [v, wt] : w)
      if (wt > 0) ++nonzero;
    if (nonzero == 3) {
      key = {1000 + fi, i, j, 0};
    } else {
      for (const auto& [v, wt] : w)
        if (wt > 0 && used < 2) key[2 * used] = v, key[2 * used + 1] = wt, ++used;
    }
    const auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    const Vector3d p = (n - i - j) * ico[f[0]] + i * ico[f[1]] + j * ico[f[2]];
    const int id = mb.add_point(center + radius * p.normalized());
    ids[key] = id;
    return id;
  };
  for (int fi = 0; fi < static_cast<int>(faces.size()); ++fi)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        mb.add_triangle(vertex(fi, i, j), vertex(fi, i + 1, j), vertex(fi, i, j + 1));
        if (i + j + 1 < n) mb.add_triangle(vertex(fi, i + 1, j), vertex(fi, i + 1, j + 1), vertex(fi, i, j + 1));
      }
  mb.end_patch(false);  // sub-triangles keep the outward order of their icosahedron face
  body.initial = mb.build("sphere");
  return body;
}

AnalyticBody make_ellipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& semi_axes, double h) {
  if (!center.allFinite()) throw ConfigError("ellipsoid: the centre must be finite");
  if (!semi_axes.allFinite() || !(semi_axes.minCoeff() > 0))
    throw ConfigError("ellipsoid: semi-axes must be positive, got " + num(semi_axes.x()) + " " + num(semi_axes.y()) +
                      " " + num(semi_axes.z()));
  check_h("ellipsoid", h, 2 * semi_axes.maxCoeff());
  AnalyticBody body;
  body.reference = std::make_unique<EllipsoidReference>(center, semi_axes);
  // A cube lattice mapped to the ellipsoid: cube coordinates w in [-1, 1]^3 with equal-angle
  // spacing (w = tan(pi/4 u)), the unit sphere point w / |w|, scaled by the semi-axes. The
  // divisions per axis follow the lengths of the quarter ellipse arcs they map to, so the
  // triangles stay roughly uniform (~h) whatever the axis ratios.
  const auto to_surface = [&](const Vector3d& w) -> Vector3d {
    return center + semi_axes.cwiseProduct(w.normalized());
  };
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) {
    double len = 0;
    for (int other = 1; other <= 2; ++other) {
      const int b = (a + other) % 3;
      double l = 0;
      Vector3d prev;
      for (int m = 0; m <= 64; ++m) {
        Vector3d w = Vector3d::Zero();
        w[a] = std::tan(M_PI / 4 * (-1 + 2.0 * m / 64));
        w[b] = 1;
        const Vector3d p = to_surface(w);
        if (m > 0) l += (p - prev).norm();
        prev = p;
      }
      len = std::max(len, l);
    }
    n[a] = std::max(1, static_cast<int>(std::lround(len / h)));
  }
  MeshBuilder mb;
  build_cube(mb, n, [&](int i, int j, int k) {
    const Vector3d u(-1 + 2.0 * i / n[0], -1 + 2.0 * j / n[1], -1 + 2.0 * k / n[2]);
    Vector3d w;
    for (int a = 0; a < 3; ++a) w[a] = std::tan(M_PI / 4 * u[a]);
    return to_surface(w);
  });
  mb.end_patch(false);  // the map keeps the cube's orientation
  body.initial = mb.build("ellipsoid");
  return body;
}

AnalyticBody make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h) {
  if (!lo.allFinite() || !hi.allFinite() || !((hi - lo).minCoeff() > 0))
    throw ConfigError("box: need lo < hi in every coordinate, got lo = (" + num(lo.x()) + ", " + num(lo.y()) + ", " +
                      num(lo.z()) + "), hi = (" + num(hi.x()) + ", " + num(hi.y()) + ", " + num(hi.z()) + ")");
  check_h("box", h, (hi - lo).maxCoeff());
  AnalyticBody body;
  body.reference = std::make_unique<BoxReference>(lo, hi);
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::lround((hi[a] - lo[a]) / h)));
  MeshBuilder mb;
  const CubeLattice lat = build_cube(mb, n, [&](int i, int j, int k) {
    const std::array<int, 3> ijk = {i, j, k};
    Vector3d p;
    // Exact end values (no rounding at hi), uniform in between.
    for (int a = 0; a < 3; ++a) p[a] = ijk[a] == n[a] ? hi[a] : lo[a] + (hi[a] - lo[a]) * ijk[a] / n[a];
    return p;
  });
  mb.end_patch(false);
  // The 12 edges (curve 4 a + 2 sb + sc, as BoxReference) and the 8 corners.
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int sb = 0; sb < 2; ++sb)
      for (int sc = 0; sc < 2; ++sc) {
        std::vector<int> vs;
        for (int m = 0; m <= n[a]; ++m) {
          std::array<int, 3> ijk{};
          ijk[a] = m;
          ijk[b] = sb ? n[b] : 0;
          ijk[c] = sc ? n[c] : 0;
          vs.push_back(lat.id(ijk[0], ijk[1], ijk[2]));
        }
        mb.mark_polyline(vs, 4 * a + 2 * sb + sc, EdgeFeature::ConvexRidge);
      }
  }
  for (int corner = 0; corner < 8; ++corner)
    mb.mark_corner(lat.id(corner & 1 ? n[0] : 0, corner & 2 ? n[1] : 0, corner & 4 ? n[2] : 0),
                   VertexFeature::ConvexCorner);
  body.initial = mb.build("box");
  return body;
}

AnalyticBody make_wing(const WingParams& params, double h) {
  const std::string name = "wing " + params.file.string();
  if (!(params.chord > 0) || !std::isfinite(params.chord))
    throw ConfigError(name + ": chord must be positive, got " + num(params.chord));
  if (!(params.span > 0) || !std::isfinite(params.span))
    throw ConfigError(name + ": span must be positive, got " + num(params.span));
  if (!(params.corner_angle_deg > 0 && params.corner_angle_deg < 180))
    throw ConfigError(name + ": corner_angle_deg must be in (0, 180), got " + num(params.corner_angle_deg));
  check_h(name, h, std::max(params.chord, params.span));
  BodyContour contour = read_body_contour(params.file);
  for (Vector2d& p : contour.points) p *= params.chord;
  std::vector<int> corners = detect_corners(contour.points, params.corner_angle_deg);
  corners.insert(corners.end(), contour.corners.begin(), contour.corners.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const std::array<WingEnd, 2> ends = {params.root, params.tip};
  const bool rounded = ends[0] == WingEnd::Rounded || ends[1] == WingEnd::Rounded;
  if (rounded) {
    std::vector<int> te = contour.corners;
    std::sort(te.begin(), te.end());
    for (int c : corners)
      if (!std::binary_search(te.begin(), te.end(), c))
        throw InputError(contour.file + ":" + std::to_string(contour.lines[c]) +
                         ": a rounded wing end needs a section whose only corners are at the trailing edge, but the " +
                         "contour turns by more than " + num(params.corner_angle_deg) + " degrees here");
  }
  const int n = static_cast<int>(contour.points.size());
  if (rounded && contour.corners.size() == 2) {
    const int a = contour.corners[0], b = contour.corners[1];
    if (!((b - a) == 1 || (a == 0 && b == n - 1)))
      throw InputError(name + ": the blunt trailing edge corners are not adjacent points");
  }
  AnalyticBody body;
  auto ref = std::make_unique<WingReference>(SplineLoop(contour.points, corners, contour.file), params.span, ends,
                                             contour.corners);
  if (rounded) {
    // The rounded cap pairs the two surfaces at equal chord stations: x must increase from the
    // leading edge to the trailing edge along both.
    const SplineLoop& loop = ref->loop();
    for (int arc = 0; arc < 2; ++arc) {
      const double t_end = arc == 0 ? ref->t_a() : ref->t_b();
      const int samples = 64 * n;
      double prev = loop.point(ref->t_le()).x();
      for (int k = 1; k <= samples; ++k) {
        const double x = loop.point(ref->t_le() + (t_end - ref->t_le()) * k / samples).x();
        if (x < prev - 1e-9 * params.chord)
          throw InputError(name + ": a rounded end needs x increasing from the leading edge to the trailing edge on " +
                           "both surfaces of the section");
        prev = std::max(prev, x);
      }
    }
  }
  // Contour samples: refined until the sampled section polygon is simple (coarse h on thin
  // sections could make chords cross).
  ContourSamples cs;
  double h_contour = h;
  for (int attempt = 0;; ++attempt) {
    const RoundedCap* cap = ref->cap(0) ? ref->cap(0) : ref->cap(1);
    cs = cap ? sample_by_stations(*ref, *cap, h_contour) : sample_by_corners(*ref, h_contour);
    std::vector<Vector2d> poly;
    for (double t : cs.t) poly.push_back(ref->loop().point(t));
    if (polygon_is_simple(poly)) break;
    if (attempt >= 8) throw MesherError(name + ": could not sample the section contour as a simple polygon");
    h_contour *= 0.5;
  }
  MeshBuilder mb;
  build_wing_mesh(*ref, cs, h, mb, name);
  body.initial = mb.build(name);
  body.reference = std::move(ref);
  return body;
}

}  // namespace plaf
