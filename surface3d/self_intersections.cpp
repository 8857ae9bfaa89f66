// SPDX-License-Identifier: MIT
// Step 7 of validate_surface, and count_self_intersections (validate.h): triangle pairs from the
// bounding-box tree's overlapping boxes tested exactly (predicates.h); pairs sharing a vertex or
// an edge count only where they overlap beyond what they share.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "modules/base/error.h"
#include "modules/geometry/predicates.h"
#include "surface3d/validate_steps.h"

namespace plaf {

using Eigen::Vector2d;
using Eigen::Vector3d;
using validate_detail::fmt_point;
using validate_detail::idx;
using validate_detail::plural;
using validate_detail::Tri;

namespace {

// A coordinate plane on which triangle abc projects without degenerating (exactly), as the two
// kept axes; {-1, -1} for a degenerate triangle.
std::pair<int, int> projection_axes(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (sign_orient2d({a[i], a[j]}, {b[i], b[j]}, {c[i], c[j]}) != 0) return {i, j};
  }
  return {-1, -1};
}

int side_2d(const std::pair<int, int>& ax, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  return sign_orient2d({a[ax.first], a[ax.second]}, {b[ax.first], b[ax.second]}, {c[ax.first], c[ax.second]});
}

// The closed segment pq meets the closed non-degenerate triangle abc (exact). Written out instead
// of triangles_intersect on the degenerate triangle (p, q, q), whose exactly zero projections
// always fall through to the slow exact stage; this test is the bulk of step 7.
bool segment_meets_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b,
                            const Vector3d& c) {
  const int sp = sign_orient3d(a, b, c, p), sq = sign_orient3d(a, b, c, q);
  if (sp == sq && sp != 0) return false;
  if (sp != 0 || sq != 0) {
    // pq meets the plane at one point, inside the closed triangle iff the line pq passes on no
    // two different sides of the triangle's edges.
    const int s0 = sign_orient3d(p, q, a, b), s1 = sign_orient3d(p, q, b, c), s2 = sign_orient3d(p, q, c, a);
    return !((s0 > 0 || s1 > 0 || s2 > 0) && (s0 < 0 || s1 < 0 || s2 < 0));
  }
  // Coplanar: in a projection where the triangle keeps its area, an endpoint inside or an edge
  // crossed.
  const auto ax = projection_axes(a, b, c);
  if (ax.first < 0) return false;
  auto pr = [&](const Vector3d& x) { return Vector2d(x[ax.first], x[ax.second]); };
  const Vector2d p2 = pr(p), q2 = pr(q), a2 = pr(a), b2 = pr(b), c2 = pr(c);
  const int o = sign_orient2d(a2, b2, c2);
  auto inside = [&](const Vector2d& x) {
    return sign_orient2d(a2, b2, x) * o >= 0 && sign_orient2d(b2, c2, x) * o >= 0 && sign_orient2d(c2, a2, x) * o >= 0;
  };
  return inside(p2) || inside(q2) || segments_intersect(p2, q2, a2, b2) || segments_intersect(p2, q2, b2, c2) ||
         segments_intersect(p2, q2, c2, a2);
}

// A point where the closed triangles s and t meet (approximate, for the message): where an edge of
// one crosses the other, else the first's centroid.
Vector3d meeting_point(const std::array<Vector3d, 3>& s, const std::array<Vector3d, 3>& t) {
  for (int side = 0; side < 2; ++side) {
    const auto& e = side == 0 ? s : t;
    const auto& f = side == 0 ? t : s;
    const Vector3d n = (f[1] - f[0]).cross(f[2] - f[0]);
    for (int k = 0; k < 3; ++k) {
      const Vector3d& a = e[idx(k)];
      const Vector3d& b = e[idx((k + 1) % 3)];
      if (!segment_meets_triangle(a, b, f[0], f[1], f[2])) continue;
      const double da = n.dot(a - f[0]), db = n.dot(b - f[0]);
      if (da != db) return a + std::clamp(da / (da - db), 0.0, 1.0) * (b - a);
      return closest_point_on_triangle((a + b) / 2, f[0], f[1], f[2]);
    }
  }
  return (s[0] + s[1] + s[2]) / 3;
}

