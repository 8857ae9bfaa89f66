// SPDX-License-Identifier: MIT
// The discrete reference geometry (reference.h): the input triangulation itself. Projection is the
// exact closest point on the triangles (AABB tree). The normal at a surface point blends
// angle-weighted vertex normals by the barycentric coordinates, so it varies continuously across
// smooth regions instead of jumping at every input edge; vertices on feature edges keep the
// face's own normal, so a ridge is never rounded off. Feature curves are the polylines of the
// edges carrying each curve id, and projecting onto one is the closest point on its segments.
#include "surface3d/discrete_reference.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "modules/base/error.h"
#include "modules/geometry/aabb_tree.h"
#include "surface3d/features.h"

namespace plaf {

using Eigen::Vector3d;

namespace {

std::size_t idx(int i) {
  return static_cast<std::size_t>(i);
}

// The angle at a between the directions to b and c (atan2 form: accurate near 0 and pi).
double corner_angle(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d u = b - a, v = c - a;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

// The edges (a, b) of one curve chained into polylines: start at an end (a vertex with an odd
// number of the curve's edges, one for a simple open curve) while there is one, else anywhere (a
// closed loop), and walk to unused edges. Each candidate start is tried once, so the walk is
// linear in the curve's edges.
std::vector<std::vector<Vector3d>> chain_polylines(const std::vector<std::pair<int, int>>& edges,
                                                   const std::vector<Vector3d>& points) {
  std::vector<std::vector<Vector3d>> polylines;
  std::vector<std::pair<int, int>> ends;  // (vertex, edge) incidences, sorted by vertex
  for (std::size_t i = 0; i < edges.size(); ++i) {
    ends.emplace_back(edges[i].first, static_cast<int>(i));
    ends.emplace_back(edges[i].second, static_cast<int>(i));
  }
  std::sort(ends.begin(), ends.end());
  auto incident = [&](int v) {
    const auto lo = std::lower_bound(ends.begin(), ends.end(), std::make_pair(v, -1));
    auto hi = lo;
    while (hi != ends.end() && hi->first == v) ++hi;
    return std::make_pair(lo, hi);
  };
  std::vector<int> odd;
  for (std::size_t i = 0; i < ends.size();) {
    std::size_t j = i;
    while (j < ends.size() && ends[j].first == ends[i].first) ++j;
    if ((j - i) % 2 == 1) odd.push_back(ends[i].first);
    i = j;
  }
  std::vector<char> used(edges.size(), 0);
  std::size_t n_used = 0, next_odd = 0, next_edge = 0;
  auto has_free_edge = [&](int v) {
    const auto [lo, hi] = incident(v);
    return std::any_of(lo, hi, [&](const std::pair<int, int>& x) { return !used[idx(x.second)]; });
  };
  while (n_used < edges.size()) {
    int start = -1;
    while (start < 0 && next_odd < odd.size()) {
      if (has_free_edge(odd[next_odd])) start = odd[next_odd];
      ++next_odd;
    }
    while (start < 0) {
      if (!used[next_edge]) start = edges[next_edge].first;
      ++next_edge;
    }
    std::vector<Vector3d> line = {points[idx(start)]};
    for (int v = start;;) {
      const auto [lo, hi] = incident(v);
      auto it = lo;
      while (it != hi && used[idx(it->second)]) ++it;
      if (it == hi) break;
      const auto& e = edges[idx(it->second)];
      used[idx(it->second)] = 1;
      ++n_used;
      v = e.first == v ? e.second : e.first;
      line.push_back(points[idx(v)]);
    }
    polylines.push_back(std::move(line));
  }
  return polylines;
}

// The polylines' segments as degenerate triangles (a, b, b) in a tree, for O(log n) closest
// points.
TriangleTree segment_tree(const std::vector<std::vector<Vector3d>>& polylines) {
  std::vector<Vector3d> seg_points;
  std::vector<std::array<int, 3>> segs;
  for (const auto& line : polylines) {
    const int first = static_cast<int>(seg_points.size());
    seg_points.insert(seg_points.end(), line.begin(), line.end());
    for (int i = 0; i + 1 < static_cast<int>(line.size()); ++i)
      segs.push_back({first + i, first + i + 1, first + i + 1});
  }
  return TriangleTree(seg_points, segs);
}

class DiscreteReference final : public ReferenceGeometry<3> {
 public:
  explicit DiscreteReference(const TriSurface& s);

  Vector3d project(const Vector3d& p) const override { return tree_.closest(p).point; }
  Vector3d project(const Vector3d& p, Vector3d& normal_out) const override {
    const TriangleTree::Closest c = tree_.closest(p);
    normal_out = blended_normal(c);
    return c.point;
  }
  Vector3d normal(const Vector3d& x) const override { return blended_normal(tree_.closest(x)); }
  Vector3d project_to_curve(const Vector3d& p, int curve) const override;
  int num_curves() const override { return static_cast<int>(curves_.size()); }
  double scale() const override { return scale_; }
  // The cone points are sorted by x: a query scans only those within tol in x (a body with many
  // cone points, e.g. a scan's noisy vertices, made the judged detector's per-vertex queries
  // quadratic).
  bool is_cone_point(const Vector3d& x, double tol) const override {
    auto it = std::lower_bound(cone_points_.begin(), cone_points_.end(), x.x() - tol,
                               [](const Vector3d& c, double v) { return c.x() < v; });
    for (; it != cone_points_.end() && it->x() <= x.x() + tol; ++it)
      if ((*it - x).norm() <= tol) return true;
    return false;
  }

 private:
  // tris_, their unit normals, and the angle-weighted unit vertex normals.
  void add_normals(const TriSurface& s);
  // The closest face's normal blended with its vertices' (feature vertices take the face's).
  Vector3d blended_normal(const TriangleTree::Closest& c) const;
  std::vector<Vector3d> points_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<Vector3d> face_normal_;    // unit (zero for a degenerate face)
  std::vector<Vector3d> vertex_normal_;  // unit, angle weighted
  std::vector<char> on_feature_;         // the vertex touches a feature edge
  std::vector<Vector3d> cone_points_;    // corners on no feature edge (is_cone_point), sorted by x
  TriangleTree tree_;
  // Per curve: the segments of its ordered polylines (one for a simple curve) as degenerate
  // triangles (a, b, b) in a tree, for O(log n) closest points.
  std::vector<TriangleTree> curves_;
  double scale_ = 0;
};

DiscreteReference::DiscreteReference(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  points_ = vertex_points(s, scale_);
  if (m.n_faces() == 0) throw MesherError("discrete reference: the surface has no faces");
  add_normals(s);
  tree_ = TriangleTree(points_, tris_);

  // Feature edges by curve; a boundary or ridge edge without a curve id is still a feature for
  // the normals.
  on_feature_.assign(points_.size(), 0);
  const int n_curves = s.num_curves();
  std::vector<std::vector<std::pair<int, int>>> curve_edges(idx(n_curves));
  for (const auto e : m.edges()) {
    const int c = m.property(s.edge_curve, e);
    const bool feature = c >= 0 || m.property(s.edge_feature, e) != EdgeFeature::Smooth || m.is_boundary(e);
    const auto h = m.halfedge_handle(e, 0);
    const int a = m.from_vertex_handle(h).idx(), b = m.to_vertex_handle(h).idx();
    if (feature) on_feature_[idx(a)] = on_feature_[idx(b)] = 1;
    if (c >= 0) curve_edges[idx(c)].emplace_back(a, b);
  }
  for (int c = 0; c < n_curves; ++c) curves_.push_back(segment_tree(chain_polylines(curve_edges[idx(c)], points_)));
  for (const auto v : m.vertices())
    if (is_corner(m.property(s.vertex_feature, v)) && !on_feature_[idx(v.idx())]) cone_points_.push_back(points_[idx(v.idx())]);
  std::sort(cone_points_.begin(), cone_points_.end(), [](const Vector3d& a, const Vector3d& b) { return a.x() < b.x(); });
}

void DiscreteReference::add_normals(const TriSurface& s) {
  const TriMesh& m = s.mesh;
  vertex_normal_.assign(points_.size(), Vector3d::Zero());
  std::vector<int> at(m.n_faces(), -1);  // each face's position in tris_
  for (const auto f : m.faces()) {
    at[idx(f.idx())] = static_cast<int>(tris_.size());
    const auto fv = s.face_vertices(f);
    const std::array<int, 3> t = {fv[0].idx(), fv[1].idx(), fv[2].idx()};
    tris_.push_back(t);
    const Vector3d &a = points_[idx(t[0])], &b = points_[idx(t[1])], &c = points_[idx(t[2])];
    const Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    face_normal_.push_back(len > 0 ? Vector3d(n / len) : Vector3d::Zero());
  }
  // A folded cap (validate.h's: largest angle over 170 degrees, and here inverted, features.h:
  // back to back with the sheet across two or three of its edges) is a fold of the triangulation,
  // not of the body: its normal says nothing of the body's at its corners, and it counts for
  // nothing in their normals. Counted, it turns the angle-weighted normal at its tip, where its
  // weight is the largest: the cap's corner (near 180 degrees) and its fan's nearly cancel. The
  // published Orion capsule's caps (0.29 long, largest angle 179.7 degrees, the sheet in a
  // 20-degree wedge around them) turned their tips' normals 82 degrees from the body's (another,
  // 177.9 degrees, 90). The remesher then took the edges at a tip for wraps around a tight turn
  // (remesher.h: one measured 7.05 in the metric, its chord 0.16 at a size of about 0.15), refused
  // their collapses for the lengths and the tip's moves for the cap's turning, and the fold
  // repair's flips and split for the alignment: the tip never moved and the input's cap stayed a
  // fold through all 8 rounds of the graded pass and the sliver passes (3 folded triangles, one
  // per cap). Only caps: an inverted face with no corner near 180 degrees weighs no more than its
  // neighbours, and beside a cap its neighbour across a ridge over 90 degrees reads as inverted
  // too (on the Orion, a face of the body at a 99-degree ridge beside its 6-long needle cap: left
  // out in an experiment, it turned a ridge vertex's normal 22 degrees, and a fold was left among
  // the needles). The
  // face keeps its own normal where it is the one taken: at feature vertices, and where the
  // blend cancels.
  const std::vector<char> inverted = inverted_faces(m);
  const double cap = 170 * M_PI / 180;
  for (const auto f : m.faces()) {
    const std::array<int, 3>& t = tris_[idx(at[idx(f.idx())])];
    const Vector3d &a = points_[idx(t[0])], &b = points_[idx(t[1])], &c = points_[idx(t[2])];
    const std::array<double, 3> angle = {corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)};
    if (inverted[idx(f.idx())] && std::max({angle[0], angle[1], angle[2]}) > cap) continue;
    const Vector3d& unit = face_normal_[idx(at[idx(f.idx())])];
    for (std::size_t k = 0; k < 3; ++k) vertex_normal_[idx(t[k])] += angle[k] * unit;
  }
  for (Vector3d& n : vertex_normal_) {
    const double len = n.norm();
    if (len > 0) n /= len;
  }
}

Vector3d DiscreteReference::blended_normal(const TriangleTree::Closest& c) const {
  const auto f = idx(c.triangle);
  const Vector3d& fn = face_normal_[f];
  Vector3d n = Vector3d::Zero();
  for (std::size_t k = 0; k < 3; ++k) {
    const auto v = idx(tris_[f][k]);
    n += c.barycentric[static_cast<Eigen::Index>(k)] * (on_feature_[v] ? fn : vertex_normal_[v]);
  }
  // Opposite vertex normals (a knife edge not marked as a feature) can cancel: fall back to the
  // face.
  const double len = n.norm();
  return len > 0.5 ? Vector3d(n / len) : fn;
}

Vector3d DiscreteReference::project_to_curve(const Vector3d& p, int curve) const {
  if (curve < 0 || curve >= num_curves())
    throw MesherError("discrete reference: curve " + std::to_string(curve) + " does not exist (" +
                      std::to_string(num_curves()) + " curves)");
  const TriangleTree& t = curves_[idx(curve)];
  if (t.size() == 0) return project(p);  // an unused id: no edges carry it
  return t.closest(p).point;
}

}  // namespace

std::unique_ptr<ReferenceGeometry<3>> make_discrete_reference(const TriSurface& input) {
  return std::make_unique<DiscreteReference>(input);
}

std::vector<Vector3d> vertex_points(const TriSurface& s, double& diagonal) {
  std::vector<Vector3d> points(s.mesh.n_vertices(), Vector3d::Zero());
  Eigen::AlignedBox3d box;
  for (const auto v : s.mesh.vertices()) {
    points[static_cast<std::size_t>(v.idx())] = s.mesh.point(v);
    box.extend(s.mesh.point(v));
  }
  diagonal = box.isEmpty() ? 0.0 : box.diagonal().norm();
  return points;
}

}  // namespace plaf