// Whether two triangles of a surface intersect beyond what they share (validate.h, step 7).
bool pair_intersects(const std::vector<Vector3d>& pts, const Tri& x, const Tri& y) {
  const std::array<Vector3d, 3> s = {pts[idx(x[0])], pts[idx(x[1])], pts[idx(x[2])]};
  const std::array<Vector3d, 3> t = {pts[idx(y[0])], pts[idx(y[1])], pts[idx(y[2])]};
  int shared = 0;
  std::array<int, 3> in_y{};  // for each corner of x, its corner in y or -1
  for (int i = 0; i < 3; ++i) {
    in_y[idx(i)] = -1;
    for (int j = 0; j < 3; ++j)
      if (x[idx(i)] == y[idx(j)]) in_y[idx(i)] = j;
    if (in_y[idx(i)] >= 0) ++shared;
  }
  if (shared == 0) return triangles_intersect(s.data(), t.data());
  if (shared >= 2) {
    // Sharing an edge (u, v): apart from it they meet only when folded flat onto each other, i.e.
    // coplanar with the far vertices on the same side of the edge.
    int far_x = 0;
    while (in_y[idx(far_x)] >= 0) ++far_x;
    int far_y = 0;
    while (far_y < 3 && (y[idx(far_y)] == x[0] || y[idx(far_y)] == x[1] || y[idx(far_y)] == x[2])) ++far_y;
    if (shared == 3 || far_y == 3) return true;  // the same triangle twice
    const Vector3d& u = s[idx((far_x + 1) % 3)];
    const Vector3d& v = s[idx((far_x + 2) % 3)];
    const Vector3d& w1 = s[idx(far_x)];
    const Vector3d& w2 = t[idx(far_y)];
    if (sign_orient3d(u, v, w1, w2) != 0) return false;
    const auto ax = projection_axes(u, v, w1);
    if (ax.first < 0) return true;  // degenerate triangles are refused before; be safe
    return side_2d(ax, u, v, w1) == side_2d(ax, u, v, w2);
  }
  // Sharing one vertex: beyond it they meet iff the edge opposite the shared vertex in one meets
  // the other (their intersection is convex, contains the shared vertex, and any segment from it
  // inside both leaves the smaller of the two through its opposite edge).
  int cx = 0;
  while (in_y[idx(cx)] < 0) ++cx;
  const int cy = in_y[idx(cx)];
  return segment_meets_triangle(s[idx((cx + 1) % 3)], s[idx((cx + 2) % 3)], t[0], t[1], t[2]) ||
         segment_meets_triangle(t[idx((cy + 1) % 3)], t[idx((cy + 2) % 3)], s[0], s[1], s[2]);
}

struct IntersectionCount {
  std::size_t count = 0;
  std::size_t tested = 0;
  std::vector<std::pair<int, int>> pairs;  // the intersecting pairs (positions in the list)
  int first_a = -1, first_b = -1;  // positions in the triangle list, first_a < first_b
  Vector3d point = Vector3d::Zero();
};

// Counts the intersecting pairs among tris (alive[t] != 0, or all when alive is empty); the first
// reported is the pair smallest by (key[a], key[b]).
IntersectionCount self_intersections(const std::vector<Vector3d>& pts, const std::vector<Tri>& tris,
                                     const TriangleTree& tree, const std::vector<char>& alive,
                                     const std::vector<int>& key) {
  IntersectionCount r;
  const std::vector<std::pair<int, int>> pairs = tree.overlapping_pairs();
  std::pair<int, int> best_key(-1, -1);
  for (const auto& [a, b] : pairs) {
    if (!alive.empty() && (!alive[idx(a)] || !alive[idx(b)])) continue;
    ++r.tested;
    if (!pair_intersects(pts, tris[idx(a)], tris[idx(b)])) continue;
    ++r.count;
    r.pairs.emplace_back(a, b);
    std::pair<int, int> k(key[idx(a)], key[idx(b)]);
    if (k.first > k.second) std::swap(k.first, k.second);
    if (best_key.first < 0 || k < best_key) {
      best_key = k;
      r.first_a = key[idx(a)] <= key[idx(b)] ? a : b;
      r.first_b = key[idx(a)] <= key[idx(b)] ? b : a;
    }
  }
  if (r.count > 0) r.point = meeting_point(tree.triangle(r.first_a), tree.triangle(r.first_b));
  return r;
}

// The repair of step 7 (validate.h): a folded cap is a sliver whose largest angle is over 170
// degrees, its tip just across its long edge instead of on it, so that it and the fan around its
// tip fold over the triangle across that edge (its normal more than 90 degrees from both
// neighbours across its short edges). CAD tessellations make them: the published Orion capsule
// has 5, behind all of its 20 intersecting pairs. Flipping the long edge (the cap and the
// triangle across it become two triangles on the tip's other diagonal) unfolds it, moving the
// surface by at most the tip's distance from that edge. Only caps among the intersecting
// triangles and their neighbours are flipped (a mesh has caps on sharp creases that are not
// folds), and none touching an open edge or making an edge that exists. Returns the flips.
// (extra: more candidates, without their neighbours.)
std::size_t flip_folded_caps(validate_detail::Work& w, const std::vector<char>& alive,
                             const std::vector<std::pair<int, int>>& pairs, double& moved,
                             const std::vector<int>& extra = {}) {
  const std::vector<Vector3d>& pts = w.points();
  std::map<std::pair<int, int>, int> edge_tri;  // directed edge -> its triangle
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    if (!alive.empty() && !alive[t]) continue;
    for (int k = 0; k < 3; ++k) edge_tri[{w.tris[t][idx(k)], w.tris[t][idx((k + 1) % 3)]}] = static_cast<int>(t);
  }
  auto across = [&](int a, int b) {  // the triangle on the other side of directed edge a -> b
    const auto it = edge_tri.find({b, a});
    return it == edge_tri.end() ? -1 : it->second;
  };
  auto unit_normal = [&](int t) {
    const Tri& x = w.tris[idx(t)];
    return Vector3d((pts[idx(x[1])] - pts[idx(x[0])]).cross(pts[idx(x[2])] - pts[idx(x[0])]).normalized());
  };
  std::set<int> candidates(extra.begin(), extra.end());
  for (const auto& [a, b] : pairs)
    for (int t : {a, b}) {
      candidates.insert(t);
      for (int k = 0; k < 3; ++k) {
        const int u = across(w.tris[idx(t)][idx(k)], w.tris[idx(t)][idx((k + 1) % 3)]);
        if (u >= 0) candidates.insert(u);
      }
    }
  std::set<int> touched;
  std::size_t flips = 0;
  for (int t : candidates) {
    if (touched.count(t)) continue;
    const Tri x = w.tris[idx(t)];
    // The long edge: opposite the largest angle, at corner c.
    int c = 0;
    double widest = -1;
    for (int k = 0; k < 3; ++k) {
      const Vector3d u = pts[idx(x[idx((k + 1) % 3)])] - pts[idx(x[idx(k)])];
      const Vector3d v = pts[idx(x[idx((k + 2) % 3)])] - pts[idx(x[idx(k)])];
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
      if (angle > widest) widest = angle, c = k;
    }
    if (widest < 170 * M_PI / 180) continue;
    const int tip = x[idx(c)], a = x[idx((c + 1) % 3)], b = x[idx((c + 2) % 3)];  // long edge a -> b
    const int u = across(a, b), n1 = across(b, tip), n2 = across(tip, a);
    if (u < 0 || n1 < 0 || n2 < 0 || touched.count(u)) continue;
    const Vector3d n = unit_normal(t);
    if (!(n.dot(unit_normal(n1)) < 0 && n.dot(unit_normal(n2)) < 0)) continue;  // not folded
    const Tri y = w.tris[idx(u)];
    int d = -1;
    for (int k = 0; k < 3; ++k)
      if (y[idx(k)] != a && y[idx(k)] != b) d = y[idx(k)];
    if (d < 0 || d == tip || edge_tri.count({tip, d}) || edge_tri.count({d, tip})) continue;
    bool open = false;  // a boundary edge's slot must not move (step 5's loops keep slots)
    for (const Tri& z : {x, y})
      for (int k = 0; k < 3; ++k) open = open || across(z[idx(k)], z[idx((k + 1) % 3)]) < 0;
    if (open) continue;
    // t = (a, b, tip) and u = (b, a, d) become (a, d, tip) and (d, b, tip), the same orientation.
    for (const auto& e : {std::pair<int, int>{a, b}, {b, tip}, {tip, a}, {b, a}, {a, d}, {d, b}}) edge_tri.erase(e);
    w.tris[idx(t)] = {a, d, tip};
    w.tris[idx(u)] = {d, b, tip};
    for (int z : {t, u})
      for (int k = 0; k < 3; ++k) edge_tri[{w.tris[idx(z)][idx(k)], w.tris[idx(z)][idx((k + 1) % 3)]}] = z;
    const Vector3d& pa = pts[idx(a)];
    const Vector3d ab = pts[idx(b)] - pa;
    moved = std::max(moved, (pts[idx(tip)] - pa - ab * (ab.dot(pts[idx(tip)] - pa) / ab.squaredNorm())).norm());
    touched.insert(t);
    touched.insert(u);
    ++flips;
  }
  return flips;
}

// The triangles back to back with the surface all around: each turned more than 90 degrees from
// the triangles across all three of its edges, which agree with each other (features.h's inverted
// faces, with the surface on every side). No body's surface does that; a tessellation that doubles
// back over a sliver does, without crossing itself when the sheet around is not flat (the
// published Orion capsule: caps 0.29 long, largest angle 179.7 degrees, in a 20-degree wedge of
// the sheet, and a 6-long needle cap in a fan that doubles back). Kept, such a cap is a fold the
// remesher starts from and cannot always mend (its corners fixed, its flips needles), and its
// tip's normal is no body's (discrete_reference.cpp).
std::vector<int> back_to_back(const validate_detail::Work& w, const std::vector<char>& alive) {
  const std::vector<Vector3d>& pts = w.points();
  std::map<std::pair<int, int>, int> edge_tri;  // directed edge -> its triangle
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    if (!alive.empty() && !alive[t]) continue;
    for (int k = 0; k < 3; ++k) edge_tri[{w.tris[t][idx(k)], w.tris[t][idx((k + 1) % 3)]}] = static_cast<int>(t);
  }
  auto normal = [&](std::size_t t) {
    const Tri& x = w.tris[t];
    return Vector3d((pts[idx(x[1])] - pts[idx(x[0])]).cross(pts[idx(x[2])] - pts[idx(x[0])]));
  };
  std::vector<int> out;
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    if (!alive.empty() && !alive[t]) continue;
    const Vector3d n = normal(t);
    std::vector<Vector3d> across;
    for (int k = 0; k < 3; ++k) {
      const auto it = edge_tri.find({w.tris[t][idx((k + 1) % 3)], w.tris[t][idx(k)]});
      if (it == edge_tri.end()) break;
      const Vector3d g = normal(idx(it->second));
      if (!(n.dot(g) < 0)) break;
      across.push_back(g);
    }
    bool agree = across.size() == 3;
    for (std::size_t i = 0; agree && i < 3; ++i) agree = across[i].dot(across[(i + 1) % 3]) > 0;
    if (agree) out.push_back(static_cast<int>(t));
  }
  return out;
}

}  // namespace

void validate_detail::check_self_intersections(Work& w, const TriangleTree& tree, const std::vector<char>& alive,
                                               bool repair, SurfaceCheckReport& rep) {
  std::size_t cap_flips = 0;
  if (repair) {
    // Folded caps back to back with the surface all around, crossing nothing: flipped too (up to
    // three rounds, as below), before the crossing pairs are repaired.
    double moved = 0;
    for (int round = 0; round < 3; ++round) {
      const std::vector<int> folded = back_to_back(w, alive);
      const std::size_t now = folded.empty() ? 0 : flip_folded_caps(w, alive, {}, moved, folded);
      if (now == 0) break;
      cap_flips += now;
    }
    if (cap_flips > 0) {
      rep.repairs.push_back(plural(cap_flips, "folded sliver triangle") +
                            " (a cap over its long edge, back to back with the surface around it) flipped (the "
                            "surface moved by at most " + fmt_number(moved) + ")");
    }
  }
  // One crossing test, on the triangles after those flips (the given tree is of the ones before).
  IntersectionCount si =
      cap_flips > 0 ? self_intersections(w.points(), w.tris, TriangleTree(w.points(), w.tris), alive, w.input_index)
                    : self_intersections(w.points(), w.tris, tree, alive, w.input_index);
  rep.self_intersection_pairs_tested = si.tested;
  if (si.count > 0 && repair) {
    // Up to three rounds: a flip can leave another cap folded beside it (one of the Orion's).
    const std::size_t before = si.count;
    const Vector3d where = si.point;
    std::size_t flips = 0;
    double moved = 0;
    for (int round = 0; round < 3 && si.count > 0; ++round) {
      const std::size_t now = flip_folded_caps(w, alive, si.pairs, moved);
      if (now == 0) break;
      flips += now;
      si = self_intersections(w.points(), w.tris, TriangleTree(w.points(), w.tris), alive, w.input_index);
    }
    if (flips > 0)
      rep.repairs.push_back(plural(flips, "folded sliver triangle") + " (a cap over its long edge) flipped, " +
                            plural(before - std::min(before, si.count), "self-intersecting pair") +
                            " removed (first near " + fmt_point(where) + "; the surface moved by at most " +
                            fmt_number(moved) + ")");
  }
  if (si.count > 0)
    throw InputError(w.source() + ": " + plural(si.count, "self-intersecting triangle pair") + "; first: triangles " +
                     std::to_string(w.input_index[idx(si.first_a)]) + " and " +
                     std::to_string(w.input_index[idx(si.first_b)]) + " near " + fmt_point(si.point) +
                     ": mend the surface there in the tool that wrote it, or set geometry.self_intersections: skip"
                     " to mesh it as it is");
}

namespace {

// Step 7's test on a surface's faces (their key: the face index).
IntersectionCount surface_intersections(const TriSurface& s, std::vector<int>& face_id) {
  std::vector<Vector3d> pts(s.mesh.n_vertices());
  for (const auto v : s.mesh.vertices()) pts[idx(v.idx())] = s.mesh.point(v);
  std::vector<Tri> tris;
  face_id.clear();
  for (const auto f : s.mesh.faces()) {
    const auto fv = s.face_vertices(f);
    tris.push_back({fv[0].idx(), fv[1].idx(), fv[2].idx()});
    face_id.push_back(f.idx());
  }
  const TriangleTree tree(pts, tris);
  return self_intersections(pts, tris, tree, {}, face_id);
}

}  // namespace

std::size_t count_self_intersections(const TriSurface& s, std::string* first) {
  std::vector<int> face_id;
  const IntersectionCount si = surface_intersections(s, face_id);
  if (first) {
    first->clear();
    if (si.count > 0)
      *first = "faces " + std::to_string(face_id[idx(si.first_a)]) + " and " +
               std::to_string(face_id[idx(si.first_b)]) + " near " + fmt_point(si.point);
  }
  return si.count;
}

std::vector<std::pair<int, int>> self_intersecting_pairs(const TriSurface& s) {
  std::vector<int> face_id;
  const IntersectionCount si = surface_intersections(s, face_id);
  std::vector<std::pair<int, int>> out;
  for (const auto& [a, b] : si.pairs) out.emplace_back(face_id[idx(a)], face_id[idx(b)]);
  return out;
}

}  // namespace plaf
